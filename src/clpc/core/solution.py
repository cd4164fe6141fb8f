"""The LPC solution of one equation: the solved problem, its near-null subspace, the vector.

Plain Python in numba's subset, written once: the batch estimator calls these functions
after its numpy SVD (as plain Python), the CLPC kernel compiles them (each is registered
with ``numba.extending.register_jitable``). Thresholds and
settings are in :mod:`clpc.core.rules`.

Paper (section III): with lag vectors ``z_n`` (eq. 36), mean ``Z`` (eq. 25) and scatter
``A = sum (z_n - Z)(z_n - Z)^T`` (eq. 27), the maximum-likelihood ``theta`` under
``||theta|| = 1`` is the eigenvector of the smallest eigenvalue of ``A`` (eqs. 28-32),
``c = Z^T theta`` (eq. 24) and ``sigma_r^2 = theta^T A theta / n``. The problem actually
solved is ``T^T A T`` (:func:`clpc.core.rules.transform_mode`).
"""

from __future__ import annotations

import math

import numpy as np
from numba.extending import register_jitable

from clpc.core.rules import (
    CHANNEL_SCALES,
    CONSTANT_CHANNEL_FRACTION,
    CONSTANT_CHANNEL_RELATIVE_STD,
    FIXED_TRANSFORM,
    MAX_DEGENERACY_RATIO,
    NO_TRANSFORM,
    SIGN_PIVOT_TOL,
    SolveSettings,
    is_input_relation,
)

__all__ = [
    "channel_scales",
    "degeneracy_ratio",
    "is_degenerate",
    "pick_paper",
    "pick_robust",
    "solve_from_eig",
    "solved_matrix",
    "unit_free_weights",
]


# ------------------------------------------------------------------ the solved problem
@register_jitable(error_model="numpy")
def channel_scales(
    scat: np.ndarray, n_rows: float, col_channel: np.ndarray, n_channels: int, scales: np.ndarray
) -> None:
    """Per-column scale: the standard deviation of each channel (mean over its lags).

    A constant channel gets scale 1 (it is flagged degenerate by :func:`is_degenerate`).
    """
    p = scat.shape[0]
    n_safe = max(n_rows, 1.0)
    for ch in range(n_channels):
        acc = 0.0
        cnt = 0
        for a in range(p):
            if col_channel[a] == ch:
                acc += scat[a, a]
                cnt += 1
        std = math.sqrt(max(acc / max(cnt, 1), 0.0) / n_safe)
        for a in range(p):
            if col_channel[a] == ch:
                scales[a] = std if std > 0 else 1.0


@register_jitable(error_model="numpy")
def solved_matrix(
    scat: np.ndarray,
    mode: int,
    fixed: np.ndarray,
    scales: np.ndarray,
    tmat: np.ndarray,
    mat: np.ndarray,
) -> None:
    """Fill ``tmat`` with ``T`` and ``mat`` with the symmetric ``T^T A T``."""
    p = scat.shape[0]
    for a in range(p):
        for b in range(p):
            if mode == FIXED_TRANSFORM:
                tmat[a, b] = fixed[a, b]
            elif mode == CHANNEL_SCALES:
                tmat[a, b] = 1.0 / scales[a] if a == b else 0.0
            else:
                tmat[a, b] = 1.0 if a == b else 0.0
    if mode == CHANNEL_SCALES:
        for a in range(p):
            for b in range(p):
                mat[a, b] = scat[a, b] / (scales[a] * scales[b])
    elif mode == FIXED_TRANSFORM:
        for a in range(p):
            for b in range(p):
                acc = 0.0
                for k in range(p):
                    for m in range(p):
                        acc += tmat[k, a] * scat[k, m] * tmat[m, b]
                mat[a, b] = acc
        for a in range(p):
            for b in range(a):
                sym = 0.5 * (mat[a, b] + mat[b, a])
                mat[a, b] = sym
                mat[b, a] = sym
    else:
        for a in range(p):
            for b in range(p):
                mat[a, b] = scat[a, b]


@register_jitable(error_model="numpy")
def is_degenerate(
    scat: np.ndarray,
    mean: np.ndarray,
    n_rows: float,
    top: float,
    col_channel: np.ndarray,
    n_channels: int,
) -> bool:
    """Nothing varies (``lambda_max <= 0``) or a channel is constant."""
    if not top > 0:
        return True
    p = scat.shape[0]
    n_safe = max(n_rows, 1.0)
    for ch in range(n_channels):
        var = -1.0
        size = 0.0
        for a in range(p):
            if col_channel[a] == ch:
                var = max(var, scat[a, a])
                size = max(size, abs(mean[a]))
        if var <= CONSTANT_CHANNEL_FRACTION * max(top, 1e-300):
            return True
        if var / n_safe <= (CONSTANT_CHANNEL_RELATIVE_STD * size) ** 2:
            return True
    return False


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


