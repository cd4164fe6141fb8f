"""The near-null subspace of the solved problem and the vector picked from it.

Plain Python in numba's subset (each function registered with
``numba.extending.register_jitable``), called by :func:`clpc.core.solution.solve_from_eig`
in the batch estimator and compiled into the CLPC kernel.

The eigenvectors of the solved problem ``T^T A T`` are judged by their unit-free weights
(:func:`unit_free_weights`); the paper takes the last principal component
(:func:`pick_paper`), the robust method the minimum-norm ``a0 = 1`` vector of the subspace
whose eigenvalues the noise cannot tell apart (:func:`pick_robust`, with the Marchenko-Pastur
:func:`degeneracy_ratio`).
"""

from __future__ import annotations

import math

import numpy as np
from numba.extending import register_jitable

from clpc.core.rules import SolveSettings

__all__ = [
    "MAX_DEGENERACY_RATIO",
    "degeneracy_ratio",
    "pick_paper",
    "pick_robust",
    "ratio",
    "unit_free_weights",
]

#: Largest eigenvalue ratio of one near-null subspace (cap of the Marchenko-Pastur ratio).
MAX_DEGENERACY_RATIO = 4.0


@register_jitable(error_model="numpy")
def degeneracy_ratio(fixed: float, p: int, n_rows: float) -> float:
    """``fixed`` if > 0, else the Marchenko-Pastur edge ratio for ``p`` columns, ``n`` rows."""
    if fixed > 0:
        return fixed
    x = math.sqrt(p / max(n_rows, 1.0))
    if not x < 1:
        return MAX_DEGENERACY_RATIO
    return min(((1 + x) / max(1 - x, 1e-12)) ** 2, MAX_DEGENERACY_RATIO)


@register_jitable(error_model="numpy")
def ratio(num: float, den: float) -> float:
    """``num / den`` clipped to [0, 1]; 1 when ``den`` is not positive."""
    num = max(num, 0.0)
    den = max(den, 0.0)
    if not den > 0:
        return 1.0
    return min(num / den, 1.0)


@register_jitable(error_model="numpy")
def unit_free_weights(
    vec: np.ndarray,
    transform: tuple[np.ndarray, np.ndarray, bool],
    n_out_cols: int,
) -> tuple[float, float]:
    """The ``y(n)`` weight and the output-block weight of ``theta = T v``, free of units.

    ``transform = (T, s, identity)``: with ``s`` the channels' standard deviations (per
    column), ``w = diag(s) T v`` is the relation in units of each channel's own spread:
    ``|w_0| / ||w||`` (the ``y(n)`` weight) and ``||w_y||^2 / ||w||^2`` (the output block's
    share) do not change when a channel is rescaled. An input-only relation has ``y(n)``
    weight 0 in any units. ``identity`` skips the product when ``T = I``.
    """
    tmat, scales, identity = transform
    p = vec.shape[0]
    total = 0.0
    out = 0.0
    first = 0.0
    for a in range(p):
        if identity:
            acc = vec[a]
        else:
            acc = 0.0
            for b in range(p):
                acc += tmat[a, b] * vec[b]
        w = scales[a] * acc
        total += w * w
        if a < n_out_cols:
            out += w * w
        if a == 0:
            first = abs(w)
    if not total > 0:
        return 0.0, 0.0
    return first / math.sqrt(total), out / total


@register_jitable(error_model="numpy")
def pick_paper(
    eig: tuple[np.ndarray, np.ndarray],
    transform: tuple[np.ndarray, np.ndarray, bool],
    s: SolveSettings,
    phi: np.ndarray,
) -> tuple[int, int, float]:
    """The literal last principal component; returns ``(n_null, n_input, separation)``."""
    vals, vecs = eig
    p = vals.shape[0]
    for a in range(p):
        phi[a] = vecs[a, 0]
    out_weight = unit_free_weights(vecs[:, 0], transform, s.n_out_cols)[1]
    n_input = 1 if out_weight < s.min_output_weight else 0
    return 1, n_input, ratio(vals[0], vals[1] if p > 1 else vals[0])


@register_jitable(error_model="numpy")
def pick_robust(
    eig: tuple[np.ndarray, np.ndarray],
    transform: tuple[np.ndarray, np.ndarray, bool],
    s: SolveSettings,
    n_rows: float,
    phi: np.ndarray,
) -> tuple[int, int, float]:
    """Minimum-norm ``a0 = 1`` vector in the near-null subspace of the solved problem.

    The eigenvectors' weights are unit-free (:func:`unit_free_weights` with ``transform``)
    and computed only as far as they are needed. The first eigenvector (ascending) whose
    ``y(n)`` weight is at least ``min_a0_weight`` is the candidate (none: the one with the
    largest); the
    near-null subspace runs from the smallest eigenvalue through every eigenvalue within
    the degeneracy ratio of the candidate's; ``phi`` is the projection of ``e_a0`` onto it.
    Returns ``(n_null, n_input, separation)``.
    """
    vals, vecs = eig
    p = vals.shape[0]
    lim = degeneracy_ratio(s.degeneracy_ratio, p, n_rows)
    first = -1
    best = -1.0
    best_i = 0
    for i in range(p):
        weight = unit_free_weights(vecs[:, i], transform, s.n_out_cols)[0]
        if weight >= s.min_a0_weight:
            first = i
            break
        if weight > best:
            best = weight
            best_i = i
    if first < 0:
        first = best_i
    lam_s = max(vals[first], s.zero_tol * max(vals[p - 1], 0.0))
    last = p - 1
    for i in range(first + 1, p):
        if not max(vals[i], 0.0) <= lim * lam_s:
            last = i - 1
            break
    for a in range(p):
        phi[a] = 0.0
    n_input = 0
    for i in range(last + 1):
        w = vecs[0, i]
        for a in range(p):
            phi[a] += vecs[a, i] * w
        if unit_free_weights(vecs[:, i], transform, s.n_out_cols)[1] < s.min_output_weight:
            n_input += 1
    separation = 1.0 if last + 1 >= p else ratio(lam_s, vals[last + 1])
    return last + 1, n_input, separation
