"""The figure of a record: every input and output against time (:meth:`IOData.plot`)."""

from __future__ import annotations

from os import PathLike
from typing import Any

from clpc.core.figure import COLORS, axes_for, draw_signal, save_figure, time_label

__all__ = ["plot_iodata"]


def plot_iodata(
    data: Any,
    path: str | PathLike[str] | None = None,
    *,
    t0: float = 0.0,
    title: str | None = None,
    ax: Any = None,
) -> Any:
    """Plot every channel of a record, one panel each (inputs first).

    Parameters
    ----------
    data : IOData
    path : str or path-like, optional
        Also write the figure as PNG here (parent folders are created).
    t0 : float
        Time of the first sample [s, or samples without a sample time].
    title : str, optional
        Figure title (default: the sample count and sample time).
    ax : sequence of matplotlib Axes, optional
        ``n_inputs + n_outputs`` axes to draw on; default: a new figure.

    Returns
    -------
    matplotlib.figure.Figure
        Inputs are drawn in the input colour, outputs in the measured colour
        (:data:`clpc.core.figure.COLORS`); long records as min/max envelopes.
    """
    names = [*data.input_names, *data.output_names]
    fig, axes = axes_for(ax, len(names), height=1.6)
    t = t0 + data.time
    for k, name in enumerate(names):
        is_input = k < data.n_inputs
        values = data.u[:, k] if is_input else data.y[:, k - data.n_inputs]
        draw_signal(axes[k], t, values, color=COLORS["input" if is_input else "measured"])
        axes[k].set_ylabel(f"{name}\n({'input' if is_input else 'output'})")
        axes[k].grid(True, alpha=0.3)
    if ax is None:
        for a in axes[:-1]:
            a.sharex(axes[-1])
            a.tick_params(labelbottom=False)
    axes[-1].set_xlabel(time_label(data.dt))
    sampling = f"dt = {data.dt:g} s" if data.dt != 1.0 else "no sample time given"
    fig.suptitle(title or f"record: {data.n_samples} samples, {sampling}")
    save_figure(fig, path)
    return fig
