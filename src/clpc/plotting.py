"""Headless figures (PNG) of traces, model responses, pole-zero maps and Bode plots.

Every function draws on a fresh :class:`matplotlib.figure.Figure` rendered by the Agg
backend: no window opens, no global pyplot state changes, and the functions work on servers
and in threads. matplotlib is an optional dependency (``pip install 'clpc[plot]'``) and is
imported only when a figure is drawn.

>>> import clpc, clpc.datasets as ds                                  # doctest: +SKIP
>>> trace = clpc.CLPC(3, 201, 12).run(ds.load("dryer"))               # doctest: +SKIP
>>> clpc.plotting.plot_trace(trace, "trace.png")                      # doctest: +SKIP
"""

from __future__ import annotations

from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from clpc.appraiser.trace import Trace
    from clpc.model import LinearModel

__all__ = ["plot_bode", "plot_compare", "plot_pz", "plot_residuals", "plot_trace"]

_INSTALL_HINT = "plotting needs matplotlib: pip install 'clpc[plot]'"


def _figure(n_rows: int = 1, n_cols: int = 1, *, height: float = 3.0) -> tuple[Figure, Any]:
    """A new Agg-backed figure and its axes array of shape (n_rows, n_cols)."""
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError:  # pragma: no cover - depends on the environment
        raise ImportError(_INSTALL_HINT) from None
    fig = Figure(figsize=(8.0, 0.6 + height * n_rows), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(n_rows, n_cols, squeeze=False)
    return fig, axes


def _save(fig: Figure, path: str | PathLike[str]) -> Path:
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110, format="png")
    return out


def plot_trace(trace: Trace, path: str | PathLike[str], *, title: str | None = None) -> Path:
    """Plot a CLPC trace: the degree of linearity ``D`` and the ``theta`` entries per update.

    Parameters
    ----------
    trace : Trace
        Output of :meth:`clpc.CLPC.run` (or concatenated :meth:`clpc.CLPC.push` results).
    path : str or path-like
        PNG file to write (parent folders are created).
    title : str, optional
        Figure title.

    Returns
    -------
    Path
        The file written.

    Notes
    -----
    One row of panels per output equation: ``D = lambda_max - lambda_min`` on a log axis
    (top) and the held parameter vector ``theta`` (paper convention, unit norm) below.
    Flagged updates are marked on the ``D`` panel: red crosses where the estimate was not
    accepted (held), orange circles where the window does not determine the model, grey
    shading where the window had too few rows.
    """
    n_eq = trace.n_equations
    fig, axes = _figure(2 * n_eq, 1, height=2.4)
    t = np.asarray(trace.time, dtype=float)
    labels = trace.labels()
    d_all = trace.arrays["D"]
    theta_all = trace.arrays["theta"]
    accepted = trace.arrays["accepted"]
    determined = trace.arrays["determined"]
    few = np.asarray(trace.not_enough_data, dtype=bool)
    for e in range(n_eq):
        ax_d, ax_t = axes[2 * e, 0], axes[2 * e + 1, 0]
        name = trace.output_names[e] if e < len(trace.output_names) else f"y{e}"
        d = np.asarray(d_all[:, e], dtype=float)
        positive = d > 0
        ax_d.plot(t, np.where(positive, d, np.nan), "-", color="C0", lw=1.2, label="D")
        if np.any(positive):
            ax_d.set_yscale("log")
        bad = ~accepted[:, e]
        if np.any(bad):
            ax_d.plot(
                t[bad],
                np.where(positive, d, np.nan)[bad],
                "x",
                color="red",
                label=f"not accepted ({int(bad.sum())})",
            )
        und = ~determined[:, e] & ~bad
        if np.any(und):
            ax_d.plot(
                t[und],
                np.where(positive, d, np.nan)[und],
                "o",
                mfc="none",
                color="orange",
                label=f"not determined ({int(und.sum())})",
            )
        for k in np.flatnonzero(few):
            ax_d.axvspan(t[k] - 0.5 * _step(t), t[k] + 0.5 * _step(t), color="0.85", lw=0)
        ax_d.set_ylabel(f"D ({name})")
        ax_d.grid(True, alpha=0.3)
        ax_d.legend(loc="best", fontsize="small")
        for i, lab in enumerate(labels):
            ax_t.plot(t, theta_all[:, e, i], lw=1.0, label=lab)
        ax_t.set_ylabel(f"theta ({name})")
        ax_t.grid(True, alpha=0.3)
        ax_t.legend(loc="center left", bbox_to_anchor=(1.0, 0.5), fontsize="small")
    axes[-1, 0].set_xlabel("time [s]" if trace.sample_time != 1.0 else "sample")
    axes[0, 0].set_title(title or f"CLPC trace: {len(trace)} updates")
    return _save(fig, path)


