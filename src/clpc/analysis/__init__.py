"""Scoring models on data: fit %, RMSE, VAF, k-step fits, whiteness."""

from clpc.analysis.metrics import WhitenessResult, fit_percent, kstep_fit, rmse, vaf, whiteness_test

__all__ = ["WhitenessResult", "fit_percent", "kstep_fit", "rmse", "vaf", "whiteness_test"]
