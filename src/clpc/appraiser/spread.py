"""How much the windows' models disagree: the local DC gain of every window.

The steady-state model (:func:`clpc.appraiser.convergence.steady_state_model`) averages
the accepted windows after convergence. When those windows hold different operating points
of a nonlinear plant their models differ, and the average mixes operating points (issue 18:
on a crank servo it was the worst model of all). :func:`gain_spread` measures the
disagreement from the trace alone; the operating points themselves need the data
(:func:`clpc.analysis.operating_point.operating_point_diagnostics`).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "GAIN_SPREAD_LIMIT",
    "TREND_LIMIT",
    "gain_spread",
    "level_trend",
    "window_dc_gains",
]

#: Relative spread of the windows' DC gains, ``(P90 - P10) / |median|``, above which the
#: windows disagree. Measured: the crank servo of :mod:`clpc_paper.plants.crank_servo` 0.84-0.93;
#: its negative control with the velocity integrator 0.42-0.46 (its windows are too short to
#: settle the integrator); linear records of the test suite (a tracked chirp, the quick
#: demo's actuator) up to 0.32, which the first limit tried (0.25) flagged.
GAIN_SPREAD_LIMIT = 0.35
#: |Spearman rank correlation| between the windows' DC gains and their output levels above
#: which the disagreement follows the operating point (crank servo 0.93-0.94, its control
#: 0.72-0.82; those linear records 0.52-0.53)
TREND_LIMIT = 0.6


def level_trend(levels: np.ndarray, gains: np.ndarray) -> float:
    """Spearman rank correlation of gains with levels (finite pairs; 0 if fewer than 3)."""
    ok = np.isfinite(levels) & np.isfinite(gains)
    if ok.sum() < 3 or np.ptp(levels[ok]) == 0 or np.ptp(gains[ok]) == 0:
        return 0.0
    rank_l = np.argsort(np.argsort(levels[ok])).astype(float)
    rank_g = np.argsort(np.argsort(gains[ok])).astype(float)
    return float(np.corrcoef(rank_l, rank_g)[0, 1])


def window_dc_gains(theta: np.ndarray, na: int) -> np.ndarray:
    """DC gain ``-sum(b) / sum(a)`` of each unit-norm ``theta`` row (SISO), shape (n,).

    ``theta`` has shape (n, p) (paper convention ``[a; b]``); an integrating window
    (``sum(a) = 0``) gives ``inf``.
    """
    th = np.asarray(theta, dtype=np.float64)
    a = th[:, : na + 1].sum(axis=1)
    b = th[:, na + 1 :].sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(a != 0, -b / np.where(a != 0, a, 1.0), np.inf)


def gain_spread(gains: np.ndarray) -> float:
    """``(P90 - P10) / |median|`` of the finite gains (0 for fewer than 3; inf if median 0)."""
    g = np.asarray(gains, dtype=np.float64)
    g = g[np.isfinite(g)]
    if g.size < 3:
        return 0.0
    lo, med, hi = np.percentile(g, [10, 50, 90])
    return float((hi - lo) / abs(med)) if med != 0 else float("inf")
