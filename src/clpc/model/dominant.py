"""The dominant poles of a model in an engineer's units: frequency, damping, time constant.

A discrete pole ``p`` of sample time ``dt`` is the continuous pole ``s = ln(p) / dt``
(principal logarithm). A complex pair has the natural frequency ``wn = |s|`` [rad/s]
(``wn / 2 pi`` Hz) and the damping ratio ``zeta = -Re(s) / |s|`` (negative: growing); a
real pole in ``(0, 1)`` the time constant ``tau = -dt / ln(p)`` [s], one beyond 1 the
growth time ``dt / ln(p)``; ``p = 1`` is an integrator; a negative real pole alternates
in sign every sample (no continuous equivalent). The dominant poles are the slowest ones:
the largest ``|p|`` (for a stable model, the closest to the unit circle); a complex pair
counts once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.core.polynomials import UNIT_CIRCLE_TOL

__all__ = ["DOMINANT_POLES", "DominantPole", "companion_roots", "dominant_poles"]

#: How many poles (a complex pair counting once) :func:`dominant_poles` returns at most.
DOMINANT_POLES = 3

#: An imaginary part below this (relative to ``|p|``) is a real pole: ``np.roots`` leaves
#: rounding in the imaginary part of a real root.
_REAL_TOL = 1e-9


@dataclass(frozen=True)
class DominantPole:
    """One dominant pole (or complex pair) of a model.

    Attributes
    ----------
    pole : complex
        The discrete pole (of a pair: the one with a positive imaginary part).
    kind : str
        ``"complex pair"``, ``"real"``, ``"integrator"``, ``"alternating"`` (negative
        real) or ``"delay"`` (at ``z = 0``).
    natural_frequency : float or None
        ``wn`` [rad/s] of a complex pair.
    damping : float or None
        ``zeta`` of a complex pair (dimensionless; negative: growing).
    time_constant : float or None
        ``tau`` [s] of a real pole in ``(0, 1)``; negative for one beyond 1 (its growth time
        is ``-tau``).
    """

    pole: complex
    kind: str
    natural_frequency: float | None = None
    damping: float | None = None
    time_constant: float | None = None

    @property
    def frequency_hz(self) -> float | None:
        """``wn / 2 pi`` [Hz] of a complex pair."""
        wn = self.natural_frequency
        return None if wn is None else wn / (2.0 * math.pi)

    @property
    def text(self) -> str:
        """E.g. ``"0.95±0.12j: wn 1.49 rad/s (0.237 Hz), damping 0.33"``."""
        p = self.pole
        if self.kind == "complex pair":
            assert self.natural_frequency is not None and self.damping is not None
            return (
                f"{p.real:.4g}±{abs(p.imag):.4g}j: wn {self.natural_frequency:.3g} rad/s "
                f"({self.frequency_hz:.3g} Hz), damping {self.damping:.3g}"
            )
        if self.kind == "integrator":
            return f"{p.real:.4g}: integrator"
        if self.kind == "delay":
            return "0: a pure delay of one sample"
        if self.kind == "alternating":
            return f"{p.real:.4g}: alternating sign every sample (no continuous equivalent)"
        tau = self.time_constant
        assert tau is not None
        if tau < 0:
            return f"{p.real:.4g}: unstable, grows e-fold in {-tau:.3g} s"
        return f"{p.real:.4g}: time constant {tau:.3g} s"


def _describe(p: complex, dt: float) -> DominantPole:
    if abs(p.imag) > _REAL_TOL * max(abs(p), 1e-300):
        s = complex(np.log(p)) / dt
        wn = abs(s)
        return DominantPole(p, "complex pair", wn, -s.real / wn if wn > 0 else None)
    r = p.real
    if abs(r - 1.0) <= UNIT_CIRCLE_TOL:
        return DominantPole(complex(r, 0.0), "integrator")
    if r == 0.0:
        return DominantPole(0j, "delay")
    if r < 0.0:
        return DominantPole(complex(r, 0.0), "alternating")
    return DominantPole(complex(r, 0.0), "real", time_constant=-dt / math.log(r))


def dominant_poles(model: Any, output: int = 0, count: int = DOMINANT_POLES) -> list[DominantPole]:
    """The slowest poles of one output's equation, in continuous-time terms.

    Parameters
    ----------
    model : LinearModel
        The model (its ``dt`` [s] gives the units).
    output : int
        Output index (default 0).
    count : int
        At most this many (a complex pair counts once; default :data:`DOMINANT_POLES`).

    Returns
    -------
    list of DominantPole
        Largest ``|p|`` first; empty when the model has no poles.
    """
    poles = np.asarray(model.poles(output), dtype=complex)
    keep = poles[poles.imag >= -_REAL_TOL * np.maximum(np.abs(poles), 1e-300)]  # pairs once
    order = np.argsort(-np.abs(keep), kind="stable")
    return [_describe(complex(keep[k]), float(model.dt)) for k in order[: max(int(count), 0)]]


def companion_roots(den: np.ndarray) -> np.ndarray:
    """Roots of each monic row of ``den`` (n, m >= 2), shape (n, m - 1); NaN if not finite."""
    n, m = den.shape
    comp = np.zeros((n, m - 1, m - 1))
    comp[:, 0, :] = -den[:, 1:]
    comp[:, np.arange(1, m - 1), np.arange(m - 2)] = 1.0
    ok = np.all(np.isfinite(comp), axis=(1, 2))
    roots = np.full((n, m - 1), np.nan + 0j)
    if ok.any():
        roots[ok] = np.linalg.eigvals(comp[ok])
    return roots
