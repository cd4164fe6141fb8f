"""Figures of a multi-model: local DC gain and poles against the operating point, validity.

Headless like :mod:`clpc.experiment.figures`: a :class:`matplotlib.figure.Figure` on the Agg
canvas, matplotlib imported only inside the functions.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["fig_fits", "plot_multimodel"]


def _grid(mm: Any, lo: float | None = None, hi: float | None = None) -> np.ndarray:
    c = mm.centres
    span = float(c.max() - c.min()) or 2.0
    lo = float(c.min() - 0.15 * span) if lo is None else lo
    hi = float(c.max() + 0.15 * span) if hi is None else hi
    return np.linspace(lo, hi, 200)


def plot_multimodel(
    mm: Any, path: str | Path, *, reference: tuple[Any, Any, Any] | None = None, dpi: int = 110
) -> str:
    """Local DC gain, local pole frequencies and validity functions against ``psi``.

    Parameters
    ----------
    mm : MultiModel
        A fitted multi-model.
    path : str or Path
        PNG to write.
    reference : (psi, dc_gain, poles_hz), optional
        A known plant's curves (e.g. :func:`clpc.plants.crank_servo.crank_operating_point`):
        drawn dashed.
    dpi : int

    Returns
    -------
    str
        The file name written.
    """
    from matplotlib.figure import Figure

    psi = _grid(mm)
    lin = [mm.linearize(p) for p in psi]
    gains = np.array([float(m.dc_gain()[0, 0]) for m in lin])
    dt = mm.dt
    freqs = np.array(
        [np.sort(np.abs(np.log(m.poles().astype(complex))) / (2 * np.pi * dt))[:2] for m in lin]
    )
    fig = Figure(figsize=(6.4, 7.2), layout="constrained")
    ax1, ax2, ax3 = fig.subplots(3, 1, sharex=True)
    ax1.plot(psi, gains, "C0", label="multi-model (frozen validity)")
    own = [float(m.dc_gain()[0, 0]) for m in mm.local_models]
    ax1.plot(mm.centres, own, "C0o", label="local models at their centres")
    ax2.plot(psi, freqs[:, 0], "C1", label="multi-model poles |s| / 2 pi")
    if freqs.shape[1] > 1:
        ax2.plot(psi, freqs[:, 1], "C1", lw=0.8)
    if reference is not None:
        rpsi, rgain, rpoles = (np.asarray(r) for r in reference)
        ax1.plot(rpsi, rgain, "k--", lw=1, label="plant, closed form")
        if np.any(np.isfinite(rpoles)):
            ax2.plot(rpsi, np.abs(rpoles[:, 0]), "k--", lw=1, label="plant, closed form")
    ax1.set_ylabel("local DC gain")
    ax1.legend(fontsize=7)
    ax2.set_ylabel("pole frequency [Hz]")
    ax2.legend(fontsize=7)
    phi = mm.validity(psi)
    for i in range(phi.shape[1]):
        ax3.plot(psi, phi[:, i], lw=1)
    ax3.set_ylabel("validity")
    ax3.set_xlabel(f"scheduling variable {mm.diagnostics.get('schedule', '')}")
    ax3.set_ylim(-0.05, 1.05)
    fig.suptitle(f"Multi-model: {mm.n_models} local models", fontsize=10)
    out = Path(path)
    fig.savefig(out, dpi=dpi)
    return out.name


def fig_fits(
    path: Path, rec: Any, models: dict[str, Any], start: int, name: str, quick: bool
) -> str:
    """Validation free runs of the global LS model and the multi-model against the plant."""
    from matplotlib.figure import Figure

    u, y = rec.command, rec.position
    n = min(y.size - start, 3000 if not quick else 1500)
    t = np.arange(start, start + n) * rec.sample_time
    fig = Figure(figsize=(6.4, 3.6), layout="constrained")
    ax = fig.subplots()
    ax.plot(t, y[start : start + n], "k", lw=1.2, label="measured position")
    for key, style in (("global_ls", "C3"), ("multimodel", "C0")):
        m = models[key]
        sim = m.simulate(u[start:], y_init=y[start - 2 : start], u_init=u[start - 2 : start])
        ax.plot(t, sim[:n], style, lw=0.9, label=key.replace("_", " ") + " (free run)")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("position [rad]")
    ax.set_title(f"Crank servo ({name}): validation levels", fontsize=10)
    ax.legend(fontsize=7)
    fig.savefig(path, dpi=110 if not quick else 80)
    return path.name
