"""Summaries of identified models, as JSON-safe dicts.

* :func:`model_summary` - transfer functions, poles, stability, ``D``, fit % of the free-run
  simulation and of k-step predictions, and the identifiability verdict in plain words;
  per output the DC gains +- sigma and the dominant poles
  (:func:`clpc.report.identifiability.identifiability_summary`).
* :func:`model_response` - simulated or k-step-predicted output and its fit %.

A trace's summary is in :mod:`clpc.report.trace_summary`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from clpc.analysis.metrics import fit_percent
from clpc.core.jsonable import jsonable
from clpc.core.polynomials import pole_class
from clpc.data import IOData
from clpc.model import LinearModel, ModelError
from clpc.model.residuals import residual_analysis
from clpc.model.uncertainty import parameter_labels, parameter_std, parameter_vector
from clpc.model.verdict import fit_verdict
from clpc.report.identifiability import identifiability_summary

__all__ = [
    "model_response",
    "model_summary",
    "verdict_text",
]


def verdict_text(model: LinearModel, output: int = 0) -> str | None:
    """The identifiability verdict of one output equation in plain words.

    Uses :func:`clpc.model.verdict.fit_verdict` on the statistics in ``model.info``
    (``determined``, ``n_null``, ``n_input_relations``...) and the evidence a fit stored
    (``heldout``, ``residual_test``); ``None`` for models with neither (e.g. a CLPC
    steady-state model or a hand-built one).

    Parameters
    ----------
    model : LinearModel
        A fitted model.
    output : int
        Output index whose equation is judged (default 0).

    Returns
    -------
    str or None
    """
    has_eig = all(k in model.info for k in ("n_null", "n_input_relations", "determined"))
    if not has_eig and "heldout" not in model.info and "excitation_order" not in model.info:
        return None
    return str(fit_verdict(model, output))


def model_response(
    model: Any, u: Any, y: Any, k: int | None = None
) -> tuple[np.ndarray, int, np.ndarray]:
    """Simulated (``k=None``) or ``k``-step-predicted output of a model on measured data.

    Parameters
    ----------
    model : LinearModel or MultiModel
        Anything with ``warmup``, ``simulate(u, y_init=, u_init=)`` and ``predict(u, y, k)``.
    u : array_like, shape (T, n_inputs)
        Measured inputs.
    y : array_like, shape (T, n_outputs)
        Measured outputs.
    k : int, optional
        Prediction horizon in samples; ``None`` for the free-run simulation.

    Returns
    -------
    y_hat : ndarray, shape (T, n_outputs)
        Model output. The first ``model.warmup`` samples have no complete past and are
        copied from ``y``; the free-run simulation starts from those measured samples
        (initial conditions) and then uses the input alone.
    start : int
        First compared sample (``warmup``, plus ``k - 1`` for a prediction).
    fit : ndarray, shape (n_outputs,)
        Fit % over samples ``start:`` (NaN when the simulation diverges).
    """
    u2 = np.asarray(u, dtype=np.float64).reshape(len(u), -1)
    y2 = np.asarray(y, dtype=np.float64).reshape(len(y), -1)
    start = model.warmup
    if y2.shape[0] <= start + 1:
        raise ValueError(
            f"comparing needs more than {start + 1} samples (the model's warm-up is {start}); "
            f"got {y2.shape[0]}."
        )
    if k is None:
        y_hat = y2.copy()
        with np.errstate(over="ignore", invalid="ignore"):
            free = model.simulate(u2[start:], y_init=y2[:start], u_init=u2[:start])
        y_hat[start:] = np.asarray(free).reshape(-1, y2.shape[1])
    else:
        y_hat = np.asarray(model.predict(u2, y2, k=k)).reshape(y2.shape)
        start += k - 1  # only true k-step predictions are scored (as clpc.kstep_fit)
    fit = np.full(y2.shape[1], np.nan)
    for j in range(y2.shape[1]):  # per output: one diverging output leaves the others' fit
        if np.all(np.isfinite(y_hat[start:, j])):
            fit[j] = fit_percent(y2[start:, j], y_hat[start:, j])
    return y_hat, start, fit


def _all_of(flags: list[bool | None]) -> bool | None:
    """``False`` if any is, ``True`` if all are, else ``None`` (not judged)."""
    return False if False in flags else (True if all(flags) else None)


def model_summary(
    model: LinearModel, data: IOData | None = None, horizons: Sequence[int] = (1, 10)
) -> dict[str, Any]:
    """Everything worth printing about an identified model, JSON-safe.

    Parameters
    ----------
    model : LinearModel
        The model (monic engineering convention is reported: ``den = A(z)/a0`` with
        ``den[0] = 1``, ``num = -B(z)/a0``, ascending powers of ``z^-1``).
    data : IOData, optional
        Record to evaluate on: fit % of the free-run simulation and of the ``k``-step
        predictions for each ``k`` in ``horizons`` (see :func:`model_response`).
    horizons : sequence of int
        Prediction horizons.

    Returns
    -------
    dict
        Keys ``inputs``, ``outputs``, ``dt``, ``structure``, ``mode``, ``method``
        (and ``estimators``, one per output, for a model of :func:`clpc.identify`),
        ``stable``, ``equations`` (one dict per output: ``den``, ``num`` per input,
        ``intercept``, ``poles`` as ``[re, im]`` pairs, ``stable``, ``D``, ``lambda_min``,
        ``eig_ratio``, ``noise_variance``, ``determined``, ``n_input_relations``,
        ``verdict`` (one finding per line), and ``dc_gain``, ``dominant_poles``,
        ``identifiability`` of
        :func:`clpc.report.identifiability.identifiability_summary`), ``identifiable``
        (``False`` when an output is not, ``None`` when not judged) and, with data,
        ``n_samples`` and ``fit`` (``{"simulation": [...], "prediction_1": [...], ...}``,
        one fit % per output, ``None`` if it diverges).
    """
    s = model.structure
    info = model.info
    dens, nums, icpt = model.denominators, model.numerators, model.intercept

    def stat(key: str, j: int) -> Any:
        return jsonable(np.atleast_1d(info[key])[j]) if key in info else None

    try:
        sigma: np.ndarray | None = np.atleast_2d(parameter_std(model))
    except ModelError:
        sigma = None
    labels, values = parameter_labels(model), parameter_vector(model)
    equations = []
    for j in range(model.n_outputs):
        poles = model.poles(j)
        equations.append(
            {
                "output": model.output_names[j],
                "den": jsonable(dens[j]),
                "num": {model.input_names[i]: jsonable(nums[j, i]) for i in range(model.n_inputs)},
                "intercept": jsonable(icpt[j]),
                "poles": [[jsonable(p.real), jsonable(p.imag)] for p in poles],
                "stable": bool(np.all(np.abs(poles) < 1.0)),
                "stability": pole_class(poles),
                "D": stat("D", j),
                "lambda_min": stat("lambda_min", j),
                "eig_ratio": stat("eig_ratio", j),
                "noise_variance": stat("noise_variance", j),
                "determined": stat("determined", j),
                "n_input_relations": stat("n_input_relations", j),
                "verdict": verdict_text(model, j),
                **identifiability_summary(model, j),
                "parameters": [
                    {
                        "name": n,
                        "value": jsonable(v),
                        "std": None if sigma is None else jsonable(sd),
                    }
                    for n, v, sd in zip(
                        labels,
                        values[j],
                        np.zeros_like(values[j]) if sigma is None else sigma[j],
                        strict=True,
                    )
                ],
            }
        )
    out: dict[str, Any] = {
        "inputs": list(model.input_names),
        "outputs": list(model.output_names),
        "dt": model.dt,
        "structure": {"na": s.na, "nb": s.nb, "nk": s.nk},
        "mode": model.mode,
        "method": info.get("method"),
        **({"estimators": list(info["estimators"])} if "estimators" in info else {}),
        "scaling": info.get("scaling"),
        "cancelled": int(np.sum(info.get("cancelled", 0))),  # per output in a mixed model
        "stable": model.is_stable,
        "stability": model.stability,
        "identifiable": _all_of([eq["identifiability"]["identifiable"] for eq in equations]),
        "equations": equations,
    }
    if data is not None:
        fits: dict[str, Any] = {}
        for k in (None, *horizons):
            _, _, fit = model_response(model, data.u, data.y, k)
            fits["simulation" if k is None else f"prediction_{k}"] = jsonable(fit)
        out["n_samples"] = data.n_samples
        out["fit"] = fits
        try:
            res = residual_analysis(model, data.u, data.y)
            out["residual_test"] = {"passed": res.passed, "tests": [str(t) for t in res.tests]}
        except ValueError as exc:
            out["residual_test"] = {"passed": None, "tests": [f"not computed: {exc}"]}
    return out
