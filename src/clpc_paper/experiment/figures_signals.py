"""Figs. 13-17 (torque and position against time) and the rich-command figure.

Each figure says what it shows: the fit or error numbers of ``summary.json`` in the panel
titles, the noise level as a band, the ramp's corner and the rest before the ramp marked.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from clpc_paper.experiment.claims import fmt
from clpc_paper.experiment.figure_base import PARAM_NAMES, figure, footnote, save, times
from clpc_paper.experiment.results import CommandResult, TorqueCheck
from clpc_paper.experiment.settings import RAMP

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

__all__ = [
    "fig_estimated_position",
    "fig_position",
    "fig_position_error",
    "fig_rich",
    "fig_torque",
    "fig_torque_error",
]

_INVERSE = (
    "estimate: steady-state actuator model run backwards, u = (den(z) y - k)/num(z) "
    "(stable inverse)"
)


def _torque_panel(
    ax: Axes, u: np.ndarray, u_hat: np.ndarray, act: dict[str, Any], what: str
) -> None:
    t = times(u.size)
    ax.axvspan(0.0, RAMP.start, color="0.75", alpha=0.35, lw=0, label="at rest before the ramp")
    ax.plot(t, u, lw=1.2, label="experimental torque command")
    ax.plot(t, u_hat, lw=1.0, ls="--", label="estimated torque command")
    ax.set_title(f"{what}: torque fit {fmt(act['torque_fit'], '.1f')} %", fontsize=9)
    ax.set_ylabel("torque [N m]")
    ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.3)


def fig_torque(path: Path, result: CommandResult, smooth: TorqueCheck, dpi: int) -> str:
    """Fig. 13: experimental and estimated torque command [N m], with and without friction."""
    fig = figure((6.4, 5.6), bottom=0.12)
    fig.subplots_adjust(hspace=0.45, top=0.9)
    top, bottom = fig.subplots(2, 1, sharex=True)
    act = result.summary["actuator"]
    _torque_panel(top, result.actuator.u, result.torque_hat, act, "(a) servo of Table 1")
    _torque_panel(
        bottom, smooth.u, smooth.u_hat, smooth.summary, "(b) same ramp, no Coulomb friction"
    )
    bottom.set_xlabel("time [s]")
    fig.suptitle("Fig. 13  Experimental and estimated torque command [N m]", fontsize=11)
    footnote(
        fig,
        f"{_INVERSE}. Best linear estimate from the position on (a), least squares on "
        f"the same record: fit {fmt(act['torque_linear_bound'], '.1f')} %.",
    )
    return save(fig, path, dpi)


def _error_panel(ax: Axes, err: np.ndarray, act: dict[str, Any], what: str) -> None:
    t = times(err.size)
    noise = 1e3 * act["torque_noise_level"]
    ax.axvspan(0.0, RAMP.start, color="0.75", alpha=0.35, lw=0, label="at rest before the ramp")
    ax.axhspan(-noise, noise, color="tab:green", alpha=0.2, lw=0, label="noise level (+-)")
    ax.plot(t, 1e3 * err, lw=1.0, color="tab:red", label="experimental - estimated")
    ax.axhline(0.0, color="0.4", lw=0.8)
    e = act["torque_error"]
    ax.set_title(
        f"{what}: RMS last second {1e3 * e['rms_last_second']:.2f} mN m, noise level "
        f"{noise:.2f} mN m",
        fontsize=9,
    )
    ax.set_ylabel("torque error [mN m]")
    ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.3)


def fig_torque_error(path: Path, result: CommandResult, smooth: TorqueCheck, dpi: int) -> str:
    """Fig. 14: the torque identification error [N m], with and without friction."""
    fig = figure((6.4, 5.6), bottom=0.12)
    fig.subplots_adjust(hspace=0.45, top=0.9)
    top, bottom = fig.subplots(2, 1, sharex=True)
    _error_panel(
        top, result.actuator.u - result.torque_hat, result.summary["actuator"], "(a) Table 1 servo"
    )
    _error_panel(bottom, smooth.u - smooth.u_hat, smooth.summary, "(b) no Coulomb friction")
    bottom.set_xlabel("time [s]")
    fig.suptitle("Fig. 14  Torque command identification error (exp. - est.)", fontsize=11)
    footnote(
        fig,
        "Noise level: RMS over the last second of the estimate's response to the resolver's "
        "noise and quantisation alone (measured minus true position, run through the inverse).",
    )
    return save(fig, path, dpi)


def fig_position(path: Path, result: CommandResult, dpi: int) -> str:
    """Fig. 15: the experimental (measured) position [rad] with the command."""
    ctl = result.control
    fig = figure()
    ax = fig.add_subplot()
    t = times(ctl.y.size)
    ax.plot(t, ctl.u, color="0.6", lw=1.0, ls=":", label="position command")
    ax.plot(t, ctl.y, lw=1.5, label="experimental (measured) position")
    ax.set(xlabel="time [s]", ylabel="angular position [rad]")
    ax.set_title("Fig. 15  Experimental angular position of the motor")
    ax.legend(fontsize=8, loc="best")
    ax.grid(alpha=0.3)
    return save(fig, path, dpi)


def fig_estimated_position(path: Path, result: CommandResult, dpi: int) -> str:
    """Fig. 16: the estimated position [rad], and a zoom on the corner against the measured."""
    ctl = result.control
    fig = figure((6.4, 5.6), bottom=0.1)
    fig.subplots_adjust(hspace=0.4, top=0.92)
    top, zoom = fig.subplots(2, 1)
    t = times(ctl.y.size)
    top.plot(t, ctl.u, color="0.6", lw=1.0, ls=":", label="position command")
    top.plot(t, result.position_hat, lw=1.5, color="tab:orange", label="estimated (model free run)")
    top.set(xlabel="time [s]", ylabel="angular position [rad]")
    top.legend(fontsize=8, loc="best")
    diff = 1e3 * (ctl.y - result.position_hat)
    zoom.plot(t, diff, lw=1.0, color="tab:red", label="experimental (Fig. 15) - estimated")
    zoom.axhline(0.0, color="0.4", lw=0.8)
    zoom.set(xlabel="time [s]", ylabel="difference [mrad]")
    zoom.set_title(
        "difference panel: the two position curves coincide within "
        f"{np.nanmax(np.abs(diff)):.2f} mrad (= Fig. 17)",
        fontsize=9,
    )
    zoom.legend(fontsize=7, loc="best")
    for ax in (top, zoom):
        ax.grid(alpha=0.3)
    fig.suptitle("Fig. 16  Estimated angular position of the motor", fontsize=11)
    return save(fig, path, dpi)


def fig_position_error(path: Path, result: CommandResult, dpi: int) -> str:
    """Fig. 17: the position identification error [mrad], corner and rest marked."""
    ctl = result.control
    cs = result.summary["control_system"]
    e, noise = cs["position_error"], 1e3 * cs["position_noise_level"]
    fig = figure(bottom=0.2)
    ax = fig.add_subplot()
    t = times(ctl.y.size)
    err = 1e3 * (ctl.y - result.position_hat)
    ax.axvspan(0.0, RAMP.start, color="0.75", alpha=0.35, lw=0, label="at rest before the ramp")
    ax.axhspan(-noise, noise, color="tab:green", alpha=0.2, lw=0, label="noise level (+-)")
    ax.plot(t, err, lw=1.0, color="tab:red", label="experimental - estimated")
    ax.axvline(RAMP.corner, color="0.3", ls="--", lw=1, label=f"ramp corner {RAMP.corner:.1f} s")
    ax.axhline(0.0, color="0.4", lw=0.8)
    if not e.get("diverged"):
        k = int(np.argmax(np.abs(err)))
        ax.plot(t[k], err[k], "ko", ms=4, label=f"largest |error| {abs(err[k]):.2f} mrad")
    ax.set(xlabel="time [s]", ylabel="position error [mrad]")
    ax.set_title("Fig. 17  Position identification error (exp. - est.)")
    ax.legend(fontsize=6.5, loc="best", ncol=2)
    ax.grid(alpha=0.3)
    if not e.get("diverged"):
        m = cs["model"]
        static = (
            f" Model's static map y = {m['dc_gain']:.5f} r {1e3 * m['static_offset']:+.3f} mrad: "
            f"off by {-1e3 * m['static_offset']:+.3f} mrad at rest (r = 0)."
            if m.get("static_offset") is not None and m.get("dc_gain") is not None
            else ""
        )
        footnote(
            fig,
            f"RMS first second {1e3 * e['rms_first_second']:.3f} mrad, last second "
            f"{1e3 * e['rms_last_second']:.3f} mrad; noise level (RMS of measured - true "
            f"position, last second) {noise:.3f} mrad.{static}",
        )
    return save(fig, path, dpi)


def fig_rich(path: Path, ramp: CommandResult, rich: CommandResult, dpi: int) -> str:
    """The richer command beside the ramp: command, D, parameters, estimated torque."""
    fig = figure((11.0, 7.0))
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.08, top=0.95, hspace=0.35, wspace=0.2)
    axes = fig.subplots(2, 2)
    ctl = rich.control
    t = times(ctl.y.size)
    show = t <= 6.0
    ax = axes[0, 0]
    ax.plot(t[show], ctl.u[show], color="0.5", lw=1, label="command")
    ax.plot(t[show], ctl.y[show], lw=1.2, label="measured position")
    ax.set(xlabel="time [s]", ylabel="position [rad]")
    ax.set_title("Rich command: ramp-and-hold moves (2 s period) + PRBS dither", fontsize=10)
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    for res, style, label in ((ramp, "s-", "ramp (Fig. 6)"), (rich, "o-", "rich command")):
        tr = res.control.trace
        ax.plot(tr.time, tr.D, style, ms=2.5, lw=1, label=label)
    ax.set(xlabel="time of the update [s]", ylabel="D [rad$^2$]")
    ax.set_title("D per cluster: ramp vs rich command", fontsize=10)
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    tr = ctl.trace
    ok = np.asarray(tr.accepted & tr.has_model, dtype=bool)
    for i, name in enumerate(PARAM_NAMES):
        values = np.where(ok, tr.theta[:, i], np.nan)
        ax.plot(tr.time, values, lw=1, ls="-" if i < 3 else "--", label=f"${name}$")
    if ctl.convergence.converged:
        ax.axvline(ctl.convergence.time, color="tab:green", ls=":", label="convergence rule met")
    ax.set(xlabel="time of the update [s]", ylabel="unit-norm $\\theta$ [-]")
    frac = float(np.mean(tr.trusted))
    ax.set_title(
        f"Figs. 7-12 analogue: parameters, rich command (b: dashed); {frac:.0%} of windows trusted",
        fontsize=10,
    )
    ax.legend(fontsize=7, ncol=4)
    ax = axes[1, 1]
    act = rich.actuator
    ta = times(act.u.size)
    zoom = (ta >= 4.0) & (ta <= 8.0)
    ax.plot(ta[zoom], act.u[zoom], lw=1.2, label="experimental")
    ax.plot(ta[zoom], rich.torque_hat[zoom], lw=1, ls="--", label="estimated")
    ax.set(xlabel="time [s]", ylabel="torque command [N m]")
    fit = fmt(rich.summary["actuator"]["torque_fit"], ".1f")
    ax.set_title(f"Fig. 13 analogue: torque, rich command (4-8 s), fit {fit} %", fontsize=10)
    ax.legend(fontsize=8)
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
    return save(fig, path, dpi)
