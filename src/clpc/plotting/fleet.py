"""The figures of a fleet report: every record's Bode magnitude, and its DC gain over time.

Ordinary records are thin grey lines, the fleet's median model a black dashed line, the
outliers coloured and named in the legend, so the one axis that differs stands out.
"""

from __future__ import annotations

from collections.abc import Sequence
from os import PathLike
from typing import Any

import numpy as np

from clpc.core.figure import new_figure, place_legend, save_figure

__all__ = ["plot_fleet_bode", "plot_fleet_drift"]

_GREY = "#9a9a9a"
#: colours of the outliers, in rank order (repeats after the last)
_MARKED = ("#d62728", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf")


def _db(h: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore"):
        return np.asarray(20 * np.log10(np.abs(h)))


def plot_fleet_bode(
    freqs: np.ndarray,
    responses: Sequence[np.ndarray],
    names: Sequence[str],
    marked: Sequence[bool],
    reference: np.ndarray,
    band: tuple[float, float],
    path: str | PathLike[str] | None = None,
    *,
    unit: str = "Hz",
) -> Any:
    """Bode magnitudes of all records, the median model's, the band, the outliers marked.

    Parameters
    ----------
    freqs : ndarray, shape (n_freqs,)
        Frequencies [``unit``], ascending and positive.
    responses : sequence of ndarray, shape (n_freqs,)
        Each record's frequency response (first input to first output).
    names : sequence of str
        Record names (only the marked ones are labelled).
    marked : sequence of bool
        Which records are outliers (drawn in colour, above the others).
    reference : ndarray, shape (n_freqs,)
        The fleet median model's response.
    band : (float, float)
        The band the distance is computed over [``unit``] (shaded).
    path : str or path-like, optional
        Also write the figure as PNG here.
    unit : str
        Frequency unit for the axis label.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(1, 1, height=3.6)
    ax = axes[0, 0]
    ax.axvspan(band[0], band[1], color="#e8f0fb", zorder=0, label="band of the distance")
    n_plain = 0
    for h, flag in zip(responses, marked, strict=True):
        if not flag:
            label = "records" if n_plain == 0 else None
            ax.semilogx(freqs, _db(h), color=_GREY, lw=1.4, alpha=0.8, label=label, zorder=2)
            n_plain += 1
    ax.semilogx(freqs, _db(reference), color="black", dashes=(3, 4), lw=1.0,
                label="fleet median model", zorder=3)  # fmt: skip
    k = 0
    for h, name, flag in zip(responses, names, marked, strict=True):
        if flag:
            color = _MARKED[k % len(_MARKED)]
            ax.semilogx(freqs, _db(h), color=color, lw=1.8, label=f"outlier: {name}", zorder=4)
            k += 1
    ax.set_xlim(freqs[0], freqs[-1])
    ax.grid(True, which="both", alpha=0.3)
    ax.set_xlabel(f"frequency [{unit}]")
    ax.set_ylabel("magnitude [dB]")
    place_legend(ax, outside=True)
    fig.suptitle(f"Bode magnitude of {len(responses)} records (first input to first output)")
    save_figure(fig, path)
    return fig


def plot_fleet_drift(
    series: Sequence[tuple[np.ndarray, np.ndarray]],
    names: Sequence[str],
    marked: Sequence[bool],
    path: str | PathLike[str] | None = None,
    *,
    time_unit: str = "s",
) -> Any:
    """The DC gain of every record over time (accepted updates after convergence).

    Parameters
    ----------
    series : sequence of (ndarray, ndarray)
        Per record: times [``time_unit``] and DC gains (first input to first output).
    names : sequence of str
        Record names.
    marked : sequence of bool
        Which records are outliers.
    path : str or path-like, optional
        Also write the figure as PNG here.
    time_unit : str
        Unit of the times.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = new_figure(1, 1, height=3.0)
    ax = axes[0, 0]
    order = sorted(range(len(series)), key=lambda i: bool(marked[i]))  # marked drawn last
    k, n_plain = 0, 0
    for i in order:
        t, g = (np.asarray(a, dtype=float) for a in series[i])
        if t.size == 0:
            continue
        label: str | None
        if marked[i]:
            color, label, lw = _MARKED[k % len(_MARKED)], f"outlier: {names[i]}", 1.6
            k += 1
        else:
            color, label, lw = _GREY, "records" if n_plain == 0 else None, 0.8
            n_plain += 1
        ax.plot(t, g, color=color, lw=lw, label=label, marker="." if t.size < 3 else None)
    ax.grid(True, alpha=0.3)
    ax.set_xlabel(f"time [{time_unit}]")
    ax.set_ylabel("DC gain")
    place_legend(ax, outside=True)
    fig.suptitle("DC gain over time, every record (accepted updates after convergence)")
    save_figure(fig, path)
    return fig
