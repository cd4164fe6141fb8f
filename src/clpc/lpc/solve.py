"""The LPC solve, batched: from a scatter matrix to the parameter vector and its statistics.

Shared by the one-shot estimator (:mod:`clpc.lpc`) and the appraiser (:mod:`clpc.clpc`),
so a window in CLPC is solved exactly like a whole record in LPC. Every function works on a
stack of problems: leading axis ``k`` (windows or equations), parameter axis ``p``.

Paper (section III): with lag vectors ``z_n`` (rows of M, eq. 36), mean ``Z`` (eq. 25) and
scatter ``A = sum (z_n - Z)(z_n - Z)^T`` (eq. 27), the maximum-likelihood parameter vector
under ``||theta|| = 1`` is the eigenvector of the smallest eigenvalue of ``A``
(eqs. 28-32), ``c = Z^T theta`` (eq. 24) and ``sigma_r^2 = lambda_min / n``.

Two solutions are offered (see ``docs/method.md`` for the derivation):

``method="paper"``
    The literal eigenvector of the smallest eigenvalue of ``A`` (no scaling).
``method="robust"`` (default)
    Columns are first whitened by a noise covariance ``W`` (default: each channel scaled
    to unit standard deviation, which makes the estimate unit-free). In the whitened
    problem, relations that do not involve ``y(n)`` (input-only relations of a smooth input,
    shifted copies of the system relation when the order is too large) are recognised by
    the ``y(n)`` component of their eigenvector, and the parameter vector is the
    minimum-norm vector with ``a0 = 1`` in the near-null subspace (the nongeneric TLS
    solution of Van Huffel and Vandewalle).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["RobustRule", "SolveResult", "solve_scatter"]

_LOG_2PI = float(np.log(2.0 * np.pi))


@dataclass(frozen=True)
class RobustRule:
    """Thresholds of the excitation-aware (``method="robust"``) solution.

    Parameters
    ----------
    min_a0_weight : float
        An eigenvector of the whitened scatter matrix is a candidate system relation when
        its ``y(n)`` component ``|v[a0]|`` is at least this (0..1). Smaller eigenvectors
        below the first candidate are relations that do not determine ``y(n)``.
    degeneracy_ratio : float, optional
        Eigenvalues within this factor of the candidate's belong to the same near-null
        subspace (the noise cannot tell them apart); the solution is then the minimum-norm
        vector with ``a0 = 1`` in that subspace. Default: the ratio of the edges of the
        Marchenko-Pastur law, ``((1 + sqrt(p/n)) / (1 - sqrt(p/n)))^2`` (the spread of the
        eigenvalues of pure noise with ``n`` rows and ``p`` columns; 2.0 for ``p = 6, n = 200``
        and 1.03 for ``n = 1e5``), at most 4.
    zero_tol : float
        Eigenvalues below ``zero_tol * lambda_max`` are zero (rounding level): they are
        always in the near-null subspace, whatever their ratios.
    min_output_weight : float
        An eigenvector whose output block ``||v[y]||^2`` is below this is an input-only
        relation (the input is not persistently exciting).
    separation : float
        The solution is *determined* when the candidate eigenvalue is at most this fraction
        of the next eigenvalue outside the near-null subspace.
    """

    min_a0_weight: float = 0.1
    degeneracy_ratio: float | None = None
    zero_tol: float = 1e-12
    min_output_weight: float = 0.05
    separation: float = 0.1


@dataclass(frozen=True)
class SolveResult:
    """Batched LPC solution; every field has leading shape ``batch``.

    Attributes
    ----------
    theta : ndarray, shape (batch..., p)
        Unit-norm parameter vector ``[a; b]`` with ``a0 >= 0`` (paper convention).
    eigenvalues : ndarray, shape (batch..., p)
        Eigenvalues of the paper's scatter matrix ``A`` (eq. 27), ascending.
    solved_eigenvalues : ndarray, shape (batch..., p)
        Eigenvalues of the problem actually solved (whitened ``A``), ascending.
    c : ndarray, shape (batch...)
        Mean of the equation error, ``c = Z^T theta`` (eq. 24).
    noise_variance : ndarray, shape (batch...)
        Maximum-likelihood variance of ``r(n) = z_n^T theta``: ``theta^T A theta / n``.
    n_null : ndarray of int, shape (batch...)
        Dimension of the near-null subspace the solution was taken from (1 = generic).
    n_input_relations : ndarray of int, shape (batch...)
        Near-null relations that involve (almost) no output: the input alone satisfies
        them, so it is not persistently exciting of the model's order.
    separation : ndarray, shape (batch...)
        Solved eigenvalue of the solution over the next eigenvalue outside the near-null
        subspace (small: well determined; near 1: not determined by the data).
    degenerate : ndarray of bool, shape (batch...)
        The scatter matrix is (numerically) zero or has a constant channel: nothing to fit.
    a0_weight : ndarray, shape (batch...)
        ``|y(n)|`` component of the solution in the solved (whitened) problem, unit-free;
        near 0 the solution does not determine ``y(n)`` and has no monic form.
    """

    theta: np.ndarray
    eigenvalues: np.ndarray
    solved_eigenvalues: np.ndarray
    c: np.ndarray
    noise_variance: np.ndarray
    n_null: np.ndarray
    n_input_relations: np.ndarray
    separation: np.ndarray
    degenerate: np.ndarray
    a0_weight: np.ndarray


def channel_scales(scatter: np.ndarray, n_rows: np.ndarray, blocks: list[slice]) -> np.ndarray:
    """Per-column scale: the standard deviation of each channel, repeated over its lags.

    Parameters
    ----------
    scatter : ndarray, shape (k, p, p)
    n_rows : ndarray, shape (k,)
    blocks : list of slice
        Column blocks of one channel each (output block first).

    Returns
    -------
    ndarray, shape (k, p)
        Positive scales; a constant channel gets scale 1 (it is flagged degenerate).
    """
    diag = np.diagonal(scatter, axis1=-2, axis2=-1)
    scales = np.empty_like(diag)
    n = np.maximum(n_rows, 1)[:, None]
    for block in blocks:
        std = np.sqrt(np.maximum(diag[:, block].mean(axis=1, keepdims=True), 0.0) / n)
        scales[:, block] = std
    bad = ~(scales > 0)
    scales[bad] = 1.0
    return scales


def solve_scatter(
    scatter: np.ndarray,
    mean: np.ndarray,
    n_rows: np.ndarray,
    *,
    n_output_cols: int,
    blocks: list[slice],
    method: str = "robust",
    noise_cov: np.ndarray | None = None,
    rule: RobustRule | None = None,
    data: np.ndarray | None = None,
) -> SolveResult:
    """Solve a stack of LPC problems given their scatter matrices.

    Parameters
    ----------
    scatter : ndarray, shape (k, p, p)
        Centered scatter matrices ``A`` (eq. 27).
    mean : ndarray, shape (k, p)
        Mean lag vectors ``Z`` (eq. 25).
    n_rows : ndarray of int, shape (k,)
        Number of lag vectors behind each matrix.
    n_output_cols : int
        Number of output columns (``na + 1``); column 0 is ``y(n)``, i.e. ``a0``.
    blocks : list of slice
        Column blocks, one per channel (output first), for the default scaling.
    method : {"robust", "paper"}
        See the module docstring.
    noise_cov : ndarray, shape (p,) or (p, p), optional
        Covariance ``W`` of the noise on the lag vector (weighted LPC: the generalized
        eigenproblem ``A theta = lambda W theta``); 1-D means diagonal (variances).
        Default: ``method="paper"`` uses the identity, ``"robust"`` the channel variances.
    rule : RobustRule, optional
        Thresholds of the robust solution.
    data : ndarray, shape (k, n, p), optional
        Centered data matrices; when given (one-shot fits) the decomposition is the SVD of
        the data, which is more accurate than the eigen-decomposition of the scatter.

    Returns
    -------
    SolveResult
    """
    if method not in ("robust", "paper"):
        raise ValueError(f"method must be 'robust' or 'paper'; got {method!r}.")
    rule = rule or RobustRule()
    scatter = np.asarray(scatter, dtype=np.float64)
    k, p, _ = scatter.shape
    n_rows = np.asarray(n_rows)
    n_safe = np.maximum(n_rows, 1).astype(np.float64)

    transform = _whitening(scatter, n_rows, blocks, method, noise_cov)  # (k,p,p) or None
    vals, vecs = _decompose(scatter, transform, data)
    if transform is None:
        raw_vals = vals
    elif data is not None:
        raw_vals = np.linalg.svd(data, compute_uv=False)[:, ::-1] ** 2
    else:  # only the paper's eigenvalues (for D) are needed from the raw matrix
        raw_vals = np.linalg.eigvalsh(0.5 * (scatter + np.swapaxes(scatter, -1, -2)))

    # degenerate: nothing varies in the window, or a channel is constant
    diag = np.diagonal(scatter, axis1=-2, axis2=-1)
    # a channel is constant when its spread is at rounding level relative to its own size
    # (|mean| * 1e-12) or to the whole matrix; merged statistics of a constant channel are
    # ~1e-29, not 0
    channel_var = np.stack([diag[:, b].max(axis=1) for b in blocks], axis=1)
    channel_size = np.stack([np.abs(mean[:, b]).max(axis=1) for b in blocks], axis=1)
    per_row = channel_var / n_safe[:, None]
    top = np.maximum(raw_vals[:, -1], 0.0)
    degenerate = ~(top > 0) | np.any(
        (channel_var <= 1e-28 * np.maximum(top, 1e-300)[:, None])
        | (per_row <= (1e-12 * channel_size) ** 2),
        axis=1,
    )

    if method == "paper":
        phi = vecs[:, :, 0]
        n_null = np.ones(k, dtype=np.int64)
        n_input = np.sum(vecs[:, :n_output_cols, 0] ** 2, axis=1) < rule.min_output_weight
        n_input = n_input.astype(np.int64)
        nxt = vals[:, 1] if p > 1 else vals[:, 0]
        separation = _ratio(vals[:, 0], nxt)
    else:
        ratio = degeneracy_ratio(rule, n_rows, p)
        phi, n_null, n_input, separation = _robust_vector(vals, vecs, n_output_cols, rule, ratio)

    phi_norm = np.linalg.norm(phi, axis=1)
    a0_weight = np.abs(phi[:, 0]) / np.where(phi_norm > 0, phi_norm, 1.0)
    theta = phi if transform is None else np.einsum("kij,kj->ki", transform, phi)
    theta = _normalise(theta)
    theta[degenerate] = 0.0
    c = np.einsum("kp,kp->k", mean, theta)
    noise_variance = np.maximum(np.einsum("ki,kij,kj->k", theta, scatter, theta), 0.0) / n_safe
    return SolveResult(
        theta=theta,
        eigenvalues=np.maximum(raw_vals, 0.0),
        solved_eigenvalues=np.maximum(vals, 0.0),
        c=c,
        noise_variance=noise_variance,
        n_null=n_null,
        n_input_relations=n_input,
        separation=separation,
        degenerate=degenerate,
        a0_weight=np.where(degenerate, 0.0, a0_weight),
    )


def _ratio(num: np.ndarray, den: np.ndarray) -> np.ndarray:
    num = np.maximum(num, 0.0)
    den = np.maximum(den, 0.0)
    out = np.ones_like(num)
    ok = den > 0
    out[ok] = num[ok] / den[ok]
    return np.minimum(out, 1.0)


def _whitening(
    scatter: np.ndarray,
    n_rows: np.ndarray,
    blocks: list[slice],
    method: str,
    noise_cov: np.ndarray | None,
) -> np.ndarray | None:
    """Transform ``T`` with ``T^T W T = I``: the solved problem is ``T^T A T``."""
    k, p, _ = scatter.shape
    if noise_cov is None:
        if method == "paper":
            return None
        scales = channel_scales(scatter, n_rows, blocks)
        return np.einsum("kp,pq->kpq", 1.0 / scales, np.eye(p))
    return np.broadcast_to(fixed_transform(noise_cov, p), (k, p, p))


def fixed_transform(noise_cov: np.ndarray, p: int) -> np.ndarray:
    """Whitening ``T`` (shape (p, p)) with ``T^T W T = I`` for a known noise covariance ``W``.

    Parameters
    ----------
    noise_cov : array_like, shape (p,) or (p, p)
        Variances (diagonal ``W``) or the full covariance of the lag-vector noise.
    p : int
        Lag-vector length.
    """
    cov = np.asarray(noise_cov, dtype=np.float64)
    if cov.shape == (p,):
        if np.any(~np.isfinite(cov)) or np.any(cov <= 0):
            raise ValueError(
                "noise_cov must hold positive finite variances, one per lag-vector entry; "
                f"got {cov.tolist()}."
            )
        return np.diag(1.0 / np.sqrt(cov))
    if cov.shape != (p, p):
        raise ValueError(
            f"noise_cov must have shape ({p},) (variances) or ({p}, {p}) (covariance), one "
            f"entry per lag-vector element; got shape {cov.shape}."
        )
    if not np.all(np.isfinite(cov)) or not np.allclose(cov, cov.T):
        raise ValueError("noise_cov must be a finite symmetric matrix.")
    try:
        chol = np.linalg.cholesky(cov)
    except np.linalg.LinAlgError:
        raise ValueError("noise_cov must be positive definite.") from None
    # T = L^{-T}: then T^T W T = L^{-1} L L^T L^{-T} = I
    return np.linalg.inv(chol).T


def _decompose(
    scatter: np.ndarray, transform: np.ndarray | None, data: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray]:
    """Ascending eigenvalues and eigenvectors of ``T^T A T`` (SVD of ``M T`` when given)."""
    if data is not None:
        mat = data if transform is None else data @ transform
        _, s, vt = np.linalg.svd(mat, full_matrices=False)
        return s[:, ::-1] ** 2, np.swapaxes(vt, -1, -2)[:, :, ::-1]
    mat = scatter if transform is None else np.swapaxes(transform, -1, -2) @ scatter @ transform
    mat = 0.5 * (mat + np.swapaxes(mat, -1, -2))
    return np.linalg.eigh(mat)


def degeneracy_ratio(rule: RobustRule, n_rows: np.ndarray, p: int) -> np.ndarray:
    """Eigenvalue ratio within which directions are indistinguishable (see RobustRule)."""
    if rule.degeneracy_ratio is not None:
        return np.full(np.shape(n_rows), float(rule.degeneracy_ratio))
    x = np.sqrt(p / np.maximum(np.asarray(n_rows, dtype=float), 1.0))
    with np.errstate(divide="ignore"):
        mp = np.where(x < 1, ((1 + x) / np.maximum(1 - x, 1e-12)) ** 2, np.inf)
    return np.minimum(mp, 4.0)


def _robust_vector(
    vals: np.ndarray, vecs: np.ndarray, n_output_cols: int, rule: RobustRule, ratio: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Minimum-norm ``a0 = 1`` vector in the near-null subspace, vectorised over windows."""
    k, p = vals.shape
    idx = np.arange(p)
    a0 = vecs[:, 0, :]  # (k, p): y(n) component of each eigenvector
    out_w = np.sum(vecs[:, :n_output_cols, :] ** 2, axis=1)  # (k, p)
    cand = np.abs(a0) >= rule.min_a0_weight
    # first candidate; if none qualifies, the eigenvector with the largest y(n) component
    first = np.where(cand.any(axis=1), np.argmax(cand, axis=1), np.argmax(np.abs(a0), axis=1))
    floor = rule.zero_tol * np.maximum(vals[:, -1], 0.0)
    lam_s = np.maximum(vals[np.arange(k), first], floor)
    within = (np.maximum(vals, 0.0) <= ratio[:, None] * lam_s[:, None]) | (
        idx[None, :] <= first[:, None]
    )
    # the near-null subspace is a leading block of the ascending spectrum
    last = np.where(within.all(axis=1), p - 1, np.argmin(within, axis=1) - 1)
    member = idx[None, :] <= last[:, None]
    # projection of e_a0 onto span(v_0..v_last): sum_i v_i v_i[a0]
    phi = np.einsum("kpi,ki->kp", vecs, np.where(member, a0, 0.0))
    n_null = (last + 1).astype(np.int64)
    n_input = np.sum(member & (out_w < rule.min_output_weight), axis=1).astype(np.int64)
    nxt = np.where(last + 1 < p, vals[np.arange(k), np.minimum(last + 1, p - 1)], np.inf)
    separation = np.where(
        np.isfinite(nxt), _ratio(lam_s, np.where(np.isfinite(nxt), nxt, 1.0)), 1.0
    )
    return phi, n_null, n_input, separation


