"""The figure class of every clpc plot: matplotlib's ``Figure`` that Jupyter shows as PNG.

clpc draws on Agg figures and never imports ``pyplot`` (no window, no global state), so
IPython's matplotlib display hook, which ``%matplotlib inline`` or a ``pyplot`` import
installs, is not there; a figure returned to a notebook cell would print as
``<Figure size ...>``. :class:`NotebookFigure` carries its own ``_repr_png_``, so the last
expression of a cell shows the image with or without ``%matplotlib inline``. Importing this
module imports matplotlib: :mod:`clpc.core.figure` imports it on a plot's first use.
"""

from __future__ import annotations

import io

from matplotlib.figure import Figure

__all__ = ["NotebookFigure"]


class NotebookFigure(Figure):
    """An Agg figure that renders itself as PNG for Jupyter (``_repr_png_``)."""

    def _repr_png_(self) -> bytes:
        """The figure as PNG bytes at matplotlib's ``savefig.dpi`` (IPython's display hook)."""
        buffer = io.BytesIO()
        self.savefig(buffer, format="png")
        return buffer.getvalue()
