"""One command through both identifications, evaluated against the global baselines.

:func:`analyse_command` simulates the servo for a command, identifies (a) the control
system and (b) the motor as actuator, and gathers the numbers of Figs. 6-17;
:func:`extended_ramp` and :func:`aliasing_check` are the two side checks of the report.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from clpc import ARX, LPC, LinearModel, ModelError, kstep_fit
from clpc.appraiser import decimate
from clpc_paper.experiment.analysis import (
    constant_windows,
    error_profile,
    excitation,
    fit,
    free_run,
    inverse_noise,
    linear_bound,
    online_prediction,
    stable_inverse,
)
from clpc_paper.experiment.identification import appraise, identify
from clpc_paper.experiment.results import CommandResult, Identification, TorqueCheck
from clpc_paper.experiment.settings import (
    A0_MIN,
    EXTENDED_RAMP_DURATION,
    LOG_SAMPLE_TIME,
    RAMP,
    RAMP_DURATION,
    SAMPLE_TIME,
)
from clpc_paper.experiment.statistics import (
    d_statistics,
    equivalent_damping,
    model_summary,
    parameter_statistics,
)
from clpc_paper.plants import ServoParameters, ramp_with_saturation, simulate_servo

__all__ = ["aliasing_check", "analyse_command", "extended_ramp", "torque_without_friction"]


def _global_models(ident: Identification, method: str) -> dict[str, LinearModel]:
    """The CLPC steady-state model beside one LPC and one least-squares fit of the record."""
    u, y = ident.u, ident.y
    return {
        "clpc": ident.model,
        "lpc": LPC(order=2, method=method).fit(u, y, dt=SAMPLE_TIME),
        "arx": ARX(order=2).fit(u, y, dt=SAMPLE_TIME),
    }


def _online(ident: Identification) -> dict[str, Any]:
    one = online_prediction(ident.trace, ident.u, ident.y, 1)
    ten = online_prediction(ident.trace, ident.u, ident.y, 10)
    return {"k1_fit": one["fit"], "k10_fit": ten["fit"], "coverage": ten["coverage"]}


def _rms_last_second(x: np.ndarray) -> float:
    n = round(1.0 / SAMPLE_TIME)
    return float(np.sqrt(np.mean(x[-n:] ** 2)))


def evaluate_control_system(
    ident: Identification, method: str, position_noise: np.ndarray, corner: float | None = None
) -> tuple[dict[str, Any], np.ndarray]:
    """Figs. 15-17 numbers and the global LPC / least-squares comparison (control system).

    ``position_noise`` is the decimated measured minus true position [rad]: its RMS over
    the last second is the noise level the position error is judged against.
    """
    u, y, model = ident.u, ident.y, ident.model
    y_hat = free_run(model, u, y)
    out: dict[str, Any] = {
        "model": model_summary(model),
        "position_error": error_profile(y - y_hat, SAMPLE_TIME, corner),
        "position_noise_level": _rms_last_second(position_noise),
        "baselines": {},
    }
    models = _global_models(ident, method)
    models["lpc_order1"] = LPC(order=1, method=method).fit(u, y, dt=SAMPLE_TIME)
    for name, m in models.items():
        out["baselines"][name] = {
            "simulation_fit": fit(y, free_run(m, u, y)),
            "k1_fit": float(kstep_fit(m, u, y, 1)),
            "k10_fit": float(kstep_fit(m, u, y, 10)),
            "stable": bool(m.is_stable),
        }
    out["baselines"]["clpc_online"] = _online(ident)
    return out, y_hat


def _window_fits(ident: Identification) -> dict[str, Any]:
    """Torque fit of each trusted window's own model (the best a single cluster gives).

    Also the best window's ``B(1)`` (``num_sum``) and the last trusted window's
    (``last_window_num_sum``).
    """
    trace, u, y = ident.trace, ident.u, ident.y
    best: dict[str, Any] = {"cluster": None, "time": None, "fit": None, "num_sum": None}
    last_b1 = None
    for j in np.flatnonzero(trace.trusted & trace.has_model & (trace.theta[:, 0] >= A0_MIN)):
        model = LinearModel(
            theta=trace.theta[j][None, :],
            structure=trace.structure,
            n_inputs=1,
            mode=trace.mode,
            c=np.atleast_1d(trace.c[j]),
            dt=SAMPLE_TIME,
        )
        with np.errstate(over="ignore", invalid="ignore"):
            f = fit(u, stable_inverse(model, y))
        last_b1 = float(model.num.sum())
        if f is not None and (best["fit"] is None or f > best["fit"]):
            best = {"cluster": int(j) + 1, "time": float(trace.time[j]), "fit": f}
            best["num_sum"] = last_b1
    best["last_window_num_sum"] = last_b1
    return best


def evaluate_actuator(
    ident: Identification,
    method: str,
    params: ServoParameters,
    position_noise: np.ndarray,
    corner: float | None = None,
) -> tuple[dict[str, Any], np.ndarray]:
    """Figs. 13-14 numbers (estimated torque), k-step fits and the rigid-body comparison.

    ``torque_noise_level`` is the RMS over the last second of the estimate's response to
    ``position_noise`` (decimated measured minus true position, :func:`inverse_noise`);
    ``torque_linear_bound`` the fit of the best linear estimate of the torque from the
    position (:func:`linear_bound`); ``torque_best_window`` the best trusted window's model.
    """
    u, y, model = ident.u, ident.y, ident.model
    out: dict[str, Any] = {"model": model_summary(model), "baselines": {}}
    try:
        causal = model.infer_input(y)
        out["causal_inverse"] = "finite" if np.all(np.isfinite(causal)) else "diverged"
    except ModelError as exc:
        out["causal_inverse"] = f"refused: {exc}"
    u_hat = stable_inverse(model, y)
    out["torque_fit"] = fit(u, u_hat)
    out["torque_error"] = error_profile(u - u_hat, SAMPLE_TIME, corner)
    out["torque_noise_level"] = _rms_last_second(inverse_noise(model, position_noise))
    out["torque_linear_bound"] = linear_bound(u, y)
    out["torque_best_window"] = _window_fits(ident)
    out["equivalent_damping"] = equivalent_damping(model, params.total_inertia, SAMPLE_TIME)
    for name, m in _global_models(ident, method).items():
        out["baselines"][name] = {
            "k1_fit": float(kstep_fit(m, u, y, 1)),
            "k10_fit": float(kstep_fit(m, u, y, 10)),
            "simulation_fit": fit(y, free_run(m, u, y)),
            "pole_distance_to_1": float(np.abs(m.poles() - 1.0).min()),
        }
    out["baselines"]["clpc_online"] = _online(ident)
    return out, u_hat


def analyse_command(
    name: str,
    command: np.ndarray,
    seed: Any,
    method: str,
    params: ServoParameters,
    corner: float | None = None,
) -> CommandResult:
    """Simulate the servo for one command and run both identifications on it.

    Parameters
    ----------
    name : str
        ``"ramp"`` or ``"rich"``.
    command : ndarray, shape (T,)
        Position command [rad] at :data:`LOG_SAMPLE_TIME`.
    seed : int or SeedSequence
        Servo noise seed.
    method : {"robust", "paper"}
    params : ServoParameters
    corner : float, optional
        Time of the command's saturation corner [s] (error reported there).
    """
    rec = simulate_servo(command, sample_time=LOG_SAMPLE_TIME, params=params, seed=seed)
    control = identify(rec.position_command, rec.position, method)
    actuator = identify(rec.torque_command, rec.position, method)
    noise = _position_noise(rec)
    cs, y_hat = evaluate_control_system(control, method, noise, corner)
    act, u_hat = evaluate_actuator(actuator, method, params, noise, corner)
    cs.update(D=d_statistics(control.trace), parameters=parameter_statistics(control))
    act.update(D=d_statistics(actuator.trace), parameters=parameter_statistics(actuator))
    summary = {
        "duration": float(rec.time[-1]),
        "excitation": excitation(np.asarray(command), LOG_SAMPLE_TIME),
        "torque_peak": float(np.abs(rec.torque_command).max()),
        "control_system": cs,
        "actuator": act,
    }
    return CommandResult(name, np.asarray(command), control, actuator, y_hat, u_hat, summary)


def _position_noise(rec: Any) -> np.ndarray:
    """Decimated measured minus true position [rad] (resolver noise and quantisation)."""
    factor = round(SAMPLE_TIME / LOG_SAMPLE_TIME)
    true = rec.true_position if rec.params.feedback_on_load else rec.motor_position
    return np.asarray(decimate(rec.position, factor) - decimate(true, factor))


def torque_without_friction(
    command: np.ndarray, seed: Any, method: str, params: ServoParameters, corner: float
) -> TorqueCheck:
    """The actuator identification and torque estimate on the servo without Coulomb friction.

    Same command, seed and settings as the main run; only ``motor_coulomb_friction`` and
    ``load_coulomb_friction`` are 0. What changes between the two runs is what the
    friction does.
    """
    smooth = params.replace(motor_coulomb_friction=0.0, load_coulomb_friction=0.0)
    rec = simulate_servo(command, sample_time=LOG_SAMPLE_TIME, params=smooth, seed=seed)
    actuator = identify(rec.torque_command, rec.position, method)
    act, u_hat = evaluate_actuator(actuator, method, smooth, _position_noise(rec), corner)
    act.pop("baselines")
    act["parameters"] = parameter_statistics(actuator)
    return TorqueCheck(actuator.u, u_hat, act)


def extended_ramp(seed: Any, method: str, params: ServoParameters) -> dict[str, Any]:
    """The ramp record continued to 6 s: what the appraiser does once nothing moves.

    ``constant_command_windows`` counts the later windows whose (decimated) command does not
    change at all - nothing to identify - independently of the appraiser's own
    ``degenerate`` flag, reported beside it.
    """
    cmd = ramp_with_saturation(
        EXTENDED_RAMP_DURATION,
        LOG_SAMPLE_TIME,
        start=RAMP.start,
        ramp_time=RAMP.ramp_time,
        level=RAMP.level,
    )
    rec = simulate_servo(cmd, sample_time=LOG_SAMPLE_TIME, params=params, seed=seed)
    ident = identify(rec.position_command, rec.position, method)
    trace = ident.trace
    late = trace.time > RAMP_DURATION
    constant = constant_windows(trace, ident.u)
    return {
        "duration": EXTENDED_RAMP_DURATION,
        "updates_after_ramp_left_window": int(late.sum()),
        "constant_command_windows": int(np.sum(constant & late)),
        "degenerate_flagged": int(np.sum(trace.degenerate & late)),
        "accepted_after": int(np.sum(trace.accepted & late)),
        "accepted_constant_command": int(np.sum(trace.accepted & constant)),
        "accepted_without_a0": int(np.sum(trace.accepted & (trace.theta_estimate[:, 0] < A0_MIN))),
        "D_last": float(trace.D[-1]),
        "D_max": float(trace.D.max()),
        "held_theta_last": trace.theta[-1].tolist(),
    }


def aliasing_check(
    command_fn: Callable[[float], np.ndarray], seed: Any, method: str, params: ServoParameters
) -> dict[str, Any]:
    """Actuator identified from a log taken directly at 10 ms (torque samples aliased)."""
    cmd = command_fn(SAMPLE_TIME)
    rec = simulate_servo(cmd, sample_time=SAMPLE_TIME, params=params, seed=seed)
    ident = appraise(rec.torque_command, rec.position, SAMPLE_TIME, method)
    return {"log_sample_time": SAMPLE_TIME, "model": model_summary(ident.model)}
