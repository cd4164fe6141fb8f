"""The paper's Figs. 5-17 (and one comparison figure) from an experiment run, as PNG files.

Headless: figures are built with :class:`matplotlib.figure.Figure` on the Agg canvas
(no pyplot, no global backend switch), and matplotlib is imported only inside the
functions. Every figure carries the paper's number in its title and units on its axes.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from clpc.experiment.results import CommandResult, Identification
from clpc.experiment.settings import LOG_SAMPLE_TIME, SAMPLE_TIME

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["write_figures"]

FILES = {
    5: "fig05_command.png",
    6: "fig06_D.png",
    7: "fig07_a01.png",
    8: "fig08_a11.png",
    9: "fig09_a21.png",
    10: "fig10_b01.png",
    11: "fig11_b11.png",
    12: "fig12_b21.png",
    13: "fig13_torque.png",
    14: "fig14_torque_error.png",
    15: "fig15_position.png",
    16: "fig16_estimated_position.png",
    17: "fig17_position_error.png",
}
RICH_FILE = "figR_rich_command.png"
_PARAM_NAMES = ("a_{01}", "a_{11}", "a_{21}", "b_{01}", "b_{11}", "b_{21}")


def _figure(size: tuple[float, float] = (6.4, 3.6), *, top_axis: bool = False) -> Figure:
    """A figure with fixed margins (no layout engine: half the drawing time)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=size)
    fig.subplots_adjust(left=0.13, right=0.97, bottom=0.14, top=0.76 if top_axis else 0.9)
    return fig


def _save(fig: Figure, path: Path, dpi: int) -> str:
    fig.savefig(path, dpi=dpi)
    return path.name


def _time_axis(ax: Axes, dt_cluster: float, t0: float) -> None:
    """Secondary x axis: the time [s] of the newest sample of cluster ``j``."""

    def to_time(j: ArrayLike) -> np.ndarray:
        return np.asarray(t0 + (np.asarray(j) - 1) * dt_cluster)

    def to_cluster(t: ArrayLike) -> np.ndarray:
        return np.asarray((np.asarray(t) - t0) / dt_cluster + 1)

    sec = ax.secondary_xaxis("top", functions=(to_time, to_cluster))
    sec.set_xlabel("time of the update [s]")


def _cluster_marks(ax: Axes, ident: Identification) -> None:
    """Window-full and convergence markers on a per-cluster plot."""
    trace = ident.trace
    full = np.flatnonzero(trace.rows >= trace.rows.max())
    if full.size:
        ax.axvline(full[0] + 1, color="0.5", ls="--", lw=1, label="window full (201 rows)")
    if ident.convergence.converged:
        ax.axvline(
            ident.convergence.update + 1,
            color="tab:green",
            ls=":",
            lw=1.5,
            label="quasi-constant from here",
        )


def _per_cluster(ax: Axes, ident: Identification, values: np.ndarray, label: str) -> None:
    trace = ident.trace
    clusters = np.arange(1, len(trace) + 1)
    ax.plot(clusters, values, "o-", ms=3, lw=1, label=label)
    ax.set_xlabel("cluster j (an update every 12 samples = 0.12 s)")
    _cluster_marks(ax, ident)
    dt_cluster = float(np.median(np.diff(trace.time))) if len(trace) > 1 else 0.12
    _time_axis(ax, dt_cluster, float(trace.time[0]))
    ax.grid(alpha=0.3)


def fig_command(path: Path, result: CommandResult, dpi: int) -> str:
    """Fig. 5: the position command (ramp with saturation) [rad]."""
    fig = _figure()
    ax = fig.add_subplot()
    t = np.arange(result.command_log.size) * LOG_SAMPLE_TIME
    ax.plot(t, result.command_log, lw=1.5)
    ax.set(
        xlabel="time [s]",
        ylabel="position command [rad]",
        title="Fig. 5  Position command: ramp with saturation",
    )
    ax.grid(alpha=0.3)
    return _save(fig, path, dpi)


