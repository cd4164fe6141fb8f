"""The evidence a fit's verdict cites: its held-out fit and its residual tests.

:func:`assess` stores, in the model's ``info``:

* ``info["heldout"]``: the same estimator refitted on the first two thirds of the record
  and scored on the last third (:func:`clpc.lpc.heldout.score`: free-run fit %, ``k``-step
  fit % with ``k`` one dominant time constant, stability; ``free_run_outputs`` and
  ``kstep_outputs`` per output) - how well this kind of model predicts data it has not seen;
* ``info["residual_test"]``: the whiteness and input-independence tests of the model's
  residuals on the whole record (:func:`clpc.model.residuals.residual_analysis`), per
  output, with statistics and thresholds.

:func:`clpc.model.verdict.fit_verdict` words them beside the eigenvalue structure.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from clpc.data import DataError, IOData
from clpc.lpc import heldout
from clpc.model import LinearModel, ModelError
from clpc.model.evidence import FitRecord
from clpc.model.excitation import excitation_entries
from clpc.model.residuals import residual_analysis

__all__ = ["HELDOUT_FRACTION", "assess", "evidence", "fit_record"]

#: Share of the record held out (the last part), as :func:`clpc.select_order` does.
HELDOUT_FRACTION = 1.0 / 3.0


def heldout_evidence(data: IOData, refit: Callable[[IOData], LinearModel]) -> dict[str, Any]:
    """Fit on the first part, score on the held-out rest (see the module)."""
    split = round(data.n_samples * (1.0 - HELDOUT_FRACTION))
    try:
        model = refit(data[:split])
        k = heldout.horizon(model, data.n_samples - split)
        sc = heldout.score(model, data, split, k)
        free, ahead = heldout.output_scores(model, data, split, k)
    except (DataError, ModelError, ValueError, np.linalg.LinAlgError) as exc:
        return {"note": f"no held-out fit: {exc}"}
    return {
        "free_run": sc.free_run,
        "kstep": sc.kstep,
        "free_run_outputs": free,
        "kstep_outputs": ahead,
        "horizon": k,
        "split": split,
        "n_heldout": data.n_samples - split,
        "stability": sc.stability,
    }


def residual_evidence(model: LinearModel, data: IOData) -> dict[str, Any]:
    """The residual tests as plain numbers, one entry per output (see the module)."""
    try:
        res = residual_analysis(model, data.u, data.y)
    except (ValueError, ModelError) as exc:
        return {"note": f"no residual test: {exc}"}
    n_in = model.n_inputs
    indep = [res.independence[j * n_in : (j + 1) * n_in] for j in range(model.n_outputs)]
    return {
        "kind": res.kind,
        "level": res.level,
        "lags": int(res.lags.size - 1),
        "n_samples": res.n_samples,
        "whiteness_Q": [t.statistic for t in res.whiteness],
        "whiteness_threshold": [t.threshold for t in res.whiteness],
        "white": [t.passed for t in res.whiteness],
        "independence_zeta": [[t.statistic for t in row] for row in indep],
        "independence_threshold": [[t.threshold for t in row] for row in indep],
        "independent": [[t.passed for t in row] for row in indep],
    }


def evidence(
    model: LinearModel, data: IOData, refit: Callable[[IOData], LinearModel]
) -> dict[str, Any]:
    """``info["heldout"]`` and ``info["residual_test"]`` of ``model`` (see the module).

    Parameters
    ----------
    model : LinearModel
        A fit of ``data``.
    data : IOData
        The record.
    refit : callable
        The same estimator (without evidence) on a part of the record.

    Returns
    -------
    dict
        ``{"heldout": ..., "residual_test": ...}``.
    """
    return {
        "heldout": heldout_evidence(data, refit),
        "residual_test": residual_evidence(model, data),
    }


def fit_record(
    data: IOData,
    estimator: Any,
    covariance: Callable[[LinearModel], dict[str, Any]] | None = None,
) -> FitRecord:
    """The record a fit keeps, with the evidence it offers on demand.

    Parameters
    ----------
    data : IOData
        The record the model is fitted on.
    estimator : LPC, ARX or OE
        The estimator (a dataclass with ``assess`` and ``uncertainty`` flags): with
        ``assess``, :func:`evidence` is offered, refitting a copy of it without evidence.
    covariance : callable, optional
        ``f(model) -> dict`` of covariance entries, offered when given. The input's order
        of persistent excitation (:func:`clpc.model.excitation.excitation_entries`) is
        always offered.

    Returns
    -------
    FitRecord
        Nothing is computed yet (:mod:`clpc.model.evidence`).
    """
    record = FitRecord(data).with_producer(
        "excitation", lambda fitted: excitation_entries(fitted, data)
    )
    if covariance is not None:
        record = record.with_producer("covariance", covariance)
    if estimator.assess:
        refit = replace(estimator, assess=False, uncertainty=False).fit
        record = record.with_producer("assessment", lambda fitted: evidence(fitted, data, refit))
    return record


def assess(model: LinearModel, data: IOData, refit: Callable[[IOData], LinearModel]) -> LinearModel:
    """``model`` with the entries of :func:`evidence` and the excitation in its ``info`` (now)."""
    found = {**evidence(model, data, refit), **excitation_entries(model, data)}
    return replace(model, info={**model.info, **found})
