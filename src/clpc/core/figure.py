"""Figure primitives shared by every plot: Agg figures, colours per quantity, envelopes.

Kept at the bottom layer so that :meth:`clpc.IOData.plot` and :mod:`clpc.plotting` draw
alike. matplotlib is imported only when a figure is made (``pip install '.[plot]'`` in the
source tree).

* :data:`COLORS` - one colour per quantity (measured, model output, residual, ...), the
  same in every figure.
* :func:`new_figure` / :func:`axes_for` - a headless figure, or the caller's axes;
  :func:`new_grid` and :class:`Margins` - a figure on fixed margins (labels known ahead).
* :func:`envelope` - min/max of a long signal over bins (vectorised), for drawing.
* :func:`draw_signal` - a line, or its min/max band when there are too many points.
* :func:`time_label` / :func:`place_legend`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from clpc.core.atomic import atomic_file

__all__ = [
    "COLORS",
    "MAX_POINTS",
    "Margins",
    "axes_for",
    "draw_signal",
    "envelope",
    "new_figure",
    "new_grid",
    "place_legend",
    "save_figure",
    "time_label",
]

INSTALL_HINT = (
    "plotting needs matplotlib: pip install matplotlib (or, in the clpc source tree, "
    "pip install '.[plot]')"
)

#: the colour of each quantity, the same in every figure
COLORS: dict[str, str] = {
    "measured": "#222222",
    "model": "#d95f02",
    "prediction": "#7570b3",
    "residual": "#b2182b",
    "input": "#1b9e77",
    "D": "#1f77b4",
    "theta": "#1f77b4",
    "not accepted": "#e41a1c",
    "not determined": "#ff7f00",
    "few rows": "#bbbbbb",
    "nyquist": "#777777",
}

#: above this many samples a signal is drawn as its min/max envelope
MAX_POINTS = 4000


#: margins of :func:`new_figure` [in]: room for tick labels of up to about seven characters,
#: an axis label on the left and below, a title above each axes and the figure's title


def new_figure(
    n_rows: int = 1,
    n_cols: int = 1,
    *,
    height: float = 2.6,
    width: float = 8.0,
    fixed: bool = False,
):
    """A new Agg-backed figure (no pyplot state) and its axes, shape (n_rows, n_cols).

    ``height`` per row and ``width`` in inches (0.7 in more for the title). ``fixed``: the
    axes are placed by the fixed :data:`PLOT_MARGINS` (for stacked axes with one title and
    a legend row above each: matplotlib's constrained layout measures every tick label,
    about a third of such a figure's drawing time); otherwise constrained layout places
    them (labels of unknown size, legends beside the axes, multi-line titles).
    """
    if not fixed:
        fig = _figure((width, 0.7 + height * n_rows), constrained=True)
        return fig, fig.subplots(n_rows, n_cols, squeeze=False)
    fig, grid = new_grid(n_rows, n_cols, PLOT_MARGINS, height=height, width=width)
    axes = np.empty((n_rows, n_cols), dtype=object)
    for i in range(n_rows):
        for j in range(n_cols):
            axes[i, j] = fig.add_subplot(grid[i, j])
    return fig, axes


def new_grid(n_rows: int, n_cols: int, margins: Margins, *, height: float, width: float = 8.0):
    """A new Agg-backed figure and an empty grid (``GridSpec``) placed by fixed ``margins``.

    For a figure whose labels are known in advance and whose axes may span cells: no
    constrained layout (it measures every tick label, about a third of the drawing time).
    Sizes as for :func:`new_figure`.
    """
    fig = _figure((width, 0.7 + height * n_rows), constrained=False)
    return fig, fig.add_gridspec(n_rows, n_cols, **margins.fractions(fig, n_rows, n_cols))


def _figure(size: tuple[float, float], *, constrained: bool) -> Any:
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        from clpc.core.notebook_figure import NotebookFigure
    except ImportError:  # pragma: no cover - depends on the environment
        raise ImportError(INSTALL_HINT) from None
    fig = NotebookFigure(figsize=size, layout="constrained" if constrained else None)
    FigureCanvasAgg(fig)
    return fig


@dataclass(frozen=True)
class Margins:
    """Fixed figure margins and gaps between axes [in] (see :func:`new_grid`)."""

    left: float
    right: float
    top: float
    bottom: float
    row_gap: float
    col_gap: float

    def fractions(self, fig: Any, n_rows: int, n_cols: int) -> dict[str, float]:
        """``left, right, top, bottom, hspace, wspace`` of a grid of axes in ``fig``."""
        w, h = fig.get_size_inches()
        axes_h = (h - self.top - self.bottom - (n_rows - 1) * self.row_gap) / n_rows
        axes_w = (w - self.left - self.right - (n_cols - 1) * self.col_gap) / n_cols
        return {
            "left": self.left / w,
            "right": 1.0 - self.right / w,
            "top": 1.0 - self.top / h,
            "bottom": self.bottom / h,
            "hspace": self.row_gap / max(axes_h, 1e-3),
            "wspace": self.col_gap / max(axes_w, 1e-3),
        }


#: margins of :func:`new_figure` [in]: room for tick labels of up to about seven characters,
#: an axis label on the left and below, a title above each axes and the figure's title
PLOT_MARGINS = Margins(left=1.0, right=0.3, top=0.75, bottom=0.6, row_gap=0.75, col_gap=1.0)


def axes_for(
    ax: Any, n: int, *, height: float = 2.6, width: float = 8.0, fixed: bool = False
) -> tuple[Any, list]:
    """The figure and ``n`` axes to draw on: new ones, or the caller's ``ax``.

    Parameters
    ----------
    ax : matplotlib Axes, sequence of Axes, or None
        ``None``: a new figure with ``n`` stacked axes. Otherwise exactly ``n`` axes (a
        single Axes when ``n == 1``).
    n : int
        Panels the plot needs.
    height, width : float
        Size of each new panel [in].
    fixed : bool
        New axes placed by fixed margins (see :func:`new_figure`).

    Raises
    ------
    ValueError
        ``ax`` does not hold ``n`` axes.
    """
    if ax is None:
        fig, axes = new_figure(n, 1, height=height, width=width, fixed=fixed)
        return fig, list(axes[:, 0])
    axes = (
        list(np.ravel(np.asarray(ax, dtype=object)))
        if isinstance(ax, (Sequence, np.ndarray))
        else [ax]
    )
    if len(axes) != n:
        raise ValueError(
            f"this plot needs {n} axes; got {len(axes)}. Pass ax=None for a new figure or "
            f"a sequence of {n} matplotlib Axes."
        )
    return axes[0].get_figure(), axes


def save_figure(fig: Any, path: str | PathLike[str] | None) -> None:
    """Write ``fig`` as PNG to ``path`` (parent folders created); nothing when ``None``."""
    if path is None:
        return
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    # zlib level 1, not Pillow's 6: a long trace's figure encodes 0.07 s faster, 16 % larger
    with atomic_file(out, binary=True) as fh:  # no half-written PNG, even when killed
        fig.savefig(fh, dpi=110, format="png", pil_kwargs={"compress_level": 1})


def envelope(
    x: Any, y: Any, max_points: int = MAX_POINTS
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Min and max of ``y`` over ``max_points // 2`` equal bins of samples.

    Parameters
    ----------
    x, y : array_like, shape (n,)
        Abscissa (e.g. time) and values; NaN values are ignored (a bin of NaN only stays NaN).
    max_points : int
        Upper bound of points drawn (two per bin).

    Returns
    -------
    x_bin : ndarray, shape (n_bins,)
        ``x`` at the start of each bin (all of ``x`` when ``n <= max_points``).
    lo, hi : ndarray, shape (n_bins,)
        Minimum and maximum of ``y`` in each bin (``y`` itself when short).
    """
    xa, ya = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if ya.size <= max_points:
        return xa, ya, ya
    starts = np.linspace(0, ya.size, max(max_points // 2, 1), endpoint=False).astype(np.intp)
    with np.errstate(invalid="ignore"):
        lo = np.fmin.reduceat(ya, starts)
        hi = np.fmax.reduceat(ya, starts)
    return xa[starts], lo, hi


def draw_signal(ax: Any, x: Any, y: Any, *, color: str, label: str | None = None, **kw: Any):
    """Draw ``y(x)`` as a line, or as its min/max band when longer than :data:`MAX_POINTS`."""
    xb, lo, hi = envelope(x, y)
    if lo is hi:
        return ax.plot(xb, lo, color=color, label=label, lw=kw.pop("lw", 1.0), **kw)
    return ax.fill_between(
        xb, lo, hi, facecolor=color, edgecolor=color, alpha=0.8, lw=0.4, label=label, step="post"
    )


def time_label(dt: float | None) -> str:
    """``"time [s]"``, or ``"time [samples]"`` when no sample time was given (``dt`` 1 or None)."""
    return "time [samples]" if dt is None or dt == 1.0 else "time [s]"


def place_legend(ax: Any, *, outside: bool = False, **kw: Any) -> None:
    """A legend that does not cover the data: above the axes, or to their right."""
    handles, _ = ax.get_legend_handles_labels()
    if not handles:
        return
    kw.setdefault("fontsize", "small")
    kw.setdefault("frameon", False)
    if outside:
        ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), **kw)
    else:
        ax.legend(
            loc="lower left",
            bbox_to_anchor=(0.0, 1.0),
            ncols=min(len(handles), 4),
            borderaxespad=0.2,
            **kw,
        )