def _normalise(theta: np.ndarray) -> np.ndarray:
    """Unit norm and a deterministic sign: ``a0 > 0`` (else the first nonzero entry > 0)."""
    norm = np.linalg.norm(theta, axis=-1, keepdims=True)
    theta = np.divide(theta, norm, out=np.zeros_like(theta), where=norm > 0)
    nz = np.abs(theta) > 1e-14
    first = np.argmax(nz, axis=-1)
    pivot = np.take_along_axis(theta, first[:, None], axis=-1)[:, 0]
    sign = np.where(pivot < 0, -1.0, 1.0)
    return theta * sign[:, None]


#: A residual variance below this many machine epsilons of the largest per-row variance
#: (``lambda_max / n``) is rounding, not noise: the likelihood uses the floor instead, so
#: that noise-free records never compare orders on rounding error (2.2e-13 relative
#: variance, a residual about 126 dB below the signal).
ROUNDING_VARIANCE_FACTOR = 1e3


def likelihood_variance(
    noise_variance: np.ndarray, lambda_max: np.ndarray, n_rows: np.ndarray
) -> np.ndarray:
    """``sigma_r^2`` floored at the rounding level of the window's own scale."""
    n_safe = np.maximum(n_rows, 1)
    floor = ROUNDING_VARIANCE_FACTOR * np.finfo(float).eps * np.maximum(lambda_max, 0.0) / n_safe
    return np.maximum(np.maximum(noise_variance, floor), np.finfo(float).tiny)


def log_likelihood(noise_variance: np.ndarray, n_rows: np.ndarray) -> np.ndarray:
    """Gaussian log-likelihood of ``r(n)`` at its maximum (correct constants).

    ``log L = -n/2 (log(2 pi sigma^2) + 1)``; the paper's eq. 21 writes ``-log(2 pi)``
    per sample where the density gives ``-1/2 log(2 pi)``. Pass the variance through
    :func:`likelihood_variance` first.
    """
    var = np.maximum(noise_variance, np.finfo(float).tiny)
    return -0.5 * n_rows * (_LOG_2PI + np.log(var) + 1.0)


def index_j(noise_variance: np.ndarray, n_rows: np.ndarray) -> np.ndarray:
    """The paper's index ``J`` (eq. 22) at the solution: ``n/2 log sigma^2 + n/2``."""
    var = np.maximum(noise_variance, np.finfo(float).tiny)
    return 0.5 * n_rows * (np.log(var) + 1.0)
