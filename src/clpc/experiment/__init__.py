"""The paper's section VI experiment on the simulated brushless servo, end to end."""

from clpc.experiment.run import decimate, error_profile, free_run, run_experiment, stable_inverse

__all__ = ["decimate", "error_profile", "free_run", "run_experiment", "stable_inverse"]
