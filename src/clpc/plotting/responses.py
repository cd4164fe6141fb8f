"""Figures of a model alone: pole-zero map, step response, Bode plot."""

from __future__ import annotations

from os import PathLike
from typing import Any

import numpy as np

from clpc.core.figure import COLORS, axes_for, place_legend, save_figure, time_label

__all__ = ["bode_frequencies", "plot_bode", "plot_pz", "plot_step", "step_samples"]


def _name(names: Any, k: int, prefix: str) -> str:
    return str(names[k]) if k < len(names) else f"{prefix}{k}"


def _channels(model: Any) -> list[tuple[int, int, str]]:
    """(output, input, label) of every channel whose numerator is not identically zero."""
    out = []
    for j in range(model.n_outputs):
        for i in range(model.n_inputs):
            if np.any(model.numerators[j, i]):  # e.g. off-diagonal channels of "paired"
                inp, outp = _name(model.input_names, i, "u"), _name(model.output_names, j, "y")
                out.append((j, i, f"{inp} → {outp}"))
    return out


def bode_frequencies(model: Any, n: int = 512, decades: float = 3.0) -> np.ndarray:
    """Log-spaced frequencies [Hz] from ``10**-decades`` times Nyquist up to Nyquist.

    Parameters
    ----------
    model : LinearModel
    n : int
        Number of frequencies.
    decades : float
        Span below the Nyquist frequency ``1 / (2 dt)``.

    Returns
    -------
    ndarray, shape (n,)
        Increasing; the last is exactly the Nyquist frequency.
    """
    nyq = 0.5 / model.dt
    return np.logspace(np.log10(nyq) - decades, np.log10(nyq), n)


