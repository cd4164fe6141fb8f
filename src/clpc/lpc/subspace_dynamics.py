"""``A`` and ``C`` of one order, their characteristic polynomial and the maps ``M_k``.

Cayley-Hamilton: ``C (zI - A)^-1 = sum_k M_k z^-k / det(zI - A)`` with
``M_k = sum_{q<k} a_q C A^(k-1-q)``. Step 3 of :mod:`clpc.lpc.subspace` (``B``, ``D`` by least
squares, :mod:`clpc.lpc.subspace_bd`) and the difference equations
(:mod:`clpc.lpc.subspace_model`) are written with them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["MAX_GROWTH", "StateDynamics"]

#: Largest growth of the filtered input over a record for the simulation-error fit of B, D.
MAX_GROWTH = 1e8


@dataclass
class StateDynamics:
    """``A``, ``C``, the characteristic polynomial and the maps ``M_k`` of one order.

    Parameters
    ----------
    a : numpy.ndarray, shape (n, n)
        ``A``.
    c : numpy.ndarray, shape (l, n)
        ``C`` (scaled outputs).
    a_form : str
        How ``A`` was estimated (:meth:`clpc.lpc.subspace_projection.Projections.a_c`).

    Attributes
    ----------
    den : numpy.ndarray, shape (n + 1,)
        ``det(zI - A)``, ascending powers of ``z^-1`` (``den[0] = 1``).
    maps : numpy.ndarray, shape (n, l, n)
        ``M_k = sum_{q<k} den[q] C A^(k-1-q)``, ``k = 1 .. n``: the numerators of
        ``C (zI - A)^-1``.
    radius : float
        Largest pole modulus (0 at order 0).
    """

    a: np.ndarray
    c: np.ndarray
    a_form: str = "shift"
    den: np.ndarray = field(init=False)
    maps: np.ndarray = field(init=False)  # (n, l, n): M_k for k = 1 .. n
    radius: float = field(init=False)

    def __post_init__(self) -> None:
        n = self.a.shape[0]
        poles = np.linalg.eigvals(self.a)
        self.radius = float(np.max(np.abs(poles))) if n else 0.0
        self.den = np.real(np.poly(poles)) if n else np.ones(1)
        powers = np.empty((n, *self.c.shape))  # C A^p, p = 0 .. n-1
        cur = self.c
        for p in range(n):
            powers[p] = cur
            cur = cur @ self.a
        self.maps = np.empty((n, *self.c.shape))
        for k in range(1, n + 1):
            self.maps[k - 1] = sum(self.den[q] * powers[k - 1 - q] for q in range(k))

    @property
    def n(self) -> int:
        """The order."""
        return int(self.a.shape[0])

    def simulated(self, longest: int) -> bool:
        """Whether the simulation form is used: growth at most :data:`MAX_GROWTH`.

        Parameters
        ----------
        longest : int
            Samples of the longest experiment the model runs over.

        Returns
        -------
        bool
            ``radius <= 1`` or ``radius ** longest <= MAX_GROWTH``.
        """
        return self.radius <= 1.0 or longest * math.log(self.radius) <= math.log(MAX_GROWTH)
