"""Polynomial helpers, written once: theta to monic form, and the Schur-Cohn stability test.

Plain Python in numba's subset, registered with ``numba.extending.register_jitable``: the
model calls them as they are, the CLPC kernel compiles them into its loop, :func:`monic_many`
and :func:`stable_many` run them compiled over many equations at once.

Conventions (paper eq. 17, ``y^T a + u^T b = r``): ``theta = [a_0..a_na, b_0..b_nb, ...]``
(one ``b`` block per input, or a single block for the paper's paired MIMO). The monic
form is ``A(z) = 1 + a_1/a_0 z^-1 + ...`` and ``B(z) = -(b_0 z^-nk + b_1 z^-(nk+1) + ...)/a_0``
(the sign eq. 34 drops), so ``scipy.signal.lfilter(B, A, u)`` simulates the model.
"""

from __future__ import annotations

import numba
import numpy as np
from numba.extending import register_jitable

__all__ = [
    "UNIT_CIRCLE_TOL",
    "monic",
    "monic_many",
    "pole_class",
    "pole_words",
    "schur_stable",
    "stable_many",
]

#: A pole closer than this to the unit circle is on it (an integrator at z = 1, or an
#: undamped oscillation elsewhere): an integrator estimated from noisy data lands a few
#: thousandths from z = 1 (the ball-and-beam record, whose beam integrates: 1.0015 at
#: N = 1 and 2).
UNIT_CIRCLE_TOL = 5e-3


def pole_class(poles: np.ndarray, tol: float = UNIT_CIRCLE_TOL) -> str:
    """How a model's poles sit against the unit circle, in one word.

    Parameters
    ----------
    poles : ndarray of complex
        The poles (roots of ``z^na A(z)``).
    tol : float
        Distance from the circle that counts as on it.

    Returns
    -------
    str
        ``"unstable"`` (a pole outside the circle by more than ``tol``), ``"integrating"``
        (a pole within ``tol`` of ``z = 1``, none outside), ``"marginal"`` (a pole on the
        circle elsewhere, e.g. ``z = -1``), else ``"stable"``.
    """
    p = np.asarray(poles, dtype=complex)
    radius = np.abs(p)
    if np.any(radius > 1.0 + tol):
        return "unstable"
    if np.any(np.abs(p - 1.0) <= tol):
        return "integrating"
    return "marginal" if np.any(radius >= 1.0 - tol) else "stable"


def pole_words(kind: str) -> str:
    """The words of a :func:`pole_class` for verdicts, summaries and the model's repr."""
    return {
        "stable": "stable",
        "integrating": "integrating (pole at z = 1)",
        "marginal": "marginally stable (pole on the unit circle)",
        "unstable": "NOT stable (pole outside the unit circle)",
    }[kind]