def fig_d(path: Path, result: CommandResult, dpi: int) -> str:
    """Fig. 6: D = lambda_max - lambda_min for each cluster (control system)."""
    fig = _figure(top_axis=True)
    ax = fig.add_subplot()
    ident = result.control
    _per_cluster(ax, ident, ident.trace.D, "D")
    ax.set(
        ylabel=r"D = $\lambda_{max} - \lambda_{min}$ [rad$^2$]",
        title="Fig. 6  D for each cluster (position command -> position)",
    )
    ax.legend(fontsize=8, loc="best")
    return _save(fig, path, dpi)


def fig_parameter(path: Path, result: CommandResult, index: int, number: int, dpi: int) -> str:
    """Figs. 7-12: one entry of the unit-norm parameter vector per cluster."""
    fig = _figure(top_axis=True)
    ax = fig.add_subplot()
    ident = result.control
    name = _PARAM_NAMES[index]
    _per_cluster(ax, ident, ident.trace.theta[:, index], f"${name}$ (held output)")
    ax.axhline(
        ident.model.theta_matrix[0, index],
        color="tab:red",
        lw=1,
        ls="-.",
        label="steady-state value",
    )
    ax.set(
        ylabel=f"${name}$ [-] (unit-norm $\\theta$)",
        title=f"Fig. {number}  ${name}$ parameter (position command -> position)",
    )
    ax.legend(fontsize=8, loc="best")
    return _save(fig, path, dpi)


def _time(n: int) -> np.ndarray:
    return np.arange(n) * SAMPLE_TIME


def fig_torque(path: Path, result: CommandResult, dpi: int) -> str:
    """Fig. 13: experimental and estimated torque command [N m]."""
    fig = _figure()
    ax = fig.add_subplot()
    u, u_hat = result.actuator.u, result.torque_hat
    t = _time(u.size)
    ax.plot(t, u, lw=1.2, label="experimental torque command")
    ax.plot(t, u_hat, lw=1.0, ls="--", label="estimated (actuator model inverse)")
    ax.set(
        xlabel="time [s]",
        ylabel="torque command [N m]",
        title="Fig. 13  Experimental and estimated torque command",
    )
    ax.legend(fontsize=8, loc="best")
    ax.grid(alpha=0.3)
    return _save(fig, path, dpi)


def fig_error(path: Path, t: np.ndarray, err: np.ndarray, ylabel: str, title: str, dpi: int) -> str:
    """Figs. 14 and 17: an identification error against time."""
    fig = _figure()
    ax = fig.add_subplot()
    ax.plot(t, err, lw=1.0, color="tab:red")
    ax.axhline(0.0, color="0.4", lw=0.8)
    ax.set(xlabel="time [s]", ylabel=ylabel, title=title)
    ax.grid(alpha=0.3)
    return _save(fig, path, dpi)


def fig_position(
    path: Path, t: np.ndarray, y: np.ndarray, command: np.ndarray, label: str, title: str, dpi: int
) -> str:
    """Figs. 15 and 16: a position signal [rad] with the command for reference."""
    fig = _figure()
    ax = fig.add_subplot()
    ax.plot(t, command, color="0.6", lw=1.0, ls=":", label="position command")
    ax.plot(t, y, lw=1.5, label=label)
    ax.set(xlabel="time [s]", ylabel="angular position [rad]", title=title)
    ax.legend(fontsize=8, loc="best")
    ax.grid(alpha=0.3)
    return _save(fig, path, dpi)


