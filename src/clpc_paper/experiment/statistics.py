"""The numbers behind the paper's figures: D, the parameters, the models, the rigid body.

Each function turns a trace, an identification or a model into a JSON-ready dict of the
``summary.json`` written by :func:`clpc_paper.experiment.run_experiment`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy import signal

from clpc import LinearModel, Trace
from clpc.appraiser import usable
from clpc_paper.experiment.results import Identification
from clpc_paper.experiment.settings import A0_MIN, D_QUASI_CONSTANT, LABELS, WINDOW_SIZE
from clpc_paper.plants import ServoParameters

__all__ = [
    "d_statistics",
    "equivalent_damping",
    "model_summary",
    "parameter_statistics",
    "rigid_body",
]


def _cv(x: np.ndarray) -> float:
    mean = float(np.mean(x))
    return float(np.std(x) / mean) if mean > 0 else float("inf")


def _phase(d: np.ndarray, time: np.ndarray, mask: np.ndarray) -> dict[str, Any]:
    """Statistics of D over the updates in ``mask`` (see :func:`d_statistics`)."""
    x, t = d[mask], time[mask]
    if x.size < 2:
        return {"n_updates": int(x.size)}
    slope = np.polyfit(t, x, 1)[0] if np.ptp(t) > 0 else 0.0
    mean = float(x.mean())
    return {
        "n_updates": int(x.size),
        "first": float(x[0]),
        "last": float(x[-1]),
        "min": float(x.min()),
        "max": float(x.max()),
        "mean": mean,
        "cv": _cv(x),
        "trend": float(slope * np.ptp(t) / mean) if mean > 0 else None,
        "rising_fraction": float(np.mean(np.diff(x) > 0)),
    }


def d_statistics(trace: Trace) -> dict[str, Any]:
    """The paper's Fig. 6 claim in numbers: D while the window fills vs after.

    Fill phase: updates with fewer than ``WINDOW_SIZE`` rows (excluding those with too few
    rows for an estimate). ``cv``: standard deviation over mean; ``trend``: least-squares
    slope times the phase length over the mean (relative drift); ``rising_fraction``:
    share of consecutive increases. D is *quasi-constant* when ``cv < D_QUASI_CONSTANT``.
    """
    d = np.asarray(trace.D, dtype=float)
    full = trace.rows >= WINDOW_SIZE
    fill = ~full & ~trace.not_enough_data
    fill_stats, after_stats = _phase(d, trace.time, fill), _phase(d, trace.time, full)
    cv_after = after_stats.get("cv", float("inf"))
    cv_fill = fill_stats.get("cv", 0.0)
    return {
        "window_full_time": float(trace.time[full][0]) if full.any() else None,
        "fill": fill_stats,
        "after_fill": after_stats,
        "tolerance_cv": D_QUASI_CONSTANT,
        "quasi_constant_after_fill": bool(cv_after < D_QUASI_CONSTANT),
        "more_constant_after_fill": bool(cv_after < cv_fill),
    }


def parameter_statistics(ident: Identification) -> dict[str, Any]:
    """The Figs. 7-12 claim: cluster where theta becomes quasi-constant, variation after it.

    ``largest_step``: the largest ``||theta_j - theta_{j-1}||`` between consecutive trusted
    updates after the marker, with the cluster and time [s] where it lands.
    """
    conv, trace = ident.convergence, ident.trace
    theta = trace.theta
    a0 = theta[:, 0]
    out: dict[str, Any] = {
        "converged": conv.converged,
        "tolerance_level": ident.level,
        "theta_tol": conv.theta_tol if ident.level >= 0 else None,
        "D_tol": conv.D_tol if ident.level >= 0 else None,
        "consecutive": conv.consecutive if ident.level >= 0 else None,
        "accepted_fraction": float(np.mean(trace.accepted)),
        "determined_fraction": float(np.mean(trace.determined)),
        "trusted_fraction": float(conv.trusted_fraction),
        "convergence_reason": conv.reason,
        "accepted_without_a0": int(np.sum(trace.accepted & (trace.theta_estimate[:, 0] < A0_MIN))),
        "held_a0_min": float(a0[trace.has_model].min()) if trace.has_model.any() else None,
    }
    if conv.converged:
        after = np.arange(len(trace)) >= conv.update
        dev = np.abs(theta[after] - ident.model.theta_matrix[0][None, :]).max(axis=0)
        used = np.flatnonzero(usable(trace) & after)
        steps = np.linalg.norm(np.diff(theta[used], axis=0), axis=1) if used.size > 1 else []
        if len(steps):
            k = int(np.argmax(steps))
            out["largest_step"] = {
                "size": float(steps[k]),
                "cluster": int(used[k + 1]) + 1,
                "time": float(trace.time[used[k + 1]]),
            }
        out.update(
            cluster=int(conv.update) + 1,
            time=float(conv.time),
            theta_variation=float(conv.theta_variation),
            D_variation=float(conv.D_variation),
            entry_variation={k: float(v) for k, v in zip(LABELS, dev, strict=True)},
        )
    return out


def model_summary(model: LinearModel) -> dict[str, Any]:
    """Coefficients (both conventions), poles, zeros, stability, DC gain of a SISO model.

    ``den_sum`` is ``A(1)`` (0 for an integrator) and ``num_sum`` is ``B(1)``; the model's
    static map is ``y = dc_gain * u + static_offset`` (``static_offset = k / A(1)``);
    ``input_at_zero = -k / B(1)`` is what its inverse returns for a constant ``y = 0``.
    """
    poles, zeros = model.poles(), model.zeros()
    with np.errstate(divide="ignore", invalid="ignore"):
        dc = float(model.dc_gain()[0, 0])
    return {
        "theta": model.theta_matrix[0].tolist(),
        "den": model.den.tolist(),
        "num": model.num.tolist(),
        "poles": [[float(p.real), float(p.imag)] for p in poles],
        "pole_radius": np.abs(poles).tolist(),
        "zeros": [[float(z.real), float(z.imag)] for z in zeros],
        "stable": bool(model.is_stable),
        "minimum_phase": bool(np.all(np.abs(zeros) < 1.0)),
        "dc_gain": dc if np.isfinite(dc) else None,
        "pole_distance_to_1": float(np.abs(poles - 1.0).min()),
        "den_sum": float(model.den.sum()),
        "num_sum": float(model.num.sum()),
        "intercept": float(np.atleast_1d(model.intercept)[0]),
        "static_offset": _static_offset(model),
        "input_at_zero": _input_at_zero(model),
    }


def _input_at_zero(model: LinearModel) -> float | None:
    """``-k / B(1)``: the constant input the model needs to hold ``y = 0`` (None: B(1) = 0)."""
    b1 = float(model.num.sum())
    k = float(np.atleast_1d(model.intercept)[0])
    return -k / b1 if abs(b1) > 1e-12 else None


def _static_offset(model: LinearModel) -> float | None:
    """``k / A(1)``: the output the model holds for a zero input (None for an integrator)."""
    a1 = float(model.den.sum())
    k = float(np.atleast_1d(model.intercept)[0])
    return k / a1 if abs(a1) > 1e-12 else None


def rigid_body(params: ServoParameters, dt: float) -> dict[str, Any]:
    """Zero-order-hold discretisation of ``1 / (J s^2 + b s)`` (torque -> position).

    ``J`` is the total (motor + load) inertia, ``b`` the summed viscous friction; the
    Coulomb friction ``F`` is reported with the equivalent damping ``F / v`` it gives at the
    moves' speed.
    """
    j = params.total_inertia
    b = params.motor_viscous_friction + params.load_viscous_friction
    num, den, _ = signal.cont2discrete(([1.0], [j, b, 0.0]), dt, method="zoh")
    num = np.trim_zeros(np.ravel(num), "f")
    return {
        "inertia": j,
        "viscous": b,
        "coulomb": params.motor_coulomb_friction + params.load_coulomb_friction,
        "den": np.ravel(den).tolist(),
        "num": num.tolist(),
        "poles": np.sort(np.roots(np.ravel(den)).real).tolist(),
    }


def equivalent_damping(model: LinearModel, inertia: float, dt: float) -> float | None:
    """``b_eq = -J ln(p) / dt`` of the actuator pole farther from z = 1 (real poles only)."""
    poles = model.poles()
    if np.any(np.abs(poles.imag) > 1e-9):
        return None
    p = float(poles.real[np.argmax(np.abs(poles - 1.0))])
    return float(-inertia * np.log(p) / dt) if 0 < p < 1 else None