# ------------------------------------------------------------------ picking the vector
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


@register_jitable(error_model="numpy")
def normalise(theta: np.ndarray) -> None:
    """Unit norm and a deterministic sign: ``a0 > 0`` (else the first nonzero entry > 0)."""
    p = theta.shape[0]
    norm = 0.0
    for a in range(p):
        norm += theta[a] * theta[a]
    norm = math.sqrt(norm)
    for a in range(p):
        theta[a] = theta[a] / norm if norm > 0 else 0.0
    sign = 1.0
    for a in range(p):
        if abs(theta[a]) > SIGN_PIVOT_TOL:
            sign = -1.0 if theta[a] < 0 else 1.0
            break
    for a in range(p):
        theta[a] = sign * theta[a]


@register_jitable(error_model="numpy")
def solve_from_eig(
    scat: np.ndarray,
    mean: np.ndarray,
    n_rows: float,
    eig: tuple[np.ndarray, np.ndarray, np.ndarray],
    transform: tuple[np.ndarray, np.ndarray],
    s: SolveSettings,
    col_channel: np.ndarray,
    out: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> tuple[float, float, float, float, int, int, bool]:
    """The LPC solution of one equation from the eigen-decomposition of its solved problem.

    Parameters
    ----------
    scat, mean : ndarray, shape (p, p), (p,)
        The paper's scatter ``A`` (eq. 27) and mean ``Z`` (eq. 25).
    n_rows : float
        Lag vectors behind them.
    eig : (vals, vecs, raw)
        Ascending eigenvalues (p,) and eigenvectors (columns, (p, p)) of ``T^T A T``, and
        the ascending eigenvalues of ``A`` itself (the paper's, for ``D``).
    transform : (tmat, scales)
        ``T`` (p, p), and the channels' standard deviations per column (p,) that make the
        weights of :func:`unit_free_weights` unit-free.
    s : SolveSettings
    col_channel : ndarray of int, shape (p,)
        Channel block of each column (0 = output).
    out : (phi, theta, eigenvalues)
        Work vector (p,), and outputs: unit-norm ``theta`` with ``a0 >= 0`` (zero when
        degenerate) and the clipped eigenvalues of ``A``.

    Returns
    -------
    tuple
        ``(c, noise_variance, separation, a0_weight, n_null, n_input, degenerate)``;
        ``n_input`` is at least 1 when the solution itself is an input relation
        (:func:`clpc.core.rules.is_input_relation`), so it is never determined.
    """
    vals, vecs, raw = eig
    tmat, scales = transform
    phi, theta, eigenvalues = out
    p = scat.shape[0]
    degenerate = is_degenerate(scat, mean, n_rows, max(raw[p - 1], 0.0), col_channel, s.n_channels)
    tr = (tmat, scales, s.transform_mode == NO_TRANSFORM)
    if s.robust:
        n_null, n_input, separation = pick_robust((vals, vecs), tr, s, n_rows, phi)
    else:
        n_null, n_input, separation = pick_paper((vals, vecs), tr, s, phi)
    a0_weight = 0.0 if degenerate else unit_free_weights(phi, tr, s.n_out_cols)[0]
    if not degenerate and is_input_relation(a0_weight, s.min_a0_weight):
        n_input = max(n_input, 1)  # the solution itself is an input relation
    for a in range(p):  # theta = T phi
        if tr[2]:
            theta[a] = phi[a]
            continue
        acc = 0.0
        for b in range(p):
            acc += tmat[a, b] * phi[b]
        theta[a] = acc
    normalise(theta)
    c = 0.0
    quad = 0.0
    for a in range(p):
        if degenerate:
            theta[a] = 0.0
        eigenvalues[a] = max(raw[a], 0.0)
    for a in range(p):
        c += mean[a] * theta[a]  # eq. 24
        acc = 0.0
        for b in range(p):
            acc += scat[a, b] * theta[b]
        quad += theta[a] * acc
    noise_variance = max(quad, 0.0) / max(n_rows, 1.0)
    return c, noise_variance, separation, a0_weight, n_null, n_input, degenerate
