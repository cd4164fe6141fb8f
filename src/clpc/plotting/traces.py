"""The figure of a CLPC trace: ``D`` and every parameter on its own scale."""

from __future__ import annotations

from os import PathLike
from typing import Any

import numpy as np

from clpc.core.figure import (
    COLORS,
    MAX_POINTS,
    Margins,
    axes_for,
    draw_signal,
    new_grid,
    place_legend,
    save_figure,
    time_label,
)

__all__ = ["plot_trace", "trace_panels"]

#: flagged updates are drawn one marker each up to this count, else as shaded bins
MAX_MARKERS = 300

#: the figure's labels are known (one-line y labels, numbers of at most 7 characters, a
#: legend above D only): fixed margins place it, at two thirds of the constrained layout's
#: drawing time
_MARGINS = Margins(left=0.95, right=0.25, top=0.62, bottom=0.55, row_gap=0.66, col_gap=1.2)


def trace_panels(trace: Any) -> int:
    """Axes :func:`plot_trace` draws on: per output, one for ``D`` and one per parameter."""
    return trace.n_equations * (1 + len(trace.labels()))


def _flag_bins(t: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bin starts and whether any update in each bin is flagged (at most MAX_POINTS bins)."""
    if t.size <= MAX_POINTS:
        return t, mask
    starts = np.linspace(0, t.size, MAX_POINTS, endpoint=False).astype(np.intp)
    return t[starts], np.logical_or.reduceat(mask, starts)


def _mark(ax: Any, t: np.ndarray, d: np.ndarray, mask: np.ndarray, what: str, marker: str):
    """Flagged updates: markers on the ``D`` curve, or shaded bins when there are many."""
    n = int(mask.sum())
    if not n:
        return
    label = f"{what} ({n})"
    if n <= MAX_MARKERS:
        kw = {"mfc": "none"} if marker == "o" else {}
        ax.plot(t[mask], d[mask], marker, ms=4, color=COLORS[what], label=label, **kw)
        return
    tb, mb = _flag_bins(t, mask)
    ax.fill_between(
        tb, 0, 1, where=mb, step="post", color=COLORS[what], alpha=0.25, lw=0, label=label,
        transform=ax.get_xaxis_transform(),
    )  # fmt: skip


def plot_trace(
    trace: Any,
    path: str | PathLike[str] | None = None,
    *,
    title: str | None = None,
    ax: Any = None,
) -> Any:
    """Plot a CLPC trace: ``D`` and each entry of ``theta`` on its own axes, per update.

    Parameters
    ----------
    trace : Trace
        Output of :meth:`clpc.CLPC.run` (or concatenated :meth:`clpc.CLPC.push` results).
    path : str or path-like, optional
        Also write the figure as PNG here (parent folders are created).
    title : str, optional
        Figure title (default: the number of updates).
    ax : sequence of matplotlib Axes, optional
        :func:`trace_panels` axes to draw on, per output ``[D, theta_0, ..., theta_p-1]``;
        default: a new figure (``D`` across the top, the parameters two per row).

    Returns
    -------
    matplotlib.figure.Figure

    Notes
    -----
    ``D = lambda_max - lambda_min`` is drawn on a log axis, the held parameter vector
    ``theta`` (paper convention, unit norm: dimensionless) one entry per panel, so entries
    of very different size each use their scale. Flagged updates are marked on the ``D``
    panel: not accepted (the last accepted estimate is held), not determined by the
    window, too few rows (grey). Above :data:`clpc.core.figure.MAX_POINTS` updates every
    curve is drawn as its min/max envelope and flags as shaded bins.
    """
    labels = trace.labels()
    n_eq, p = trace.n_equations, len(labels)
    if ax is None:
        n_rows = -(-p // 2)
        fig, grid = new_grid(n_eq * (1 + n_rows), 2, _MARGINS, height=1.7)
        axes = []
        for e in range(n_eq):
            top = e * (1 + n_rows)
            axes.append(fig.add_subplot(grid[top, :]))
            axes += [fig.add_subplot(grid[top + 1 + k // 2, k % 2]) for k in range(p)]
    else:
        fig, axes = axes_for(ax, trace_panels(trace))
    t = np.asarray(trace.time, dtype=float)
    xlabel = time_label(trace.sample_time)
    few = np.asarray(trace.not_enough_data, dtype=bool)
    for e in range(n_eq):
        name = trace.output_names[e] if e < len(trace.output_names) else f"y{e}"
        ax_d, ax_p = axes[e * (1 + p)], axes[e * (1 + p) + 1 : (e + 1) * (1 + p)]
        d = np.asarray(trace.arrays["D"][:, e], dtype=float)
        d = np.where(d > 0, d, np.nan)
        draw_signal(ax_d, t, d, color=COLORS["D"], label="D")
        if np.any(np.isfinite(d)):
            ax_d.set_yscale("log")
            if np.nanmax(d) >= 10.0 * np.nanmin(d):  # a decade or more: its powers of 10 are
                from matplotlib.ticker import NullFormatter  # labelled, the rest would crowd

                ax_d.yaxis.set_minor_formatter(NullFormatter())
        accepted = np.asarray(trace.arrays["accepted"][:, e], dtype=bool)
        determined = np.asarray(trace.arrays["determined"][:, e], dtype=bool)
        _mark(ax_d, t, d, ~accepted, "not accepted", "x")
        _mark(ax_d, t, d, ~determined & accepted, "not determined", "o")
        if few.any():
            tb, mb = _flag_bins(t, few)
            ax_d.fill_between(
                tb, 0, 1, where=mb, step="post", color=COLORS["few rows"], alpha=0.5, lw=0,
                label=f"too few rows ({int(few.sum())})", transform=ax_d.get_xaxis_transform(),
            )  # fmt: skip
        ax_d.set_ylabel(f"D ({name}) [eigenvalue]")
        ax_d.set_xlabel(xlabel)
        place_legend(ax_d)
        has = np.asarray(trace.arrays["has_model"][:, e], dtype=bool)  # no model yet: gap
        theta = trace.arrays["theta"][:, e]
        for i, lab in enumerate(labels):
            axp = ax_p[i]
            draw_signal(axp, t, np.where(has, theta[:, i], np.nan), color=COLORS["theta"])
            axp.set_ylabel(f"{lab} [-]" if n_eq == 1 else f"{lab} ({name}) [-]")
            axp.set_xlabel(xlabel)
            axp.ticklabel_format(axis="both", style="sci", scilimits=(-3, 4), useOffset=False)
            if t.size > 1:
                axp.set_xlim(t[0], t[-1])
            if not has.any():
                axp.text(0.5, 0.5, "no estimate accepted", transform=axp.transAxes,
                         ha="center", va="center", color="0.4")  # fmt: skip
    for a in axes:
        a.grid(True, alpha=0.3)
    heading = title or f"CLPC trace: {len(trace)} updates"
    if len(trace) > MAX_POINTS:
        heading += " (min/max envelopes)"
    if ax is None:  # fixed margins: the title 0.1 in below the top edge, above the legend
        fig.suptitle(heading, y=1.0 - 0.1 / fig.get_figheight(), va="top")
    else:
        fig.suptitle(heading)
    save_figure(fig, path)
    return fig
