"""Scoring candidate models on held-out data: free run, k-step prediction, stability.

Order and delay selection (:mod:`clpc.lpc.order`) fit each candidate on the first part of a
record and score it here on the rest:

* the **horizon** of the k-step prediction comes from the data: one dominant time constant
  of the lowest-order candidate, at least :data:`MIN_HORIZON` samples and at most
  :data:`MAX_HORIZON_FRACTION` of the held-out part (a fixed 10 samples is 10 ms on a 1 kHz
  log, where every order predicts perfectly, and minutes on a slow process);
* the **free run** (simulation from the input alone) counts as much as the prediction:
  the score is the mean of the two fits;
* a candidate with a pole outside the unit circle is **unstable** and never chosen while a
  stable or integrating one exists (a pole on the circle, within :data:`UNIT_CIRCLE_TOL`,
  is an integrator, not an instability).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.core.polynomials import UNIT_CIRCLE_TOL  # a pole this close to the circle is on it

__all__ = ["HeldOutScore", "fit_percent", "horizon", "output_scores", "score", "stability"]

#: Shortest prediction horizon [samples].
MIN_HORIZON = 2
#: Longest prediction horizon, as a share of the held-out samples.
MAX_HORIZON_FRACTION = 0.1


@dataclass(frozen=True)
class HeldOutScore:
    """How a candidate does on held-out data.

    Attributes
    ----------
    free_run, kstep : float
        Fit % of the free-run simulation and of the ``k``-step prediction (-inf when they
        diverge).
    score : float
        Their mean: what the selection compares.
    stability : {"stable", "integrating", "unstable", "no model"}
    """

    free_run: float
    kstep: float
    score: float
    stability: str


def stability(model: Any) -> str:
    """How the model's largest pole sits against the unit circle.

    ``"stable"``, ``"integrating"`` (on the circle, within :data:`UNIT_CIRCLE_TOL`),
    ``"unstable"``, or ``"no model"`` when the poles do not exist (``a0 = 0``).
    """
    try:
        radius = max(float(np.max(np.abs(model.poles(j)))) for j in range(model.n_outputs))
    except (ValueError, np.linalg.LinAlgError):
        return "no model"
    if radius > 1.0 + UNIT_CIRCLE_TOL:
        return "unstable"
    return "integrating" if radius >= 1.0 - UNIT_CIRCLE_TOL else "stable"


def horizon(model: Any, n_heldout: int) -> int:
    """One dominant time constant of ``model`` in samples, clipped (see the module)."""
    longest = max(MIN_HORIZON, int(MAX_HORIZON_FRACTION * n_heldout))
    try:
        radius = max(float(np.max(np.abs(model.poles(j)))) for j in range(model.n_outputs))
    except (ValueError, np.linalg.LinAlgError):
        return longest
    if not 0.0 < radius < 1.0:
        return longest
    tau = -1.0 / math.log(radius)  # samples for the slowest mode to decay by 1/e
    return int(min(max(round(tau), MIN_HORIZON), longest))


def fit_percent(y: np.ndarray, y_hat: np.ndarray) -> float:
    """``100 (1 - ||y - y_hat|| / ||y - mean y||)`` (-inf when it diverges)."""
    with np.errstate(all="ignore"):
        err = float(np.linalg.norm(y - y_hat))
        ref = float(np.linalg.norm(y - y.mean(axis=0)))
    if not (math.isfinite(err) and ref > 0):
        return -math.inf
    return 100.0 * (1.0 - err / ref)


def score(model: Any, data: Any, split: int, k: int) -> HeldOutScore:
    """Score a model fitted on ``data[:split]`` on ``data[split:]``.

    The free run simulates the whole record from its start (so the held-out part starts
    from the model's own state, not from rest) and is scored on the held-out samples; the
    ``k``-step prediction uses the held-out outputs.
    """
    kind = stability(model)
    if kind == "no model":
        return HeldOutScore(-math.inf, -math.inf, -math.inf, kind)
    val = data[split:]
    with np.errstate(all="ignore"):
        sim = np.asarray(model.simulate(data.u)).reshape(data.y.shape)[split:]
        pred = np.asarray(model.predict(val.u, val.y, k=k)).reshape(val.y.shape)
    start = model.structure.max_lag + k
    free_run = fit_percent(val.y, sim)
    kstep = fit_percent(val.y[start:], pred[start:])
    return HeldOutScore(free_run, kstep, 0.5 * (free_run + kstep), kind)


def output_scores(model: Any, data: Any, split: int, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Free-run and ``k``-step fit % of each output on ``data[split:]``, as :func:`score`.

    Returns
    -------
    free_run, kstep : ndarray, shape (n_outputs,)
        -inf where a prediction diverges.
    """
    val = data[split:]
    with np.errstate(all="ignore"):
        sim = np.asarray(model.simulate(data.u)).reshape(data.y.shape)[split:]
        pred = np.asarray(model.predict(val.u, val.y, k=k)).reshape(val.y.shape)
    start = model.structure.max_lag + k
    free = [fit_percent(val.y[:, j], sim[:, j]) for j in range(val.y.shape[1])]
    ahead = [fit_percent(val.y[start:, j], pred[start:, j]) for j in range(val.y.shape[1])]
    return np.array(free), np.array(ahead)