@register_jitable(error_model="numpy")
def schur_stable(den: np.ndarray, work: np.ndarray) -> bool:
    """Whether every root of ``den[0] z^n + ... + den[n]`` lies strictly inside the unit circle.

    The Schur-Cohn (Levinson) recursion: for ``m = n .. 1`` the reflection coefficient
    ``k = a_m / a_0`` must satisfy ``|k| < 1``, then ``a_i <- (a_i - k a_{m-i}) / (1 - k^2)``.
    ``O(n^2)``, no eigenvalue problem. ``work`` has at least ``len(den)`` entries.
    """
    n = den.shape[0]
    for i in range(n):
        work[i] = den[i]
    for m in range(n - 1, 0, -1):
        k = work[m] / work[0]
        if not abs(k) < 1.0:  # also catches NaN
            return False
        scale = 1.0 - k * k
        for i in range(m // 2 + 1):  # a_i and a_{m-i} together
            lo = work[i]
            hi = work[m - i]
            work[i] = (lo - k * hi) / scale
            work[m - i] = (hi - k * lo) / scale
    return True


@register_jitable(error_model="numpy")
def monic(
    theta: np.ndarray,
    na: int,
    nb: int,
    nk: int,
    paired_input: int,
    den: np.ndarray,
    num: np.ndarray,
) -> None:
    """Fill the monic ``den`` (na + 1,) and ``num`` (n_inputs, nk + nb + 1) of one equation.

    ``paired_input >= 0``: the paper's paired MIMO, the single ``b`` block drives that input;
    ``-1``: one ``b`` block per input (SISO, MISO). ``theta[0]`` must be nonzero.
    """
    a0 = theta[0]
    for k in range(na + 1):
        den[k] = theta[k] / a0
    for i in range(num.shape[0]):
        for k in range(num.shape[1]):
            num[i, k] = 0.0
    n_blocks = (theta.shape[0] - na - 1) // (nb + 1)
    for blk in range(n_blocks):
        target = paired_input if paired_input >= 0 else blk
        for k in range(nb + 1):
            num[target, nk + k] = -theta[na + 1 + blk * (nb + 1) + k] / a0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _monic_rows(
    theta: np.ndarray, na: int, nb: int, nk: int, paired: bool, den: np.ndarray, num: np.ndarray
) -> None:
    for r in range(theta.shape[0]):
        for e in range(theta.shape[1]):
            monic(theta[r, e], na, nb, nk, e if paired else -1, den[r, e], num[r, e])


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _stable_rows(den: np.ndarray, out: np.ndarray) -> None:
    work = np.empty(den.shape[1])
    for r in range(den.shape[0]):
        out[r] = schur_stable(den[r], work)


def monic_many(
    theta: np.ndarray, na: int, nb: int, nk: int, n_inputs: int, paired: bool
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`monic` over many equations (compiled).

    Parameters
    ----------
    theta : ndarray, shape (..., E, p)
        Parameter vectors (``a0`` nonzero); ``E`` equations (outputs) per row.
    na, nb, nk : int
        The structure.
    n_inputs : int
        Inputs of the model.
    paired : bool
        The paper's paired MIMO (equation ``e`` drives input ``e``).

    Returns
    -------
    den : ndarray, shape (..., E, na + 1)
    num : ndarray, shape (..., E, n_inputs, nk + nb + 1)
    """
    theta = np.ascontiguousarray(theta, dtype=np.float64)
    lead = theta.shape[:-2]
    flat = theta.reshape(-1, *theta.shape[-2:])
    den = np.empty((*flat.shape[:2], na + 1))
    num = np.empty((*flat.shape[:2], n_inputs, nk + nb + 1))
    if flat.shape[0]:
        _monic_rows(flat, na, nb, nk, paired, den, num)
    return den.reshape(*lead, *den.shape[1:]), num.reshape(*lead, *num.shape[1:])


def stable_many(den: np.ndarray) -> np.ndarray:
    """:func:`schur_stable` over the leading axes of ``den`` (..., n + 1) (compiled)."""
    den = np.ascontiguousarray(den, dtype=np.float64)
    flat = den.reshape(-1, den.shape[-1])
    out = np.zeros(flat.shape[0], dtype=np.bool_)
    if flat.shape[0]:
        _stable_rows(flat, out)
    return out.reshape(den.shape[:-1])


#: A pole and a zero closer than this (in the z-plane) are one common factor: total least
#: squares at an order above the system's puts the extra factor of both polynomials near
#: the unit circle (a Pisarenko effect), and the pair is then cancelled.
CANCEL_DISTANCE = 0.02


def _factor(root: complex) -> np.ndarray:
    """``(1 - r z^-1)``, or ``(1 - r z^-1)(1 - conj(r) z^-1)`` for a complex ``r``."""
    if abs(root.imag) > 0:
        return np.array([1.0, -2.0 * root.real, abs(root) ** 2])
    return np.array([1.0, -root.real])


def _roots(p: np.ndarray) -> np.ndarray:
    """Roots of ``p`` (descending powers, as :func:`numpy.roots`), cheap at low degree.

    A fit calls this on every output's polynomials, so degrees 1 and 2 are solved in closed
    form (the quadratic without cancellation) instead of :func:`numpy.roots`' companion
    eigenvalues; higher degrees go to :func:`numpy.linalg.eigvals` of the companion matrix.
    Leading zeros are dropped; trailing zeros are roots at 0.
    """
    nz = np.flatnonzero(p)
    if nz.size == 0:
        return np.empty(0, dtype=complex)
    at_zero = p.size - 1 - int(nz[-1])
    p = p[int(nz[0]) : int(nz[-1]) + 1]
    deg = p.size - 1
    if deg == 0:
        found = np.empty(0, dtype=complex)
    elif deg == 1:
        found = np.array([complex(-p[1] / p[0])])
    elif deg == 2:
        b, c = p[1] / p[0], p[2] / p[0]
        disc = complex(b * b - 4.0 * c) ** 0.5
        big = -0.5 * (b + disc) if b >= 0 else -0.5 * (b - disc)  # no cancellation
        found = np.array([big, c / big if big else 0j])
    else:
        companion = np.diag(np.ones(deg - 1), -1)
        companion[0, :] = -p[1:] / p[0]
        found = np.linalg.eigvals(companion).astype(complex)
    return np.concatenate([found, np.zeros(at_zero, dtype=complex)])


def _pairs(den: np.ndarray, nums: list[np.ndarray], tol: float) -> list[complex]:
    """Poles of ``den`` within ``tol`` of a zero of every nonzero numerator (one per conj pair)."""
    poles = _roots(den)
    zero_sets = [_roots(b) for b in nums if np.any(b != 0)]
    if not zero_sets or any(z.size == 0 for z in zero_sets):
        return []
    found: list[complex] = []
    used = [np.zeros(z.size, dtype=bool) for z in zero_sets]
    for p in sorted(poles, key=lambda r: -abs(r)):  # outermost first: the spurious ones
        if p.imag < 0:
            continue  # handled with its conjugate
        hits = []
        for z, u in zip(zero_sets, used, strict=True):
            d = np.where(u, np.inf, np.abs(z - p))
            hits.append(int(np.argmin(d)) if d.min() < tol else -1)
        if min(hits) < 0:
            continue
        for h, u, z in zip(hits, used, zero_sets, strict=True):
            u[h] = True
            if p.imag > 0:  # the conjugate zero too
                u[int(np.argmin(np.where(u, np.inf, np.abs(z - np.conj(p)))))] = True
        found.append(complex(p))
    return found


def cancel_common_factors(
    den: np.ndarray, nums: np.ndarray, tol: float = CANCEL_DISTANCE
) -> tuple[np.ndarray, np.ndarray, int]:
    """Remove pole/zero pairs closer than ``tol`` from one equation's monic polynomials.

    Parameters
    ----------
    den : ndarray, shape (na + 1,)
        Monic ``A(z)``, ascending powers of ``z^-1``.
    nums : ndarray, shape (n_inputs, nk + nb + 1)
        Numerators with ``nk`` leading zeros (an all-zero row is an input the equation
        does not use).
    tol : float
        Largest pole-zero distance that counts as a common factor.

    Returns
    -------
    den, nums, removed
        The reduced polynomials (``na - removed + 1`` and ``nk + nb - removed + 1``
        coefficients) and the number of first-order factors removed.
    """
    roots = _pairs(np.asarray(den, float), [np.asarray(b, float) for b in nums], tol)
    den = np.asarray(den, float)
    nums = np.asarray(nums, float)
    removed = 0
    for r in roots:
        f = _factor(r)
        den = np.polydiv(den, f)[0].real
        nums = np.array(
            [np.polydiv(b, f)[0].real if np.any(b != 0) else b[: -f.size + 1] for b in nums]
        )
        removed += f.size - 1
    return den, nums, removed
