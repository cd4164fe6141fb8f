"""The batch LPC solve: numpy decompositions, then the rules of :mod:`clpc.core.rules`.

Shared by the estimator (:class:`clpc.LPC`) and order/noise selection. Every function works
on a stack of problems (leading axis ``k``: equations), parameter axis ``p``. The
decomposition is numpy's (the SVD of the centered data when it is given: more accurate
than the scatter's eigen-decomposition); everything decided from it - which vector, the
near-null subspace, the flags, normalisation and sign, ``c`` and the noise variance - is
the one source the CLPC kernel compiles, called here as plain Python (nothing compiles).

Paper (section III): with lag vectors ``z_n`` (rows of M, eq. 36), mean ``Z`` (eq. 25) and
scatter ``A = sum (z_n - Z)(z_n - Z)^T`` (eq. 27), the maximum-likelihood parameter vector
under ``||theta|| = 1`` is the eigenvector of the smallest eigenvalue of ``A``
(eqs. 28-32), ``c = Z^T theta`` (eq. 24) and ``sigma_r^2 = theta^T A theta / n``.

``method="paper"``
    The literal eigenvector of the smallest eigenvalue of the solved problem (``A`` itself
    with the default ``scaling="none"``).
``method="robust"`` (default)
    See :func:`clpc.core.near_null.pick_robust` and ``docs/method.md``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.core import rules, solution
from clpc.core.checks import check_positive
from clpc.core.rules import (
    NO_TRANSFORM,
    RobustRule,
    solve_settings,
)

__all__ = ["RobustRule", "SolveResult", "noise_covariance", "solve_scatter"]


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
        The solution's unit-free ``y(n)`` weight (:func:`clpc.core.near_null.unit_free_weights`);
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


def noise_covariance(
    noise_cov: Any, noise_ratio: Any, structure: Any, n_blocks: int
) -> np.ndarray | None:
    """The lag vector's noise covariance from the user's ``noise_cov`` or ``noise_ratio``.

    ``noise_ratio`` (input over output noise variance) gives the diagonal covariance
    ``diag(1, ..., 1, r, ..., r)``: 1 on the ``na + 1`` output lags, ``r`` on the input lags
    of ``n_blocks`` input blocks. ``None`` when neither is given.
    """
    if noise_cov is not None:
        return np.asarray(noise_cov, dtype=np.float64)
    if noise_ratio is None:
        return None
    ratio = check_positive(noise_ratio, "noise_ratio (input/output noise variance)")
    return np.concatenate(
        [np.ones(structure.na + 1), np.full(n_blocks * (structure.nb + 1), ratio)]
    )


def _column_channels(blocks: list[slice], p: int) -> np.ndarray:
    col_channel = np.zeros(p, dtype=np.int64)
    for ch, block in enumerate(blocks):
        col_channel[block] = ch
    return col_channel


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
    scaling: str = "none",
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
        Default: ``scaling`` decides (``"none"``: the identity; ``"std"``: the channels'
        variances).
    rule : RobustRule, optional
        Thresholds of the robust solution.
    data : ndarray, shape (k, n, p), optional
        Centered data matrices, or their ``R`` factors (shape (k, p, p),
        :func:`clpc.lpc.scatter.r_factor`: the same singular values and right vectors);
        when given (one-shot fits) the decomposition is the SVD of the data, which is more
        accurate than the eigen-decomposition of the scatter.
    scaling : {"none", "std"}
        The solved problem without a noise covariance (:func:`clpc.core.rules.transform_mode`).

    Returns
    -------
    SolveResult
    """
    if method not in ("robust", "paper"):
        raise ValueError(f"method must be 'robust' or 'paper'; got {method!r}.")
    rule_ = rule or RobustRule()
    scatter = np.ascontiguousarray(scatter, dtype=np.float64)
    mean = np.ascontiguousarray(mean, dtype=np.float64)
    k, p, _ = scatter.shape
    n_rows_f = np.asarray(n_rows, dtype=np.float64) * np.ones(k)
    mode = rules.transform_mode(scaling, noise_cov is not None)
    fixed = np.eye(p) if noise_cov is None else fixed_transform(noise_cov, p)
    settings = solve_settings(rule_, method == "robust", mode, n_output_cols, len(blocks))
    col_channel = _column_channels(blocks, p)
    out = {
        "theta": np.zeros((k, p)),
        "eigenvalues": np.zeros((k, p)),
        "solved": np.zeros((k, p)),
        "stats": np.zeros((k, 4)),
        "counts": np.zeros((k, 2), dtype=np.int64),
        "degenerate": np.zeros(k, dtype=bool),
    }
    for i in range(k):
        scales, tmat, mat = np.ones(p), np.empty((p, p)), np.empty((p, p))
        solution.channel_scales(scatter[i], n_rows_f[i], col_channel, len(blocks), scales)
        solution.solved_matrix(scatter[i], mode, fixed, scales, tmat, mat)
        rows = None if data is None or data.shape[1] < p else data[i]  # SVD needs n >= p
        vals, vecs, raw = _decompose(mat, tmat, scatter[i], rows, mode == NO_TRANSFORM)
        res = solution.solve_from_eig(
            scatter[i],
            mean[i],
            n_rows_f[i],
            (vals, vecs, raw),
            (tmat, scales),
            settings,
            col_channel,
            (np.empty(p), out["theta"][i], out["eigenvalues"][i]),
        )
        out["solved"][i] = np.maximum(vals, 0.0)
        out["stats"][i] = res[:4]
        out["counts"][i] = res[4:6]
        out["degenerate"][i] = res[6]
    c, noise_variance, separation, a0_weight = out["stats"].T
    return SolveResult(
        theta=out["theta"],
        eigenvalues=out["eigenvalues"],
        solved_eigenvalues=out["solved"],
        c=c.copy(),
        noise_variance=noise_variance.copy(),
        n_null=out["counts"][:, 0].copy(),
        n_input_relations=out["counts"][:, 1].copy(),
        separation=separation.copy(),
        degenerate=out["degenerate"],
        a0_weight=a0_weight.copy(),
    )


def _decompose(
    mat: np.ndarray,
    tmat: np.ndarray,
    scatter: np.ndarray,
    data: np.ndarray | None,
    identity: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Ascending eigenpairs of ``T^T A T`` and the eigenvalues of ``A`` (numpy/LAPACK).

    With the centered data ``M``: the SVD of ``M T`` (and of ``M`` for ``A``'s);
    ``identity``: ``T = I``, one decomposition serves both.
    """
    if data is not None:
        _, s, vt = np.linalg.svd(data if identity else data @ tmat, full_matrices=False)
        vals, vecs = s[::-1] ** 2, np.ascontiguousarray(vt[::-1].T)
        raw = vals if identity else np.linalg.svd(data, compute_uv=False)[::-1] ** 2
        return vals, vecs, raw
    vals, vecs = np.linalg.eigh(0.5 * (mat + mat.T))
    raw = vals if identity else np.linalg.eigvalsh(0.5 * (scatter + scatter.T))
    return vals, np.ascontiguousarray(vecs), raw


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
