"""When a CLPC trace became quasi-constant, and the model it settles on.

:meth:`clpc.Trace.convergence` and :meth:`clpc.Trace.steady_state_model` call these
functions (``trace`` is a :class:`clpc.Trace`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.appraiser.spread import (
    GAIN_SPREAD_LIMIT,
    TREND_LIMIT,
    gain_spread,
    level_trend,
    window_dc_gains,
)
from clpc.appraiser.trace_scan import RowSpill, ScanState, sequential_mean, usable
from clpc.core.compact import compact_repr
from clpc.model import LinearModel

__all__ = [
    "MIN_TRUSTED_FRACTION",
    "Convergence",
    "convergence",
    "convergence_of",
    "model_of",
    "no_steady_state",
    "normalised",
    "steady_state_model",
    "usable",
]


@compact_repr
@dataclass(frozen=True)
class Convergence:
    """When the appraiser's outputs became quasi-constant.

    Attributes
    ----------
    converged : bool
        Whether ``consecutive`` :func:`usable` updates in a row changed less than the tolerances.
    update : int
        Row of the trace where the quasi-constant phase starts (-1 if never).
    index : int
        Sample index of that update (-1 if never).
    time : float
        Its time [s] (nan if never).
    theta_tol, D_tol : float
        Tolerances used: ``||theta_j - theta_{j-1}||`` (unit vectors) and
        ``|D_j - D_{j-1}| / D_j``.
    consecutive : int
    theta_variation : float
        After convergence: largest ``||theta_j - theta_ss||`` over :func:`usable` updates.
    D_variation : float
        After convergence: largest ``|D_j - mean D| / mean D``.
    trusted_fraction : float
        Share of the updates whose window is trusted (every equation); convergence is
        never reported below :data:`MIN_TRUSTED_FRACTION`.
    reason : str
        In words: why the trace converged or did not.
    """

    converged: bool
    update: int
    index: int
    time: float
    theta_tol: float
    D_tol: float
    consecutive: int
    theta_variation: float
    D_variation: float
    trusted_fraction: float = 1.0
    reason: str = ""


#: ``converged`` is never reported when fewer updates than this share come from trusted
#: windows (most windows then say nothing reliable about the system).
MIN_TRUSTED_FRACTION = 0.5


def convergence(
    trace: Any, theta_tol: float = 0.02, D_tol: float = 0.1, consecutive: int = 5
) -> Convergence:
    """First update after which ``theta`` and ``D`` stay quasi-constant.

    An update is quasi-constant when every equation's accepted ``theta`` moved by less
    than ``theta_tol`` (Euclidean, unit vectors) and ``D`` by less than ``D_tol``
    (relative) since the previous update; convergence needs ``consecutive`` such
    updates in a row. Only updates from trusted windows count (:func:`usable`): with
    ``guard=False`` the appraiser also accepts untrusted ones, which say nothing reliable.
    """
    state = ScanState(theta_tol, D_tol, consecutive, RowSpill())
    state.add(trace)
    return convergence_of(state)


def convergence_of(state: ScanState) -> Convergence:
    """The :class:`Convergence` of the updates a :class:`ScanState` was fed.

    The variations need one more pass, over the rows after the convergence point that the
    state spilled (in memory, or in a scratch file for a trace read from disk).
    """
    n = state.n
    theta_tol, D_tol, consecutive = state.theta_tol, state.D_tol, state.consecutive
    frac = state.trusted / n if state.trusted is not None and n else 1.0
    none = (float("nan"), theta_tol, D_tol, consecutive, float("nan"), float("nan"))
    if frac < MIN_TRUSTED_FRACTION:
        why = (
            f"not converged: only {frac:.0%} of the {n} windows are trusted (at least "
            f"{MIN_TRUSTED_FRACTION:.0%} needed: enough rows, excited above quantization, "
            "determined)"
        )
        return Convergence(False, -1, -1, *none, frac, why)
    if state.start < 0:
        why = (
            f"not converged: no {consecutive} trusted, accepted updates in a row moved theta by "
            f"less than {theta_tol:g} and D by less than {D_tol:.0%}"
        )
        return Convergence(False, -1, -1, *none, frac, why)
    ss = normalised(state.mean("theta"))
    d_mean = state.mean("D")
    th_var = d_var = 0.0
    for theta, d in state.spill.blocks():
        th_var = max(th_var, float(np.linalg.norm(theta - ss[None], axis=2).max()))
        d_var = max(d_var, float((np.abs(d - d_mean) / np.maximum(d_mean, 1e-300)).max()))
    why = (
        f"converged at update {state.start + 1}: {consecutive} trusted, accepted updates in a "
        f"row moved theta by less than {theta_tol:g} and D by less than {D_tol:.0%}; "
        f"{frac:.0%} of the windows are trusted"
    )
    index, time = state.start_at
    return Convergence(
        True, state.start, index, time, theta_tol, D_tol, consecutive, th_var, d_var, frac, why
    )


def steady_state_model(
    trace: Any, conv: Convergence | None = None, *, allow_unconverged: bool = False
) -> LinearModel:
    """The mean ``theta`` of the :func:`usable` updates after convergence.

    See :meth:`clpc.Trace.steady_state_model`; unconverged with ``allow_unconverged``: the
    last usable update (the last accepted one when no window is trusted).
    """
    conv = conv or convergence(trace)
    acc = usable(trace)
    if not conv.converged and not acc.any():  # no trusted update: the last accepted one
        acc = np.asarray(
            trace.arrays["accepted"].all(axis=1) & trace.arrays["has_model"].all(axis=1)
        )
    if conv.converged:
        sel = acc & (np.arange(len(trace)) >= conv.update)
    elif allow_unconverged and acc.any():
        sel = np.zeros(len(trace), dtype=bool)
        sel[np.flatnonzero(acc)[-1]] = True
    else:
        raise no_steady_state(int(acc.sum()), len(trace), conv)
    theta = _mean_theta(trace.arrays["theta"][sel])
    c = sequential_mean(trace.arrays["c"][sel])
    spread = _warn_if_windows_disagree(trace, sel)
    return model_of(trace, theta, c, conv, int(sel.sum()), spread)


def no_steady_state(accepted: int, n: int, conv: Convergence) -> ValueError:
    """The error of a trace with no steady state (and ``allow_unconverged=False``)."""
    return ValueError(
        "the trace never became quasi-constant (no steady state): "
        f"{accepted} of {n} updates were accepted; {conv.reason}. Use "
        "a longer record, a richer input, larger tolerances, or allow_unconverged=True."
    )


def model_of(
    like: Any, theta: np.ndarray, c: np.ndarray, conv: Convergence, used: int, spread: Any
) -> LinearModel:
    """The steady-state :class:`LinearModel` of a trace (``like``: its labels)."""
    return LinearModel(
        theta=theta,
        structure=like.structure,
        n_inputs=like.n_inputs,
        mode=like.mode,
        c=c,
        dt=like.sample_time,
        input_names=like.input_names,
        output_names=like.output_names,
        info={
            "convergence": conv,
            "method": "clpc-steady-state",
            "scaling": like.meta.get("scaling"),
            "guard": like.meta.get("guard"),
            "updates_used": used,
            "gain_spread": spread,
        },
    )


def _warn_if_windows_disagree(trace: Any, sel: np.ndarray) -> float | None:
    """Warn loudly when the averaged windows' DC gains follow their output level (SISO).

    Needs the windows' levels (``trace.meta["window_level"]``, stored by
    :meth:`clpc.CLPC.run`); returns the gain spread, or None when it cannot be judged.
    """
    levels = trace.meta.get("window_level")
    if trace.n_inputs != 1 or trace.n_equations != 1 or levels is None:
        return None
    if np.shape(levels)[0] != len(trace):  # rows added or dropped since run(): not judged
        return None
    gains = window_dc_gains(trace.arrays["theta"][sel][:, 0, :], trace.structure.na)
    spread = gain_spread(gains)
    rho = level_trend(np.asarray(levels)[sel, 0], gains)
    if spread > GAIN_SPREAD_LIMIT and abs(rho) >= TREND_LIMIT:
        finite = gains[np.isfinite(gains)]
        warnings.warn(
            "THE STEADY-STATE MODEL AVERAGES WINDOWS WHOSE MODELS CHANGE WITH THE OUTPUT "
            f"LEVEL: their DC gains run from {np.percentile(finite, 10):.3g} to "
            f"{np.percentile(finite, 90):.3g} (10th-90th percentile; relative spread "
            f"{spread:.2f} > {GAIN_SPREAD_LIMIT}) and follow the level (rank correlation "
            f"{rho:+.2f}, limit +/-{TREND_LIMIT}). A nonlinear plant does this (the average "
            "mixes operating points and can be worse than one global fit: use "
            "clpc.MultiModel.from_trace(trace, u, y)); so do windows too poorly excited to "
            "fix their gain. clpc.operating_point_diagnostics(trace, u, y) tells which.",
            UserWarning,
            stacklevel=3,
        )
    return spread


def _mean_theta(theta: np.ndarray) -> np.ndarray:
    """Mean of unit vectors (a0 > 0 already), renormalised: shape (E, p)."""
    return normalised(sequential_mean(theta))


def normalised(mean: np.ndarray) -> np.ndarray:
    """Each row of ``mean`` (E, p) divided by its norm."""
    return mean / np.linalg.norm(mean, axis=1, keepdims=True)
