"""Stable monic polynomials through their reflection coefficients (Levinson step-up/down).

``A(z) = 1 + a_1 z^-1 + ... + a_na z^-na`` has every root strictly inside the unit circle if
and only if its reflection coefficients satisfy ``|kappa_m| < 1`` (the Schur-Cohn test run
backwards). :class:`clpc.OE` searches over ``kappa = MAX_KAPPA tanh(rho)``, so every model
it returns is stable.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MAX_KAPPA", "MAX_START_RADIUS", "poly_from_reflection", "reflection_from_poly"]

#: Largest |kappa| of a model: ``kappa = MAX_KAPPA tanh(rho)`` keeps every pole a margin
#: inside the unit circle, so that a fitted integrator stays (just) stable in floating point.
MAX_KAPPA = 1.0 - 1e-6
#: Poles of a start farther out than this radius are moved in to it (after reflection).
MAX_START_RADIUS = 0.999


def poly_from_reflection(kappa: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Monic polynomial from reflection coefficients (Levinson step-up) and its Jacobian.

    Parameters
    ----------
    kappa : ndarray, shape (na,)
        Reflection coefficients; ``|kappa_m| < 1`` for every ``m`` <=> all roots inside the
        unit circle.

    Returns
    -------
    a : ndarray, shape (na + 1,)
        ``[1, a_1, ..., a_na]`` (ascending powers of ``z^-1``).
    da : ndarray, shape (na + 1, na)
        ``d a_i / d kappa_m``.
    """
    na = kappa.size
    a = np.zeros(na + 1)
    a[0] = 1.0
    da = np.zeros((na + 1, na))
    for m in range(1, na + 1):  # loop over the order, not over samples
        idx = np.arange(1, m + 1)
        a_prev, da_prev = a.copy(), da.copy()
        a[idx] = a_prev[idx] + kappa[m - 1] * a_prev[m - idx]
        da[idx] = da_prev[idx] + kappa[m - 1] * da_prev[m - idx]
        da[idx, m - 1] += a_prev[m - idx]
    return a, da


def reflection_from_poly(a: np.ndarray) -> np.ndarray:
    """Reflection coefficients of a monic polynomial (Levinson step-down).

    Poles outside the unit circle are first reflected to ``1/conj(z)`` and every pole is
    kept within :data:`MAX_START_RADIUS`, so the result describes a stable polynomial with
    every ``|kappa_m| < MAX_KAPPA``.

    Parameters
    ----------
    a : ndarray, shape (na + 1,)
        ``[1, a_1, ..., a_na]``.

    Returns
    -------
    ndarray, shape (na,)
    """
    a = np.asarray(a, dtype=np.float64) / a[0]
    roots = np.roots(a)
    if roots.size and np.max(np.abs(roots)) > MAX_START_RADIUS:
        radius = np.abs(roots)
        outside = radius > 1.0
        roots = np.where(outside, 1.0 / np.conj(roots), roots)
        radius = np.abs(roots)
        roots = np.where(radius > MAX_START_RADIUS, roots * MAX_START_RADIUS / radius, roots)
        a = np.real(np.poly(roots))
    na = a.size - 1
    kappa = np.zeros(na)
    cur = a.copy()
    for m in range(na, 0, -1):
        k = float(np.clip(cur[m], -MAX_KAPPA, MAX_KAPPA))
        kappa[m - 1] = k
        idx = np.arange(1, m)
        cur[idx] = (cur[idx] - k * cur[m - idx]) / (1.0 - k * k)
        cur[m] = 0.0
    return kappa
