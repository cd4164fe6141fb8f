"""The LPC solution of one equation: the solved problem, its degeneracy, the vector.

Plain Python in numba's subset, written once: the batch estimator calls these functions
after its numpy SVD (as plain Python), the CLPC kernel compiles them (each is registered
with ``numba.extending.register_jitable``). The pick of the vector from the near-null
subspace is in :mod:`clpc.core.near_null`; settings are in :mod:`clpc.core.rules`.

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

from clpc.core.near_null import pick_paper, pick_robust, unit_free_weights
from clpc.core.rules import (
    CHANNEL_SCALES,
    FIXED_TRANSFORM,
    NO_TRANSFORM,
    SolveSettings,
    is_input_relation,
)

__all__ = [
    "CONSTANT_CHANNEL_FRACTION",
    "CONSTANT_CHANNEL_RELATIVE_STD",
    "SIGN_PIVOT_TOL",
    "channel_scales",
    "is_degenerate",
    "normalise",
    "solve_from_eig",
    "solved_matrix",
]

#: A channel is constant when its largest lag variance (summed over the window) is at
#: most this fraction of ``lambda_max``: merged statistics of a constant channel are about
#: 1e-29 of the signal, not exactly 0.
CONSTANT_CHANNEL_FRACTION = 1e-28
#: ... or when its per-row standard deviation is at most this fraction of its own size
#: ``max |mean|`` (a constant offset of 1e4 with rounding noise).
CONSTANT_CHANNEL_RELATIVE_STD = 1e-12
#: Entries of a unit vector below this are zero when the sign convention picks its pivot.
SIGN_PIVOT_TOL = 1e-14


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
