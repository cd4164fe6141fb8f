"""The figure of a trace's physical quantities: DC gain and the dominant pole over time.

Raw ``theta`` (unit norm) hides what changed; this figure draws, per accepted cluster
update, the DC gain ``G(1) = B(1) / A(1)`` of each input (the monic ``den``/``num`` of the
held ``theta``) and the dominant pole (largest ``|z|``) as natural frequency and damping
(or as a time constant when the dominant pole is real in every accepted update). Axes have
no offset, and y-limits come from percentiles so that a few outliers or tiny noise do not
fill the panel (:func:`robust_limits`). A shaded band around each curve shows how much the
estimates of neighbouring windows disagree (:func:`spread_band`): the trace holds no
per-window parameter covariance, and this spread is what the record itself says about how
well each window fixes the quantity.
"""

from __future__ import annotations

from os import PathLike
from typing import Any

import numpy as np

from clpc.core.figure import (
    COLORS,
    Margins,
    draw_signal,
    new_grid,
    place_legend,
    save_figure,
    time_label,
)
from clpc.model.dominant import companion_roots

__all__ = [
    "BAND_PERCENTILES",
    "BAND_WINDOWS",
    "MIN_SPAN_FRACTION",
    "plot_track_quantities",
    "robust_limits",
    "spread_band",
    "track_quantities",
]

#: a panel's y-span is never smaller than this fraction of the level (median |value|), so
#: noise around a constant level is drawn as the small wobble it is
MIN_SPAN_FRACTION = 0.2

#: percentiles of the accepted values the y-limits hold (outliers beyond are clipped)
PERCENTILES = (1.0, 99.0)

#: the band around a curve: these percentiles (about +-1 sigma of a normal spread) of the
#: accepted values of the updates within BAND_WINDOWS window lengths before and after
BAND_PERCENTILES = (16.0, 84.0)
BAND_WINDOWS = 2.0

_MARGINS = Margins(left=0.95, right=0.25, top=0.85, bottom=0.55, row_gap=0.66, col_gap=1.0)


def _dominant(den: np.ndarray) -> np.ndarray:
    """Largest-``|z|`` root of each monic ``den`` row (ascending ``z^-1``), shape (n,)."""
    n, m = den.shape
    if m < 2:
        return np.full(n, np.nan + 0j)
    roots = companion_roots(den)
    # the root of largest modulus; of a complex pair, the one with positive imaginary part
    key = np.where(np.isfinite(roots), np.abs(roots) + 1e-12 * np.sign(roots.imag), -1.0)
    return roots[np.arange(n), np.argmax(key, axis=1)]


def track_quantities(trace: Any, equation: int = 0) -> dict[str, np.ndarray]:
    """DC gain per input and the dominant pole of every update of one equation.

    Parameters
    ----------
    trace : Trace
        Output of :meth:`clpc.CLPC.run`.
    equation : int
        Equation (output) index.

    Returns
    -------
    dict
        ``time`` (n,); ``accepted`` (n,) bool; ``gain`` (n, n_inputs): ``B_i(1) / A(1)``,
        NaN where not accepted or ``A(1) = 0``; ``pole`` (n,) complex: dominant discrete
        pole (NaN where not accepted); ``wn`` [rad/s, or rad/sample], ``zeta`` and ``tau``
        [s, or samples] of ``s = log(pole) / sample_time`` (``tau = -1 / Re(s)``).
    """
    den = np.asarray(trace.arrays["den"][:, equation], dtype=float)
    num = np.asarray(trace.arrays["num"][:, equation], dtype=float)
    acc = np.asarray(trace.arrays["accepted"][:, equation], dtype=bool)
    acc &= np.asarray(trace.arrays["has_model"][:, equation], dtype=bool)
    a1 = den.sum(axis=1)
    b1 = num.sum(axis=2)
    good = acc & (np.abs(a1) > 1e-12)
    gain = np.full(b1.shape, np.nan)
    gain[good] = b1[good] / a1[good, None]
    pole = np.full(len(acc), np.nan + 0j)
    if acc.any():
        pole[acc] = _dominant(den[acc])
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.log(pole) / float(trace.sample_time)
        wn = np.abs(s)
        zeta = -s.real / wn
        tau = -1.0 / s.real
    return {
        "time": np.asarray(trace.time, dtype=float),
        "accepted": acc,
        "gain": gain,
        "pole": pole,
        "wn": wn,
        "zeta": zeta,
        "tau": tau,
    }