def _step(t: np.ndarray) -> float:
    return float(np.median(np.diff(t))) if t.size > 1 else 1.0


def plot_compare(
    time: Any,
    y: Any,
    y_hat: Any,
    fit: Any,
    path: str | PathLike[str],
    *,
    names: Any = None,
    label: str = "model",
    title: str | None = None,
) -> Path:
    """Plot measured against modelled outputs, with the fit % in the legend.

    Parameters
    ----------
    time : array_like, shape (T,)
        Time [s] (or sample index).
    y, y_hat : array_like, shape (T,) or (T, n_outputs)
        Measured and modelled (simulated or predicted) outputs.
    fit : float or array_like, shape (n_outputs,)
        Fit % per output (e.g. from :func:`clpc.fit_percent`); ``None``/NaN prints "n/a".
    path : str or path-like
        PNG file to write.
    names : sequence of str, optional
        Output names.
    label : str
        Legend label of the model curve, e.g. ``"simulation"`` or ``"10-step prediction"``.
    title : str, optional
        Figure title.

    Returns
    -------
    Path
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
    fig, axes = _figure(n_out, 1, height=2.8)
    for j in range(n_out):
        ax = axes[j, 0]
        fit_txt = "n/a" if not np.isfinite(fits[j]) else f"{fits[j]:.1f} %"
        ax.plot(t, ya[:, j], color="k", lw=1.0, label=f"measured {names[j]}")
        ax.plot(t, yh[:, j], color="C1", lw=1.0, ls="--", label=f"{label} (fit {fit_txt})")
        ax.set_ylabel(names[j])
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize="small")
    axes[-1, 0].set_xlabel("time [s]")
    axes[0, 0].set_title(title or f"measured vs {label}")
    return _save(fig, path)


def plot_pz(model: LinearModel, path: str | PathLike[str], *, title: str | None = None) -> Path:
    """Pole-zero map of every channel of a model, with the unit circle.

    Parameters
    ----------
    model : LinearModel
        The identified model (monic convention; poles of ``A_j(z)``, zeros of each
        ``B_ji(z)``).
    path : str or path-like
        PNG file to write.
    title : str, optional

    Returns
    -------
    Path
    """
    fig, axes = _figure(1, 1, height=5.0)
    ax = axes[0, 0]
    circle = np.exp(1j * np.linspace(0, 2 * np.pi, 361))
    ax.plot(circle.real, circle.imag, color="0.5", lw=0.8)
    ax.axhline(0, color="0.8", lw=0.5)
    ax.axvline(0, color="0.8", lw=0.5)
    for j in range(model.n_outputs):
        out = model.output_names[j] if j < len(model.output_names) else f"y{j}"
        p = model.poles(j)
        ax.plot(p.real, p.imag, "x", ms=9, mew=2, color=f"C{j}", label=f"poles {out}")
        for i in range(model.n_inputs):
            z = model.zeros(j, i)
            if z.size:
                inp = model.input_names[i] if i < len(model.input_names) else f"u{i}"
                ax.plot(
                    z.real,
                    z.imag,
                    "o",
                    ms=8,
                    mfc="none",
                    color=f"C{j}",
                    label=f"zeros {inp}->{out}",
                )
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("Re z")
    ax.set_ylabel("Im z")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    ax.set_title(title or "pole-zero map (x poles, o zeros)")
    return _save(fig, path)


def plot_bode(
    model: LinearModel, path: str | PathLike[str], *, n_freqs: int = 512, title: str | None = None
) -> Path:
    """Bode plot (magnitude in dB, phase in degrees) of every input-output channel.

    Parameters
    ----------
    model : LinearModel
        The identified model.
    path : str or path-like
        PNG file to write.
    n_freqs : int
        Frequencies from 0 to Nyquist (log axis from the first nonzero one).
    title : str, optional

    Returns
    -------
    Path
    """
    fig, axes = _figure(2, 1, height=2.8)
    ax_m, ax_p = axes[0, 0], axes[1, 0]
    for j in range(model.n_outputs):
        for i in range(model.n_inputs):
            if not np.any(model.numerators[j, i]):
                continue  # e.g. off-diagonal channels of a "paired" model
            f, h = model.frequency_response(n_freqs, output=j, input=i)
            keep = f > 0
            inp = model.input_names[i] if i < len(model.input_names) else f"u{i}"
            out = model.output_names[j] if j < len(model.output_names) else f"y{j}"
            with np.errstate(divide="ignore"):
                mag = 20 * np.log10(np.abs(h[keep]))
            ax_m.semilogx(f[keep], mag, lw=1.2, label=f"{inp} -> {out}")
            ax_p.semilogx(f[keep], np.degrees(np.unwrap(np.angle(h[keep]))), lw=1.2)
    ax_m.set_ylabel("magnitude [dB]")
    ax_p.set_ylabel("phase [deg]")
    ax_p.set_xlabel("frequency [Hz]" if model.dt != 1.0 else "frequency [cycles/sample]")
    for ax in (ax_m, ax_p):
        ax.grid(True, which="both", alpha=0.3)
    ax_m.legend(loc="best", fontsize="small")
    ax_m.set_title(title or "Bode plot")
    return _save(fig, path)


def plot_residuals(analysis: Any, ax: Any = None) -> Figure:
    """Residual autocorrelation and input-residual cross-correlation with their bands.

    One row per output: the autocorrelation ``rho_e(k)``, ``k = 0..M``, then the
    cross-correlation with each input, ``tau = -M..M``; the shaded bands are the per-lag
    limits of :func:`clpc.residual_analysis` and each title gives the test's outcome.

    Parameters
    ----------
    analysis : ResidualAnalysis
        From :func:`clpc.residual_analysis`.
    ax : sequence of matplotlib Axes, optional
        ``n_outputs * (1 + n_inputs)`` axes (row-major) to draw on; default a new figure.

    Returns
    -------
    matplotlib.figure.Figure
        The figure the axes belong to (save it with ``fig.savefig``).
    """
    n_out, n_in = analysis.cross_correlation.shape[:2]
    if ax is None:
        fig, axes = _figure(n_out, 1 + n_in, height=2.6)
        fig.set_size_inches(max(8.0, 4.0 * (1 + n_in)), 0.6 + 2.6 * n_out)
        flat = list(axes.ravel())
    else:
        flat = list(np.ravel(np.asarray(ax, dtype=object)))
        if len(flat) != n_out * (1 + n_in):
            raise ValueError(
                f"plot_residuals needs {n_out * (1 + n_in)} axes (outputs x (1 + inputs)); "
                f"got {len(flat)}."
            )
        fig = flat[0].figure
    tests = list(analysis.independence)
    for j in range(n_out):
        a = flat[j * (1 + n_in)]
        lags, band = analysis.lags, analysis.auto_band
        a.fill_between(lags, -band, band, color="C0", alpha=0.15, lw=0)
        a.vlines(lags[1:], 0, analysis.autocorrelation[j, 1:], color="C0", lw=1.5)
        a.axhline(0, color="0.5", lw=0.6)
        a.set_xlabel("lag k [samples]")
        a.set_ylabel("autocorrelation")
        a.set_title(_test_title(analysis.whiteness[j]), fontsize="small")
        for i in range(n_in):
            b = flat[j * (1 + n_in) + 1 + i]
            tau = analysis.cross_lags
            bnd = analysis.cross_band[j, i]
            b.fill_between(tau, -bnd, bnd, color="C1", alpha=0.15, lw=0)
            b.vlines(tau, 0, analysis.cross_correlation[j, i], color="C1", lw=1.5)
            b.axhline(0, color="0.5", lw=0.6)
            b.set_xlabel("lag tau [samples] (u leads for tau > 0)")
            b.set_ylabel("cross-correlation")
            b.set_title(_test_title(tests[j * n_in + i]), fontsize="small")
    return fig


def _test_title(test: Any) -> str:
    sym = "Q" if test.name.startswith("whiteness") else "zeta"
    rel = "<=" if test.passed else ">"
    outcome = "passed" if test.passed else "FAILED"
    return f"{test.name}\n{sym} = {test.statistic:.3g} {rel} {test.threshold:.3g}: {outcome}"
