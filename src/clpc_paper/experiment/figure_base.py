"""Shared pieces of the experiment's figures: file names, a headless figure, saving.

Figures are built with :class:`matplotlib.figure.Figure` on the Agg canvas (no pyplot, no
global backend switch); matplotlib is imported only inside the functions.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from clpc_paper.experiment.settings import SAMPLE_TIME

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["FILES", "PARAM_NAMES", "RICH_FILE", "figure", "footnote", "save", "times"]

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
PARAM_NAMES = ("a_{01}", "a_{11}", "a_{21}", "b_{01}", "b_{11}", "b_{21}")


def figure(
    size: tuple[float, float] = (6.4, 3.6), *, top_axis: bool = False, bottom: float = 0.14
) -> Figure:
    """A figure with fixed margins (no layout engine: half the drawing time)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=size)
    top = 1.0 - (0.85 if top_axis else 0.36) / size[1]  # room for the title (and top axis)
    fig.subplots_adjust(left=0.14, right=0.97, bottom=bottom, top=top)
    return fig


def footnote(fig: Figure, text: str) -> None:
    """A small caption at the bottom of the figure: what the marks are."""
    fig.text(0.01, 0.005, text, fontsize=6.5, color="0.3", va="bottom", wrap=True)


def save(fig: Figure, path: Path, dpi: int) -> str:
    """Write the PNG and return its file name."""
    fig.savefig(path, dpi=dpi)
    return path.name


def times(n: int) -> np.ndarray:
    """Sample instants [s] of ``n`` decimated samples."""
    return np.arange(n) * SAMPLE_TIME