def robust_limits(values: Any, min_fraction: float = MIN_SPAN_FRACTION) -> tuple[float, float]:
    """Y-limits holding the :data:`PERCENTILES` of the finite values, with a 10 % margin.

    Parameters
    ----------
    values : array_like
        Values drawn (NaN and inf ignored).
    min_fraction : float
        The span is at least this fraction of the level (median ``|value|``), centred on
        the values, so noise on a steady level is not magnified to fill the panel.

    Returns
    -------
    (float, float)
        Lower and upper limit; ``(-1, 1)`` when no value is finite.
    """
    v = np.asarray(values, dtype=float).ravel()
    v = v[np.isfinite(v)]
    if v.size == 0:
        return -1.0, 1.0
    lo, hi = (float(x) for x in np.percentile(v, PERCENTILES))
    level = float(np.median(np.abs(v)))
    span = max(hi - lo, min_fraction * level, 1e-12)
    mid = 0.5 * (lo + hi)
    return mid - 0.6 * span, mid + 0.6 * span


def spread_band(time: Any, values: Any, half_span: float) -> tuple[np.ndarray, np.ndarray]:
    """Percentiles of the finite values of the updates within ``half_span`` of each.

    Parameters
    ----------
    time : array_like, shape (n,)
        Time of each update [s, or samples] (increasing, evenly spaced: one update every
        ``cluster_size`` samples).
    values : array_like, shape (n,)
        One quantity per update; NaN where no estimate was accepted (ignored).
    half_span : float
        Half-width of the neighbourhood, in the unit of ``time``;
        :func:`plot_track_quantities` uses :data:`BAND_WINDOWS` window lengths.

    Returns
    -------
    (ndarray, ndarray), each shape (n,)
        The :data:`BAND_PERCENTILES` of the neighbourhood; NaN where the update itself has
        no value or fewer than 3 neighbours do. Neighbouring windows overlap, so their
        estimates are correlated and the band is a lower bound on the uncertainty of one
        window's estimate; a change of the plant widens it around the change.
    """
    import pandas as pd

    t = np.asarray(time, dtype=float)
    v = np.asarray(values, dtype=float)
    if v.size < 2:
        return np.full(v.shape, np.nan), np.full(v.shape, np.nan)
    step = float(np.median(np.diff(t)))
    count = 2 * int(half_span // step) + 1 if step > 0 else 1
    rolling = pd.Series(v).rolling(count, center=True, min_periods=3)
    lo, hi = (np.array(rolling.quantile(p / 100.0), dtype=float) for p in BAND_PERCENTILES)
    missing = ~np.isfinite(v)
    lo[missing], hi[missing] = np.nan, np.nan
    return lo, hi


def _panel(
    ax: Any, t: np.ndarray, y: np.ndarray, color: str, half_span: float, label: str | None = None
) -> None:
    lo, hi = spread_band(t, y, half_span)
    ax.fill_between(t, lo, hi, color=color, alpha=0.25, lw=0)
    draw_signal(ax, t, y, color=color, label=label, marker=".", ms=2, lw=0.8)


def _finish(ax: Any, values: np.ndarray, ylabel: str, xlabel: str, t: np.ndarray) -> None:
    ax.set_ylim(*robust_limits(values))
    ax.set_ylabel(ylabel)
    ax.set_xlabel(xlabel)
    ax.ticklabel_format(axis="y", style="plain", useOffset=False)
    ax.ticklabel_format(axis="x", useOffset=False)
    if t.size > 1:
        ax.set_xlim(t[0], t[-1])
    ax.grid(True, alpha=0.3)
    if not np.any(np.isfinite(values)):
        ax.text(0.5, 0.5, "no estimate accepted", transform=ax.transAxes,
                ha="center", va="center", color="0.4")  # fmt: skip


def plot_track_quantities(
    trace: Any, path: str | PathLike[str] | None = None, *, title: str | None = None
) -> Any:
    """Plot DC gain and dominant pole of every accepted update over time.

    Parameters
    ----------
    trace : Trace
        Output of :meth:`clpc.CLPC.run`.
    path : str or path-like, optional
        Also write the figure as PNG here.
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
        Its axes, per output: DC gain, then natural frequency and damping of the dominant
        pole (or its time constant when it is real in every accepted update).

    Notes
    -----
    Updates not accepted are omitted (gaps). The band around each curve is the spread of
    the neighbouring windows' estimates (:func:`spread_band`, :data:`BAND_WINDOWS` window
    lengths each side); the trace holds no per-update parameter covariance. Y-limits:
    :func:`robust_limits`; no offset axes.
    """
    n_eq = trace.n_equations
    per_eq = [track_quantities(trace, e) for e in range(n_eq)]
    real = [bool(np.all(np.abs(q["pole"][q["accepted"]].imag) < 1e-12)) for q in per_eq]
    rows = sum(2 if r else 3 for r in real)
    fig, grid = new_grid(rows, 1, _MARGINS, height=1.7)
    xlabel = time_label(trace.sample_time)
    unit_t = "samples" if trace.sample_time == 1.0 else "s"
    unit_w = "rad/sample" if trace.sample_time == 1.0 else "rad/s"
    # a window's length [s, or samples]: its most rows, at the appraiser's (decimated) rate
    half_span = BAND_WINDOWS * float(np.max(trace.rows, initial=1)) * float(trace.sample_time)
    row = 0
    for e, q in enumerate(per_eq):
        name = trace.output_names[e] if e < len(trace.output_names) else f"y{e}"
        t = q["time"]
        ax = fig.add_subplot(grid[row, 0])
        inputs = [i for i in range(q["gain"].shape[1]) if np.any(q["gain"][:, i] != 0)]
        for k, i in enumerate(inputs):
            lab = trace.input_names[i] if i < len(trace.input_names) else f"u{i}"
            color = f"C{k}" if k else COLORS["theta"]
            _panel(ax, t, q["gain"][:, i], color, half_span, f"{lab} → {name}")
        _finish(ax, q["gain"][:, inputs], f"DC gain ({name})", xlabel, t)
        place_legend(ax)
        row += 1
        if real[e]:
            ax = fig.add_subplot(grid[row, 0])
            _panel(ax, t, q["tau"], COLORS["model"], half_span)
            _finish(ax, q["tau"], f"time constant [{unit_t}]", xlabel, t)
            row += 1
            continue
        for key, ylabel in (("wn", f"ω_n [{unit_w}]"), ("zeta", "damping ζ [-]")):
            ax = fig.add_subplot(grid[row, 0])
            _panel(ax, t, q[key], COLORS["model"], half_span)
            _finish(ax, q[key], ylabel, xlabel, t)
            row += 1
    heading = title or (
        f"DC gain and dominant pole of {len(trace)} updates (accepted only)\nband: "
        f"{BAND_PERCENTILES[0]:g}-{BAND_PERCENTILES[1]:g}th percentile of the updates "
        f"within ±{BAND_WINDOWS:g} window lengths"
    )
    fig.suptitle(heading, y=1.0 - 0.08 / fig.get_figheight(), va="top", fontsize="medium")
    save_figure(fig, path)
    return fig