def plot_bode(
    model: Any,
    path: str | PathLike[str] | None = None,
    *,
    n_freqs: int = 512,
    title: str | None = None,
    ax: Any = None,
) -> Any:
    """Bode plot (magnitude in dB, phase in degrees) of every input-output channel.

    Parameters
    ----------
    model : LinearModel
        The identified model.
    path : str or path-like, optional
        Also write the figure as PNG here.
    n_freqs : int
        Log-spaced frequencies over three decades up to Nyquist (:func:`bode_frequencies`);
        the Nyquist frequency is marked.
    title : str, optional
    ax : pair of matplotlib Axes, optional
        ``(magnitude, phase)`` axes to draw on; default: a new figure.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax_m, ax_p) = axes_for(ax, 2, height=2.6, fixed=True)
    freqs = bode_frequencies(model, n_freqs)
    for k, (j, i, label) in enumerate(_channels(model)):
        f, h = model.frequency_response(freqs, output=j, input=i)
        with np.errstate(divide="ignore"):
            mag = 20 * np.log10(np.abs(h))
        ax_m.semilogx(f, mag, lw=1.3, color=f"C{k}", label=label)
        ax_p.semilogx(f, np.degrees(np.unwrap(np.angle(h))), lw=1.3, color=f"C{k}")
    nyq = freqs[-1]
    unit = "Hz" if model.dt != 1.0 else "cycles/sample"
    for a in (ax_m, ax_p):
        a.axvline(nyq, color=COLORS["nyquist"], ls="--", lw=1.0)
        a.grid(True, which="both", alpha=0.3)
        a.set_xlim(freqs[0], nyq * 1.15)
        a.set_xlabel(f"frequency [{unit}]")
    ax_m.text(nyq, 1.0, f" Nyquist {nyq:.3g} {unit}", transform=ax_m.get_xaxis_transform(),
              ha="right", va="bottom", fontsize="small", color=COLORS["nyquist"])  # fmt: skip
    ax_m.set_ylabel("magnitude [dB]")
    ax_p.set_ylabel("phase [deg]")
    place_legend(ax_m)
    fig.suptitle(title or "Bode plot")
    save_figure(fig, path)
    return fig


def step_samples(model: Any, lo: int = 30, hi: int = 2000) -> int:
    """Samples for a step response to settle: five times the slowest stable time constant."""
    mags = np.concatenate([np.abs(model.poles(j)) for j in range(model.n_outputs)])
    mags = mags[(mags > 0) & (mags < 1)]
    if mags.size == 0:
        return lo
    tau = -1.0 / np.log(mags.max())  # samples
    return int(np.clip(np.ceil(5 * tau), lo, hi))


def plot_step(
    model: Any,
    path: str | PathLike[str] | None = None,
    *,
    n_samples: int | None = None,
    title: str | None = None,
    ax: Any = None,
) -> Any:
    """Unit step response of every input-output channel (zero initial state, no offset).

    Parameters
    ----------
    model : LinearModel
    path : str or path-like, optional
        Also write the figure as PNG here.
    n_samples : int, optional
        Length; default :func:`step_samples` (five times the slowest time constant).
    title : str, optional
    ax : matplotlib Axes, optional
        Axes to draw on; default: a new figure.

    Returns
    -------
    matplotlib.figure.Figure
        The static gain ``G(1)`` of each channel is drawn dashed (when finite).
    """
    fig, (axs,) = axes_for(ax, 1, height=3.0, fixed=True)
    n = n_samples or step_samples(model)
    t = np.arange(n) * model.dt
    gains = model.dc_gain()
    for k, (j, i, label) in enumerate(_channels(model)):
        u = np.zeros((n, model.n_inputs))
        u[:, i] = 1.0
        with np.errstate(over="ignore", invalid="ignore"):
            y = model.simulate(u, include_offset=False).reshape(n, -1)[:, j]
        axs.step(t, y, where="post", lw=1.3, color=f"C{k}", label=label)
        if np.isfinite(gains[j, i]):
            axs.axhline(gains[j, i], color=f"C{k}", ls=":", lw=1.0)
    axs.set_xlabel(time_label(model.dt))
    axs.set_ylabel("output per unit input [-]")
    axs.grid(True, alpha=0.3)
    place_legend(axs)
    fig.suptitle(title or "step response (dotted: static gain)")
    save_figure(fig, path)
    return fig


def plot_pz(
    model: Any,
    path: str | PathLike[str] | None = None,
    *,
    title: str | None = None,
    ax: Any = None,
) -> Any:
    """Pole-zero map of every channel of a model, with the unit circle.

    Parameters
    ----------
    model : LinearModel
        The identified model (monic convention; poles of ``A_j(z)``, zeros of each
        ``B_ji(z)``).
    path : str or path-like, optional
        Also write the figure as PNG here.
    title : str, optional
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (axz,) = axes_for(ax, 1, height=3.4, width=5.6)
    circle = np.exp(1j * np.linspace(0, 2 * np.pi, 361))
    axz.plot(circle.real, circle.imag, color="0.5", lw=0.8)
    axz.axhline(0, color="0.8", lw=0.5)
    axz.axvline(0, color="0.8", lw=0.5)
    for j in range(model.n_outputs):
        out = _name(model.output_names, j, "y")
        p = model.poles(j)
        axz.plot(p.real, p.imag, "x", ms=9, mew=2, color=f"C{j}", label=f"poles of {out}")
        for i in range(model.n_inputs):
            z = model.zeros(j, i)
            if z.size:
                inp = _name(model.input_names, i, "u")
                axz.plot(z.real, z.imag, "o", ms=8, mfc="none", color=f"C{j}",
                         label=f"zeros {inp} → {out}")  # fmt: skip
    axz.set_aspect("equal", adjustable="datalim")
    axz.set_xlabel("Re z [-]")
    axz.set_ylabel("Im z [-]")
    axz.grid(True, alpha=0.3)
    place_legend(axz, outside=True)
    fig.suptitle(title or "pole-zero map (x poles, o zeros)")
    save_figure(fig, path)
    return fig
