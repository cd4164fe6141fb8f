"""The figure of a multi-model: local DC gain and poles against the operating point, validity.

On an integrating plant (voltage -> position: a local model with a pole within
:data:`clpc.core.polynomials.UNIT_CIRCLE_TOL` of ``z = 1``) the DC gain is infinite, and
the identified local models, whose pole lands just inside or outside the circle, give huge
gains of either sign that mean nothing. The top panel then draws the integrating gain
instead (:func:`integrating_gain`): the static gain of ``(1 - z^-1) G(z)``, per second.

Headless: a :class:`matplotlib.figure.Figure` on the Agg canvas, matplotlib imported only
inside the function (``clpc multimodel --figure`` and the paper's crank-servo part draw it).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["integrating_gain", "plot_multimodel"]


def integrating_gain(model: Any) -> float:
    """Static gain of ``(1 - z^-1) G(z)`` of a single-input, single-output model [1/s].

    With ``A(q) = (1 - q) Ã(q)`` (``q = z^-1``), ``Ã(1) = -A'(1) = -sum_k k a_k``, so the
    gain is ``B(1) / Ã(1)`` per sample, divided by ``dt`` (per second). It is the velocity
    gain of an integrator: ``y(n) = y(n-1) + b u(n-1)`` gives ``b / dt``. For a pole near
    but not at ``z = 1`` it is the same limit to first order in the pole's distance.

    Parameters
    ----------
    model : LinearModel
        One input, one output.

    Returns
    -------
    float
        NaN when ``Ã(1)`` is zero (a double pole at 1).
    """
    den = np.asarray(model.denominators[0], dtype=float)
    num = np.asarray(model.numerators[0, 0], dtype=float)
    deflated = -float(np.sum(np.arange(den.size) * den))
    if deflated == 0.0:
        return float("nan")
    return float(num.sum()) / deflated / float(model.dt)


def _dc_gain(model: Any) -> float:
    return float(model.dc_gain()[0, 0])


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
        A known plant's curves (e.g. the crank servo's closed form in the paper's
        application, ``clpc_paper.plants.crank_operating_point``): drawn dashed.
    dpi : int
        Resolution of the PNG.

    Returns
    -------
    str
        The file name written.
    """
    from clpc.core.notebook_figure import NotebookFigure

    psi = _grid(mm)
    lin = [mm.linearize(p) for p in psi]
    integrating = any(m.stability == "integrating" for m in mm.local_models)
    gain_of = integrating_gain if integrating else _dc_gain
    gain_label = "local integrating gain [1/s]" if integrating else "local DC gain"
    gains = np.array([gain_of(m) for m in lin])
    dt = mm.dt
    freqs = np.array(
        [np.sort(np.abs(np.log(m.poles().astype(complex))) / (2 * np.pi * dt))[:2] for m in lin]
    )
    fig = NotebookFigure(figsize=(6.4, 7.2), layout="constrained")
    ax1, ax2, ax3 = fig.subplots(3, 1, sharex=True)
    ax1.plot(psi, gains, "C0", label="multi-model (frozen validity)")
    own = [gain_of(m) for m in mm.local_models]
    ax1.plot(mm.centres, own, "C0o", label="local models at their centres")
    ax2.plot(psi, freqs[:, 0], "C1", label="multi-model poles |s| / 2 pi")
    if freqs.shape[1] > 1:
        ax2.plot(psi, freqs[:, 1], "C1", lw=0.8)
    if reference is not None:
        rpsi, rgain, rpoles = (np.asarray(r) for r in reference)
        if not integrating:  # the reference's gain is a DC gain
            ax1.plot(rpsi, rgain, "k--", lw=1, label="plant, closed form")
        if np.any(np.isfinite(rpoles)):
            ax2.plot(rpsi, np.abs(rpoles[:, 0]), "k--", lw=1, label="plant, closed form")
    ax1.set_ylabel(gain_label)
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
