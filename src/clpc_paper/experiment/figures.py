"""The paper's Figs. 5-17 (and one comparison figure) from an experiment run, as PNG files.

Figs. 5-12 (per cluster) are drawn here, Figs. 13-17 and the rich-command figure in
:mod:`clpc_paper.experiment.figures_signals`. Every figure carries the paper's number in its
title and units on its axes, and says what its marks are: clusters without an estimate are
gaps, windows at rest and untrusted windows are shaded and named, the convergence marker
and steady-state line are :func:`clpc_paper.experiment.marks.parameter_marks` (the report's rule).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from clpc_paper.experiment.figure_base import FILES, PARAM_NAMES, RICH_FILE, figure, footnote, save
from clpc_paper.experiment.figures_signals import (
    fig_estimated_position,
    fig_position,
    fig_position_error,
    fig_rich,
    fig_torque,
    fig_torque_error,
)
from clpc_paper.experiment.marks import (
    ParameterMarks,
    estimate_series,
    parameter_marks,
    window_states,
)
from clpc_paper.experiment.results import CommandResult, Identification, TorqueCheck
from clpc_paper.experiment.settings import LOG_SAMPLE_TIME

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

__all__ = ["FILES", "RICH_FILE", "draw_parameter", "write_figures"]


def _time_axis(ax: Axes, dt_cluster: float, t0: float) -> None:
    """Secondary x axis: the time [s] of the newest sample of cluster ``j``."""

    def to_time(j: ArrayLike) -> np.ndarray:
        return np.asarray(t0 + (np.asarray(j) - 1) * dt_cluster)

    def to_cluster(t: ArrayLike) -> np.ndarray:
        return np.asarray((np.asarray(t) - t0) / dt_cluster + 1)

    sec = ax.secondary_xaxis("top", functions=(to_time, to_cluster))
    sec.set_xlabel("time of the update [s]")


def _shade_windows(ax: Axes, ident: Identification) -> None:
    """Shade windows at rest ("not excited: undetermined") and other untrusted windows."""
    states = window_states(ident)
    for mask, color, label in (
        (states.at_rest, "0.75", "window at rest: not excited, undetermined"),
        (states.untrusted, "tab:orange", "window filling: not trusted"),
    ):
        for k, j in enumerate(np.flatnonzero(mask)):
            ax.axvspan(
                j + 0.5, j + 1.5, color=color, alpha=0.25, lw=0, label=label if k == 0 else None
            )


def _cluster_marks(ax: Axes, ident: Identification, marks: ParameterMarks) -> None:
    """Window-full line and the convergence marker (the report's rule, trusted updates)."""
    trace = ident.trace
    full = np.flatnonzero(trace.rows >= trace.rows.max())
    if full.size:
        ax.axvline(full[0] + 1, color="0.5", ls="--", lw=1, label="window full (201 rows)")
    if marks.cluster is not None:
        ax.axvline(
            marks.cluster,
            color="tab:green",
            ls=":",
            lw=1.5,
            label=f"convergence rule met (cluster {marks.cluster})",
        )


def _per_cluster(
    ax: Axes, ident: Identification, values: np.ndarray, label: str, marks: ParameterMarks
) -> None:
    trace = ident.trace
    clusters = np.arange(1, len(trace) + 1)
    _shade_windows(ax, ident)
    ax.plot(clusters, values, "o-", ms=3, lw=1, label=label)
    ax.set_xlabel("cluster j (an update every 12 samples = 0.12 s)")
    _cluster_marks(ax, ident, marks)
    dt_cluster = float(np.median(np.diff(trace.time))) if len(trace) > 1 else 0.12
    _time_axis(ax, dt_cluster, float(trace.time[0]))
    ax.set_xlim(0.5, len(trace) + 0.5)
    ax.grid(alpha=0.3)


def fig_command(path: Path, result: CommandResult, dpi: int) -> str:
    """Fig. 5: the position command (ramp with saturation) [rad]."""
    fig = figure()
    ax = fig.add_subplot()
    t = np.arange(result.command_log.size) * LOG_SAMPLE_TIME
    ax.plot(t, result.command_log, lw=1.5)
    ax.set(
        xlabel="time [s]",
        ylabel="position command [rad]",
        title="Fig. 5  Position command: ramp with saturation",
    )
    ax.grid(alpha=0.3)
    return save(fig, path, dpi)


def fig_d(path: Path, result: CommandResult, dpi: int) -> str:
    """Fig. 6: D = lambda_max - lambda_min for each cluster (control system)."""
    fig = figure((6.4, 4.4), top_axis=True, bottom=0.2)
    ax = fig.add_subplot()
    ident = result.control
    marks = parameter_marks(ident)
    _per_cluster(ax, ident, ident.trace.D, "D of the window", marks)
    d = result.summary["control_system"]["D"]
    cv = d["after_fill"].get("cv")
    ax.set(
        ylabel=r"D = $\lambda_{max} - \lambda_{min}$ [rad$^2$]",
        title="Fig. 6  D for each cluster (position command -> position)",
    )
    ax.legend(fontsize=7, loc="upper left")
    footnote(
        fig,
        f"Convergence rule: {marks.rule}. After the window is full D has cv "
        f"{cv:.2f} (quasi-constant: cv < 0.1): it falls as the ramp leaves the 2 s window."
        if cv is not None
        else f"Convergence rule: {marks.rule}.",
    )
    return save(fig, path, dpi)


def fig_parameter(path: Path, result: CommandResult, index: int, number: int, dpi: int) -> str:
    """Figs. 7-12: one entry of the unit-norm parameter vector per cluster."""
    fig = figure((6.4, 4.4), top_axis=True, bottom=0.2)
    ax = fig.add_subplot()
    draw_parameter(ax, result.control, index)
    name = PARAM_NAMES[index]
    ax.set_title(f"Fig. {number}  ${name}$ parameter (position command -> position)")
    marks = parameter_marks(result.control)
    footnote(
        fig,
        f"Gaps: clusters without an accepted estimate. Convergence rule: {marks.rule}; "
        "steady state = mean of the trusted updates from the marker on (band: their range).",
    )
    return save(fig, path, dpi)


def draw_parameter(ax: Axes, ident: Identification, index: int) -> ParameterMarks:
    """Theta entry ``index`` per cluster (gaps where no estimate), marker, steady state.

    Returns the :class:`ParameterMarks` drawn (the same the report's verdict reads).
    """
    marks = parameter_marks(ident)
    name = PARAM_NAMES[index]
    values = estimate_series(ident, ident.trace.theta[:, index])
    _per_cluster(ax, ident, values, f"${name}$ (held output)", marks)
    used = np.flatnonzero(marks.used) + 1
    if used.size:
        span = (used[0] - 0.5, used[-1] + 0.5)
        ax.fill_between(
            span,
            marks.low[index],
            marks.high[index],
            color="tab:red",
            alpha=0.12,
            lw=0,
            label="range of the averaged updates",
        )
        ax.plot(
            span,
            [marks.steady[index]] * 2,
            color="tab:red",
            lw=1.2,
            ls="-.",
            label=f"steady state {marks.steady[index]:.3f}",
        )
    ax.set_ylabel(f"${name}$ [-] (unit-norm $\\theta$)")
    ax.legend(fontsize=6.5, loc="best")
    return marks


def write_figures(
    out_dir: Path,
    ramp: CommandResult,
    rich: CommandResult,
    smooth: TorqueCheck,
    *,
    quick: bool = False,
) -> dict[int | str, str]:
    """Write Figs. 5-17 (from the ramp run) and the rich-command figure.

    Parameters
    ----------
    out_dir : Path
        Existing output folder.
    ramp, rich : CommandResult
        Results of :func:`clpc_paper.experiment.evaluation.analyse_command`.
    smooth : TorqueCheck
        The ramp's torque estimate on the servo without Coulomb friction (Figs. 13-14 (b)).
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
    out[13] = fig_torque(out_dir / FILES[13], ramp, smooth, dpi)
    out[14] = fig_torque_error(out_dir / FILES[14], ramp, smooth, dpi)
    out[15] = fig_position(out_dir / FILES[15], ramp, dpi)
    out[16] = fig_estimated_position(out_dir / FILES[16], ramp, dpi)
    out[17] = fig_position_error(out_dir / FILES[17], ramp, dpi)
    out["rich"] = fig_rich(out_dir / RICH_FILE, ramp, rich, dpi)
    return out
