"""A model compared with a record, for notebooks: fit table and figure in one object."""

from __future__ import annotations

import base64
import html
import io
from dataclasses import dataclass
from os import PathLike
from typing import Any

import numpy as np

from clpc.core.compact import compact_repr
from clpc.data import IOData
from clpc.model import LinearModel
from clpc.report.summaries import model_response
from clpc.report.text import format_fit

__all__ = ["Comparison", "compare"]


@compact_repr
@dataclass(frozen=True, eq=False)
class Comparison:
    """A model's output on a record beside the measured one (see :func:`compare`).

    Attributes
    ----------
    model : LinearModel
    data : IOData
    k : int or None
        ``None``: free-run simulation; else the prediction horizon [samples].
    y_hat : ndarray, shape (n_samples, n_outputs)
        Model output (:func:`clpc.report.model_response`).
    start : int
        First compared sample.
    fit : ndarray, shape (n_outputs,)
        Fit % per output (NaN when the simulation diverges).
    """

    model: LinearModel
    data: IOData
    k: int | None
    y_hat: np.ndarray
    start: int
    fit: np.ndarray

    @property
    def residuals(self) -> np.ndarray:
        """``y - y_hat`` over the compared samples: shape (n_samples - start, n_outputs)."""
        return self.data.y[self.start :] - self.y_hat[self.start :]

    def plot(self, path: str | PathLike[str] | None = None, *, ax: Any = None) -> Any:
        """Measured, model output and residuals (:func:`clpc.plotting.plot_fit`).

        Parameters
        ----------
        path : str or path-like, optional
            Also write the figure as PNG here.
        ax : sequence of matplotlib Axes, optional
            ``2 * n_outputs`` axes (output, residual per output); default: a new figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from clpc.plotting import plot_fit

        return plot_fit(self.model, self.data, path, k=self.k, ax=ax)

    def _repr_html_(self) -> str:
        what = "free-run simulation" if self.k is None else f"{self.k}-step prediction"
        rows = "".join(
            f"<tr><td>{html.escape(name)}</td><td style='text-align:right;white-space:nowrap'>"
            f"{html.escape(format_fit(float(f)))}</td></tr>"
            for name, f in zip(self.data.output_names, self.fit, strict=True)
        )
        table = (
            f"<table><caption>fit of the {what} on {self.data.n_samples - self.start} "
            f"samples</caption><tr><th>output</th><th>fit</th></tr>{rows}</table>"
        )
        try:
            fig = self.plot()
        except ImportError:  # no matplotlib: the table alone
            return table
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=80)
        png = base64.b64encode(buf.getvalue()).decode("ascii")
        return f'{table}<img alt="measured vs model" src="data:image/png;base64,{png}">'


def compare(model: LinearModel, data: IOData, k: int | None = None) -> Comparison:
    """Compare a model with a record: its free-run simulation (or ``k``-step prediction).

    Parameters
    ----------
    model : LinearModel
    data : IOData
    k : int, optional
        Prediction horizon in samples; ``None`` for the free-run simulation.

    Returns
    -------
    Comparison
        Shows its fit table and figure in a notebook; ``.plot(ax=...)`` draws the figure.
    """
    y_hat, start, fit = model_response(model, data.u, data.y, k)
    return Comparison(model, data, k, y_hat, start, fit)
