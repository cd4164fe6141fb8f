"""The figure of a trace's physical quantities: DC gain and the dominant pole over time.

Raw ``theta`` (unit norm) hides what changed; this figure draws, per accepted cluster
update, the DC gain ``G(1) = B(1) / A(1)`` of each input (the monic ``den``/``num`` of the
held ``theta``) and the dominant pole (largest ``|z|``) as natural frequency and damping
(or as a time constant when the dominant pole is real in every accepted update). Axes have
no offset, and y-limits come from percentiles so that a few outliers or tiny noise do not
fill the panel (:func:`robust_limits`).
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

__all__ = ["MIN_SPAN_FRACTION", "plot_track_quantities", "robust_limits", "track_quantities"]

#: a panel's y-span is never smaller than this fraction of the level (median |value|), so
#: noise around a constant level is drawn as the small wobble it is
MIN_SPAN_FRACTION = 0.2

#: percentiles of the accepted values the y-limits hold (outliers beyond are clipped)
PERCENTILES = (1.0, 99.0)

_MARGINS = Margins(left=0.95, right=0.25, top=0.62, bottom=0.55, row_gap=0.66, col_gap=1.0)


def _dominant(den: np.ndarray) -> np.ndarray:
    """Largest-``|z|`` root of each monic ``den`` row (ascending ``z^-1``), shape (n,)."""
    n, m = den.shape
    if m < 2:
        return np.full(n, np.nan + 0j)
    comp = np.zeros((n, m - 1, m - 1))
    comp[:, 0, :] = -den[:, 1:]
    comp[:, np.arange(1, m - 1), np.arange(m - 2)] = 1.0
    ok = np.all(np.isfinite(comp), axis=(1, 2))
    roots = np.full((n, m - 1), np.nan + 0j)
    if ok.any():
        roots[ok] = np.linalg.eigvals(comp[ok])
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


def _panel(ax: Any, t: np.ndarray, y: np.ndarray, color: str, label: str | None = None):
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
    Updates not accepted are omitted (gaps). The trace holds no per-update parameter
    uncertainty, so no band is drawn. Y-limits: :func:`robust_limits`; no offset axes.
    """
    n_eq = trace.n_equations
    per_eq = [track_quantities(trace, e) for e in range(n_eq)]
    real = [bool(np.all(np.abs(q["pole"][q["accepted"]].imag) < 1e-12)) for q in per_eq]
    rows = sum(2 if r else 3 for r in real)
    fig, grid = new_grid(rows, 1, _MARGINS, height=1.7)
    xlabel = time_label(trace.sample_time)
    unit_t = "samples" if trace.sample_time == 1.0 else "s"
    unit_w = "rad/sample" if trace.sample_time == 1.0 else "rad/s"
    row = 0
    for e, q in enumerate(per_eq):
        name = trace.output_names[e] if e < len(trace.output_names) else f"y{e}"
        t = q["time"]
        ax = fig.add_subplot(grid[row, 0])
        inputs = [i for i in range(q["gain"].shape[1]) if np.any(q["gain"][:, i] != 0)]
        for k, i in enumerate(inputs):
            lab = trace.input_names[i] if i < len(trace.input_names) else f"u{i}"
            _panel(ax, t, q["gain"][:, i], f"C{k}" if k else COLORS["theta"], f"{lab} → {name}")
        _finish(ax, q["gain"][:, inputs], f"DC gain ({name})", xlabel, t)
        place_legend(ax)
        row += 1
        if real[e]:
            ax = fig.add_subplot(grid[row, 0])
            _panel(ax, t, q["tau"], COLORS["model"])
            _finish(ax, q["tau"], f"time constant [{unit_t}]", xlabel, t)
            row += 1
            continue
        for key, ylabel in (("wn", f"ω_n [{unit_w}]"), ("zeta", "damping ζ [-]")):
            ax = fig.add_subplot(grid[row, 0])
            _panel(ax, t, q[key], COLORS["model"])
            _finish(ax, q[key], ylabel, xlabel, t)
            row += 1
    heading = title or f"DC gain and dominant pole of {len(trace)} updates (accepted only)"
    fig.suptitle(heading, y=1.0 - 0.1 / fig.get_figheight(), va="top")
    save_figure(fig, path)
    return fig
