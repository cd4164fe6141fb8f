"""The numeric criteria of the actuator's claims (Figs. 13-14), one function per claim.

The same verdict dicts and thresholds as :mod:`clpc_paper.experiment.claim_checks`: each
``check_*`` reads the actuator identification's part of the JSON-safe summary.
"""

from __future__ import annotations

from typing import Any

from clpc_paper.experiment.claim_checks import (
    NOISE_MARGIN,
    POLE_NEAR_ONE,
    TORQUE_FIT_GOOD,
    _num,
    _result,
    fmt,
    fmt_poles,
)

__all__ = ["check_actuator", "check_torque"]


def check_actuator(act: dict[str, Any], rigid: dict[str, Any]) -> dict[str, Any]:
    """Figs. 13-14: the actuator model has an integrating pole (``rigid``: the rigid body)."""
    m = act["model"]
    poles = fmt_poles(m["poles"])
    text = (
        f"poles {poles} (closest to 1 at {m['pole_distance_to_1']:.4f}); rigid body "
        f"{', '.join(f'{p:.4f}' for p in rigid['poles'])}"
    )
    if act.get("equivalent_damping") is not None:
        text += (
            f"; second pole = viscous damping {act['equivalent_damping']:.4f} N m s/rad "
            f"(servo: {rigid['viscous']:.4f} viscous, Coulomb {rigid['coulomb']:.3f} N m)"
        )
    return _result(
        (m["pole_distance_to_1"] < POLE_NEAR_ONE,),
        text,
        f"a pole within {POLE_NEAR_ONE} of z = 1",
        "torque -> position integrates (rigid-body pole exactly 1); at 10 ms a pole at "
        "0.95 is a 0.2 s time constant, already shorter than the moves",
        f"the nearest pole is {m['pole_distance_to_1']:.3f} from 1 (A(1) = "
        f"{m['den_sum']:.2g}): the ramp windows hold constant-velocity motion, which does "
        "not separate A(z) from B(z)",
    )


def check_torque(act: dict[str, Any], smooth: dict[str, Any] | None) -> dict[str, Any]:
    """Figs. 13-14: the torque estimate tracks and ends at the noise (``smooth``: no friction)."""
    e, fit = act["torque_error"], act["torque_fit"]
    criterion = (
        f"torque fit >= {TORQUE_FIT_GOOD:.0f} % and RMS(error, last second) <= "
        f"{NOISE_MARGIN} x noise level"
    )
    why = (
        f"{TORQUE_FIT_GOOD:.0f} %: the error is at most a fifth of the torque's variation, "
        "visibly tracking; the noise level is what the resolver's noise and quantisation "
        f"alone put into the estimate, and errors add in quadrature, so {NOISE_MARGIN} x "
        "leaves the model an error about as large as the noise"
    )
    if e.get("diverged"):
        return _result((False,), "the estimated torque diverged", criterion, why, "diverged")
    tracks = fit is not None and fit >= TORQUE_FIT_GOOD
    noise = act["torque_noise_level"]
    settled = e["rms_last_second"] <= NOISE_MARGIN * noise
    best = act["torque_best_window"]
    text = (
        f"torque fit {fmt(fit, '.1f')} %; error RMS last second {1e3 * e['rms_last_second']:.2f}"
        f" mN m vs noise level {1e3 * noise:.2f} mN m; best linear estimate from the position "
        f"(least squares on this record) {fmt(act['torque_linear_bound'], '.1f')} %; best "
        f"single trusted window {fmt(best['fit'], '.1f')} % (cluster {best['cluster']})"
    )
    if e.get("mean_before_ramp") is not None:
        text += f"; mean error at rest before the ramp {1e3 * e['mean_before_ramp']:.2f} mN m"
        u0 = act["model"].get("input_at_zero")
        if u0 is not None:
            text += (
                f", the model's own torque for y = 0 being -k/B(1) = {1e3 * u0:.2f} mN m "
                f"(intercept k = {act['model']['intercept']:.3g} fitted at the windows' "
                f"operating point, A(1) = {act['model']['den_sum']:.2g})"
            )
    reason = (
        f"no linear estimate of this torque from this position reaches "
        f"{TORQUE_FIT_GOOD:.0f} % (least squares on the record itself: "
        f"{fmt(act['torque_linear_bound'], '.0f')} %): Coulomb friction makes the torque -> "
        "position relation nonlinear"
        if _num(act["torque_linear_bound"]) < TORQUE_FIT_GOOD
        else "the steady-state model is worse than the best linear estimate"
    )
    if fit is not None and _num(best["fit"]) > fit + 10.0:
        reason += (
            f"; the steady-state model (B(1) = {act['model']['num_sum']:.3g}) averages "
            f"windows that fit worse than the best one ({fmt(best['fit'], '.0f')} %): once "
            "the ramp's start has left them, friction holds the motor while the torque changes"
        )
    if smooth is not None:
        se = smooth["torque_error"]
        text += (
            f". Same ramp without Coulomb friction: fit {fmt(smooth['torque_fit'], '.1f')} %, "
            f"RMS last second {1e3 * se['rms_last_second']:.2f} vs noise "
            f"{1e3 * smooth['torque_noise_level']:.2f} mN m"
        )
    return _result((tracks, settled), text, criterion, why, reason)