def fig_rich(path: Path, ramp: CommandResult, rich: CommandResult, dpi: int) -> str:
    """The richer command beside the ramp: command, D, parameters, estimated torque."""
    fig = _figure((11.0, 7.0))
    fig.subplots_adjust(left=0.07, right=0.98, bottom=0.08, top=0.95, hspace=0.35, wspace=0.2)
    axes = fig.subplots(2, 2)
    ctl = rich.control
    t = _time(ctl.y.size)
    show = t <= 6.0
    ax = axes[0, 0]
    ax.plot(t[show], ctl.u[show], color="0.5", lw=1, label="command")
    ax.plot(t[show], ctl.y[show], lw=1.2, label="measured position")
    ax.set(
        xlabel="time [s]",
        ylabel="position [rad]",
        title="Rich command: ramp-and-hold moves (2 s period) + PRBS dither",
    )
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    for res, style in ((ramp, "s-"), (rich, "o-")):
        tr = res.control.trace
        ax.plot(tr.time, tr.D, style, ms=2.5, lw=1, label=f"{res.name} (Fig. 6 analogue)")
    ax.set(
        xlabel="time of the update [s]",
        ylabel="D [rad$^2$]",
        title="D per cluster: ramp vs rich command",
    )
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    tr = ctl.trace
    for i, name in enumerate(_PARAM_NAMES):
        ax.plot(tr.time, tr.theta[:, i], lw=1, label=f"${name}$")
    if ctl.convergence.converged:
        ax.axvline(ctl.convergence.time, color="tab:green", ls=":", label="quasi-constant")
    ax.set(
        xlabel="time of the update [s]",
        ylabel="unit-norm $\\theta$ [-]",
        title="Figs. 7-12 analogue: parameters, rich command",
    )
    ax.legend(fontsize=7, ncol=4)
    ax = axes[1, 1]
    act = rich.actuator
    ta = _time(act.u.size)
    zoom = (ta >= 4.0) & (ta <= 8.0)
    ax.plot(ta[zoom], act.u[zoom], lw=1.2, label="experimental")
    ax.plot(ta[zoom], rich.torque_hat[zoom], lw=1, ls="--", label="estimated")
    ax.set(
        xlabel="time [s]",
        ylabel="torque command [N m]",
        title="Fig. 13 analogue: torque, rich command (4-8 s)",
    )
    ax.legend(fontsize=8)
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
    return _save(fig, path, dpi)


def write_figures(
    out_dir: Path, ramp: CommandResult, rich: CommandResult, *, quick: bool = False
) -> dict[int | str, str]:
    """Write Figs. 5-17 (from the ramp run) and the rich-command figure.

    Parameters
    ----------
    out_dir : Path
        Existing output folder.
    ramp, rich : CommandResult
        Results of :func:`clpc.experiment.evaluation.analyse_command`.
    quick : bool
        Lower resolution (faster).

    Returns
    -------
    dict
        Figure number (or ``"rich"``) -> file name.
    """
    dpi = 60 if quick else 110
    out: dict[int | str, str] = {
        5: fig_command(out_dir / FILES[5], ramp, dpi),
        6: fig_d(out_dir / FILES[6], ramp, dpi),
    }
    for i in range(6):
        out[7 + i] = fig_parameter(out_dir / FILES[7 + i], ramp, i, 7 + i, dpi)
    out[13] = fig_torque(out_dir / FILES[13], ramp, dpi)
    act, ctl = ramp.actuator, ramp.control
    out[14] = fig_error(
        out_dir / FILES[14],
        _time(act.u.size),
        act.u - ramp.torque_hat,
        "torque error [N m]",
        "Fig. 14  Torque command identification error (exp. - est.)",
        dpi,
    )
    t = _time(ctl.y.size)
    out[15] = fig_position(
        out_dir / FILES[15],
        t,
        ctl.y,
        ctl.u,
        "experimental position",
        "Fig. 15  Experimental angular position of the motor",
        dpi,
    )
    out[16] = fig_position(
        out_dir / FILES[16],
        t,
        ramp.position_hat,
        ctl.u,
        "estimated position (control-system model, free run)",
        "Fig. 16  Estimated angular position",
        dpi,
    )
    out[17] = fig_error(
        out_dir / FILES[17],
        t,
        1e3 * (ctl.y - ramp.position_hat),
        "position error [mrad]",
        "Fig. 17  Position identification error (exp. - est.)",
        dpi,
    )
    out["rich"] = fig_rich(out_dir / RICH_FILE, ramp, rich, dpi)
    return out
