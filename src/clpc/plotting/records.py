"""Figures of records and fits: the data, measured against modelled, residuals."""

from __future__ import annotations

from os import PathLike
from typing import Any

import numpy as np

from clpc.core.figure import COLORS, axes_for, draw_signal, place_legend, save_figure, time_label
from clpc.data.plot import plot_iodata

__all__ = ["plot_compare", "plot_data", "plot_fit"]

#: the record's figure (:meth:`clpc.IOData.plot`)
plot_data = plot_iodata


#: below this fit % a model is said to diverge (its number has no meaning then: -1e140 %)
DIVERGED_FIT = -1000.0


def _fit_text(fit: float) -> str:
    if not np.isfinite(fit) or fit < DIVERGED_FIT:
        return "n/a: diverges"
    return f"{fit:.1f} %"


def _keep_to_measured(ax_y: Any, ax_r: Any, meas: np.ndarray, modelled: np.ndarray) -> None:
    """A diverging model output: limit both panels to the measured range and say so."""
    lo, hi = float(np.min(meas)), float(np.max(meas))
    span = max(hi - lo, 1e-12)
    with np.errstate(invalid="ignore"):
        inside = np.abs(modelled - 0.5 * (lo + hi)) <= 10 * span
    if np.all(inside):
        return
    ax_y.set_ylim(lo - 0.5 * span, hi + 0.5 * span)
    ax_r.set_ylim(-1.5 * span, 1.5 * span)
    note = "the model output leaves this range (diverges)"
    ax_y.text(0.99, 0.03, note, ha="right", va="bottom", transform=ax_y.transAxes,
              fontsize="small", color=COLORS["residual"])  # fmt: skip


def _dt_of(t: np.ndarray) -> float | None:
    """The sample step of a time axis (``None`` for fewer than two samples)."""
    return float(np.median(np.diff(t))) if t.size > 1 else None


def plot_compare(
    time: Any,
    y: Any,
    y_hat: Any,
    fit: Any,
    path: str | PathLike[str] | None = None,
    *,
    names: Any = None,
    label: str = "model",
    title: str | None = None,
    ax: Any = None,
) -> Any:
    """Plot measured against modelled outputs, with the fit % in the legend.

    Parameters
    ----------
    time : array_like, shape (T,)
        Time [s], or the sample index (a step of 1 is labelled in samples).
    y, y_hat : array_like, shape (T,) or (T, n_outputs)
        Measured and modelled (simulated or predicted) outputs.
    fit : float or array_like, shape (n_outputs,)
        Fit % per output (e.g. from :func:`clpc.fit_percent`); ``None``/NaN prints "n/a".
    path : str or path-like, optional
        Also write the figure as PNG here.
    names : sequence of str, optional
        Output names.
    label : str
        Legend label of the model curve, e.g. ``"simulation"`` or ``"10-step prediction"``.
    title : str, optional
    ax : matplotlib Axes or sequence of them, optional
        One axes per output; default: a new figure.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = np.asarray(time, dtype=float).ravel()
    ya = np.asarray(y, dtype=float)
    yh = np.asarray(y_hat, dtype=float)
    ya = ya[:, None] if ya.ndim == 1 else ya
    yh = yh[:, None] if yh.ndim == 1 else yh
    if ya.shape != yh.shape or ya.shape[0] != t.size:
        raise ValueError(
            "time, y and y_hat must describe the same samples; got shapes "
            f"{t.shape}, {np.shape(y)} and {np.shape(y_hat)}."
        )
    fits = np.atleast_1d(np.asarray([np.nan] if fit is None else fit, dtype=float))
    if fits.size == 1 and ya.shape[1] > 1:
        fits = np.repeat(fits, ya.shape[1])
    n_out = ya.shape[1]
    names = list(names) if names is not None else [f"y{j}" for j in range(n_out)]
    fig, axes = axes_for(ax, n_out, height=2.6, fixed=True)
    color = COLORS["prediction" if "predict" in label else "model"]
    for j in range(n_out):
        a = axes[j]
        draw_signal(a, t, ya[:, j], color=COLORS["measured"], label=f"measured {names[j]}")
        draw_signal(a, t, yh[:, j], color=color, label=f"{label} (fit {_fit_text(fits[j])})")
        a.set_ylabel(names[j])
        a.set_xlabel(time_label(_dt_of(t)))
        a.grid(True, alpha=0.3)
        place_legend(a)
    fig.suptitle(title or f"measured vs {label}")
    save_figure(fig, path)
    return fig


def plot_fit(
    model: Any,
    data: Any,
    path: str | PathLike[str] | None = None,
    *,
    k: int | None = None,
    t0: float = 0.0,
    title: str | None = None,
    ax: Any = None,
) -> Any:
    """Measured output with the model's output, and the residuals below, per output.

    Parameters
    ----------
    model : LinearModel
    data : IOData
        The record to compare on.
    path : str or path-like, optional
        Also write the figure as PNG here.
    k : int, optional
        ``None``: the free-run simulation; else the ``k``-step prediction
        (:func:`clpc.report.model_response`).
    t0 : float
        Time of ``data``'s first sample [s, or samples without a sample time], e.g. when
        it is the end of a longer record.
    title : str, optional
    ax : sequence of matplotlib Axes, optional
        ``2 * n_outputs`` axes (output, residual per output); default: a new figure.

    Returns
    -------
    matplotlib.figure.Figure
        Residual ``y - y_hat`` over the compared samples (from the model's max lag on),
        with its RMS in the legend.
    """
    from clpc.report.summaries import model_response  # report imports this package

    y_hat, start, fit = model_response(model, data.u, data.y, k)
    what = "simulation" if k is None else f"{k}-step prediction"
    fig, axes = axes_for(ax, 2 * data.n_outputs, height=1.9, fixed=True)
    t = t0 + data.time[start:]
    color = COLORS["model" if k is None else "prediction"]
    for j, name in enumerate(data.output_names):
        a_y, a_r = axes[2 * j], axes[2 * j + 1]
        meas, modelled = data.y[start:, j], y_hat[start:, j]
        draw_signal(a_y, t, meas, color=COLORS["measured"], label=f"measured {name}")
        draw_signal(a_y, t, modelled, color=color, label=f"{what} (fit {_fit_text(fit[j])})")
        a_y.set_ylabel(f"{name}\n[data units]")
        place_legend(a_y)
        with np.errstate(over="ignore", invalid="ignore"):
            resid = meas - modelled
            rms = float(np.sqrt(np.mean(resid**2)))
        draw_signal(
            a_r,
            t,
            resid,
            color=COLORS["residual"],
            label=f"residual (RMS {rms:.3g})" if np.isfinite(rms) else "residual (diverges)",
        )
        a_r.axhline(0.0, color="0.5", lw=0.8)
        _keep_to_measured(a_y, a_r, meas, modelled)
        a_r.set_ylabel(f"{name} − model\n[data units]")
        place_legend(a_r)
        for a in (a_y, a_r):
            a.grid(True, alpha=0.3)
            a.set_xlabel(time_label(data.dt))
    fig.suptitle(title or f"measured output, model {what} and residuals")
    save_figure(fig, path)
    return fig
