"""The output-error search of :class:`clpc.OE`: Levenberg-Marquardt and the refit without pairs.

Also the start vectors of the search, and the carrying of a lower-order optimum into the
fitted structure.

The search runs over ``x = [rho; b; k]`` (:class:`~clpc.lpc.simulation_error.SimulationError`):
``rho`` the denominator's reflection coefficients through ``kappa = MAX_KAPPA tanh(rho)``, so
every iterate is stable.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.core.polynomials import cancel_common_factors
from clpc.data import IOData
from clpc.lpc.reduction import KEEP_FIT_POINTS
from clpc.lpc.reflection import MAX_KAPPA, reflection_from_poly
from clpc.lpc.regressors import Structure, lagged
from clpc.lpc.simulation_error import SimulationError
from clpc.model import LinearModel, ModelError

__all__ = [
    "embedding",
    "objective_fit",
    "padded",
    "search",
    "start_rho",
    "start_vector",
    "without_near_pairs",
]


def search(prob: SimulationError, x0: np.ndarray, limits: tuple[int, float]) -> Any:
    """Levenberg-Marquardt on ``prob`` from ``x0`` (``scipy.optimize.least_squares``).

    ``limits = (max_nfev, tolerance)``: the most residual evaluations, and the relative
    change of the cost, size of the step and gradient below which it stops.
    """
    from scipy import optimize  # imported when used (as scipy.signal: ~0.8 s)

    max_nfev, tol = limits
    return optimize.least_squares(
        prob.residual,
        x0,
        jac=prob.jacobian,
        method="lm",
        x_scale="jac",
        xtol=tol,
        ftol=tol,
        gtol=tol,
        max_nfev=max_nfev,
    )


def objective_fit(prob: SimulationError, x: np.ndarray) -> float:
    """Fit % of the objective: every run's errors against the spread of their targets."""
    t = prob.targets()
    return float(100.0 * (1.0 - np.linalg.norm(prob.residual(x)) / np.linalg.norm(t - t.mean())))


def start_rho(den: np.ndarray) -> np.ndarray:
    """The search's ``rho`` of a stable monic ``den`` (its reflection coefficients, clipped)."""
    kappa = np.clip(reflection_from_poly(den), -MAX_KAPPA * (1 - 1e-12), MAX_KAPPA * (1 - 1e-12))
    return np.arctanh(kappa / MAX_KAPPA)


def start_vector(model: LinearModel, j: int, cols: list[int], structure: Structure) -> np.ndarray:
    """``[rho; b; k]`` of output ``j`` of a start model (made stable first)."""
    den = model.denominators[j]
    b = np.concatenate([model.numerators[j, i, structure.nk :] for i in cols])
    x0 = np.concatenate([start_rho(den), b, [model.intercept[j]]])
    if not np.all(np.isfinite(x0)):
        raise ModelError(f"the start model of output {j} has non-finite parameters.")
    return x0


def without_near_pairs(
    prob: SimulationError,
    x: np.ndarray,
    data: IOData,
    cols: list[int],
    structure: Structure,
    limits: tuple[int, float],
) -> tuple[SimulationError, np.ndarray, int] | None:
    """The fit without its near pole/zero pairs, refitted at the lower order (or ``None``).

    Pairs common to every input's numerator and closer than
    :data:`~clpc.core.polynomials.CANCEL_DISTANCE` are removed and the search is run again
    at ``(na - m, nb - m)`` from what is left, on the same runs. The lower order is kept
    when its objective fit % (:func:`objective_fit`) is within
    :data:`~clpc.lpc.reduction.KEEP_FIT_POINTS` of the fitted order's, or better (the rule
    of LPC's reduction). ``limits``: the search's, as for :func:`search`. Returns the
    lower-order problem, its optimum and ``m``.
    """
    a, _, b, _ = prob.split(x)
    nb, nk = structure.nb, structure.nk
    nums = np.array([np.r_[np.zeros(nk), part] for part in np.split(b, len(cols))])
    den, red, m = cancel_common_factors(a, nums)
    if m == 0 or structure.na - m < 1 or nb - m < 0:
        return None
    small = SimulationError(
        prob.y,
        np.hstack([lagged(data.u[:, i], nb - m, nk, structure.max_lag) for i in cols]),
        structure.na - m,
        structure.max_lag,
        prob.segments,
        prob.full_run,
    )
    x0 = np.concatenate([start_rho(den), red[:, nk:].ravel(), [0.0]])
    res = search(small, x0, limits)
    if not np.isfinite(res.cost):
        return None
    if objective_fit(small, res.x) < objective_fit(prob, x) - KEEP_FIT_POINTS:
        return None  # the pair is real dynamics: keep the fitted order
    return small, res.x, m


def padded(
    small: SimulationError, xs: np.ndarray, m: int, n_cols: int
) -> tuple[np.ndarray, np.ndarray, float]:
    """``a``, ``b``, ``k`` of the lower-order optimum with ``m`` zeros after ``A`` and each ``B``.

    A pole and a zero at ``z = 0`` cancel exactly: the padded model is the lower-order one,
    written in the fitted structure.
    """
    a, _, b, k = small.split(xs)
    b_full = np.concatenate([np.r_[part, np.zeros(m)] for part in np.split(b, n_cols)])
    return np.r_[a, np.zeros(m)], b_full, k


def embedding(low: Structure, full: Structure, n_inputs: int) -> np.ndarray:
    """0/1 matrix carrying the monic vector of ``low`` into the positions of ``full``'s."""
    width_lo, width = low.nk + low.nb + 1, full.nk + full.nb + 1
    rows = np.r_[
        np.arange(low.na),
        [full.na + i * width + t for i in range(n_inputs) for t in range(width_lo)],
    ]
    out = np.zeros((full.na + n_inputs * width, low.na + n_inputs * width_lo))
    out[rows.astype(int), np.arange(out.shape[1])] = 1.0
    return out
