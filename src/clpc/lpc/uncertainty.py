"""Parameter covariances of fitted models (what :mod:`clpc.model.uncertainty` reads).

Every covariance is of the monic parameters of one output equation, the row
``np.r_[den[1:], numerators.ravel()]`` of :func:`clpc.model.uncertainty.parameter_vector`
(``q`` entries), and is stored with :func:`with_covariance`.

* **LPC** (:func:`lpc_jackknife`): a delete-one-block jackknife over ``G`` contiguous
  segments of the record. Replicate ``g`` is the LPC solve of the full scatter minus segment
  ``g``'s scatter (with the mean corrected), so it costs one ``p x p`` solve, not a refit;
  ``C = (G-1)/G sum_g (m_g - m_bar)(m_g - m_bar)^T`` with ``G - 1`` degrees of freedom.
  Contiguous segments keep the serial correlation of the lag vectors inside a segment.
* **Least squares** (:func:`least_squares_covariance`): ``s^2 (Phi^T Phi)^-1`` of the
  centered regressors, ``s^2 = RSS / (n - p)`` (the intercept counted in ``p``).
* **A Jacobian** (:func:`covariance_from_jacobian`): ``s^2 (J^T J)^-1`` for a nonlinear
  least-squares fit (e.g. an output-error model from ``scipy.optimize.least_squares``:
  pass ``result.jac`` and ``result.fun``), mapped to the monic vector by
  :func:`monic_map` when the fitted parameters are ordered differently.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from clpc.model import LinearModel, Structure

__all__ = [
    "JACKKNIFE_BLOCKS",
    "MIN_BLOCK_ROWS_PER_PARAMETER",
    "covariance_entries",
    "covariance_from_jacobian",
    "least_squares_covariance",
    "lpc_jackknife",
    "monic_map",
    "with_covariance",
]

#: Segments of the LPC jackknife.
JACKKNIFE_BLOCKS = 20
#: A segment holds at least this many lag vectors per parameter; shorter records get fewer
#: segments, and below :data:`MIN_BLOCKS` none (no covariance).
MIN_BLOCK_ROWS_PER_PARAMETER = 5
#: Fewest segments a jackknife variance is computed from.
MIN_BLOCKS = 8


def monic_map(structure: Structure, n_inputs: int, mode: str, output: int = 0) -> np.ndarray:
    """Linear map from ``x`` (``theta = [1, x]``, paper convention) to the monic vector.

    Returns
    -------
    ndarray, shape (q, p - 1)
        ``m = L @ x``: ``den[1:] = x[:na]``; the ``b`` block of input ``i`` goes, negated,
        to ``num[i, nk:]`` (paired: only input ``output``). Use ``L @ C @ L.T`` to carry a
        covariance of ``x`` over.
    """
    na, nb, nk = structure.na, structure.nb, structure.nk
    width = nk + nb + 1
    blocks = [output] if mode == "paired" else list(range(n_inputs))
    out = np.zeros((na + n_inputs * width, na + len(blocks) * (nb + 1)))
    out[np.arange(na), np.arange(na)] = 1.0
    for blk, i in enumerate(blocks):
        rows = na + i * width + nk + np.arange(nb + 1)
        out[rows, na + blk * (nb + 1) + np.arange(nb + 1)] = -1.0
    return out


def covariance_entries(cov: np.ndarray, dof: Any, method: str) -> dict[str, Any]:
    """The ``info`` entries of a covariance: ``covariance``, ``covariance_dof``, ``_method``.

    Parameters
    ----------
    cov : ndarray, shape (n_outputs, q, q)
        Covariance of ``np.r_[den[1:], num]`` per output (symmetrised here).
    dof : float or ndarray, shape (n_outputs,)
        Degrees of freedom of the variance estimate.
    method : str
        How the covariance was obtained (shown by :meth:`LinearModel.summary`).
    """
    cov = np.asarray(cov, dtype=np.float64)
    if cov.ndim != 3 or cov.shape[1] != cov.shape[2]:
        raise ValueError(f"cov must have shape (n_outputs, q, q); got {cov.shape}.")
    return {
        "covariance": 0.5 * (cov + np.swapaxes(cov, 1, 2)),
        "covariance_dof": np.broadcast_to(np.asarray(dof, float), cov.shape[:1]).copy(),
        "covariance_method": method,
    }


def with_covariance(model: LinearModel, cov: np.ndarray, dof: Any, method: str) -> LinearModel:
    """``model`` with the entries of :func:`covariance_entries` in its ``info``."""
    q = model.n_inputs * (model.structure.nk + model.structure.nb + 1) + model.structure.na
    cov = np.asarray(cov, dtype=np.float64).reshape(model.n_outputs, q, q)
    info = {k: v for k, v in model.info.items() if k != "covariance_note"}
    info.update(covariance_entries(cov, dof, method))
    return replace(model, info=info)


def without_covariance(model: LinearModel, why: str) -> LinearModel:
    """``model`` with ``info["covariance_note"]`` saying why it has no covariance."""
    info = {k: v for k, v in model.info.items() if not k.startswith("covariance")}
    info["covariance_note"] = why
    return replace(model, info=info)


def covariance_from_jacobian(
    jacobian: np.ndarray, residuals: np.ndarray, n_extra: int = 0
) -> tuple[np.ndarray, int]:
    """``s^2 (J^T J)^-1`` with ``s^2 = ||r||^2 / (N - P - n_extra)``.

    Parameters
    ----------
    jacobian : ndarray, shape (N, P)
        Derivatives of the residuals with respect to the fitted parameters at the optimum.
    residuals : ndarray, shape (N,)
        Residuals at the optimum.
    n_extra : int
        Further fitted quantities not in ``J`` (e.g. an offset), for the degrees of freedom.

    Returns
    -------
    cov : ndarray, shape (P, P)
    dof : int
        ``N - P - n_extra``.

    Raises
    ------
    ValueError
        Fewer residuals than parameters, or a rank-deficient Jacobian (the data do not
        determine the parameters: no finite covariance exists).
    """
    jac = np.asarray(jacobian, dtype=np.float64)
    res = np.asarray(residuals, dtype=np.float64).ravel()
    n, p = jac.shape
    dof = n - p - int(n_extra)
    if res.size != n or dof < 1:
        raise ValueError(
            f"covariance_from_jacobian needs one residual per Jacobian row and more rows "
            f"than parameters; got J {jac.shape}, {res.size} residuals, {n_extra} extra."
        )
    _, s, vt = np.linalg.svd(jac, full_matrices=False)
    if s[-1] <= s[0] * np.finfo(float).eps * max(n, p):  # numerical rank (numpy's tolerance)
        raise ValueError(
            "the Jacobian is rank deficient (singular values "
            f"{s[0]:.3g} .. {s[-1]:.3g}): the data do not determine every parameter, so "
            "there is no finite covariance; lower the order or excite the system more."
        )
    s2 = float(res @ res) / dof
    return s2 * (vt.T / s**2) @ vt, dof


def least_squares_covariance(
    regressors: np.ndarray, residuals: np.ndarray
) -> tuple[np.ndarray, int]:
    """``s^2 (Phi^T Phi)^-1`` of a least-squares fit with an intercept.

    Parameters
    ----------
    regressors : ndarray, shape (n, P)
        Centered regressors ``Phi`` (the intercept was fitted through the centering).
    residuals : ndarray, shape (n,)

    Returns
    -------
    cov : ndarray, shape (P, P)
    dof : int
        ``n - P - 1``.
    """
    return covariance_from_jacobian(regressors, residuals, n_extra=1)


def jackknife_blocks(n_rows: int, n_params: int) -> int:
    """Segments of the jackknife for ``n_rows`` lag vectors (0: too short for one)."""
    g = min(JACKKNIFE_BLOCKS, n_rows // (MIN_BLOCK_ROWS_PER_PARAMETER * n_params))
    return g if g >= MIN_BLOCKS else 0


def lpc_jackknife(
    mats: np.ndarray,
    solve: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray],
    to_monic: Callable[[np.ndarray, int], np.ndarray],
    n_blocks: int,
) -> np.ndarray:
    """Delete-one-block jackknife covariance of the monic parameters.

    Parameters
    ----------
    mats : ndarray, shape (E, n, p)
        Lag matrices of the ``E`` equations (rows in time order).
    solve : callable
        ``solve(scatter (k, p, p), mean (k, p), n_rows (k,)) -> theta (k, p)``: the
        estimator's solve on centered scatter matrices.
    to_monic : callable
        ``to_monic(theta (k, p), equation) -> (k, q)``; raises ``ModelError`` when a
        replicate has no monic form.
    n_blocks : int
        ``G`` contiguous segments (the last takes the remainder rows).

    Returns
    -------
    ndarray, shape (E, q, q)
    """
    e, n, p = mats.shape
    mean = mats.mean(axis=1)
    centered = mats - mean[:, None, :]
    edges = np.arange(n_blocks + 1) * (n // n_blocks)
    edges[-1] = n
    total = np.swapaxes(centered, 1, 2) @ centered  # (E, p, p)
    segments = [centered[:, a:b] for a, b in itertools.pairwise(edges)]
    # (E, G, p, p): one matrix product per segment
    block_scatter = np.stack([np.swapaxes(seg, 1, 2) @ seg for seg in segments], axis=1)
    sums = np.add.reduceat(centered, edges[:-1], axis=1)  # (E, G, p)
    rows = (n - np.diff(edges)).astype(np.float64)  # (G,)
    rest = -sums  # the centered rows sum to 0: the rest of the record sums to -block
    scatter = (
        total[:, None]
        - block_scatter
        - rest[..., :, None] * rest[..., None, :] / rows[None, :, None, None]
    )
    rep_mean = mean[:, None, :] + rest / rows[None, :, None]
    thetas = solve(
        scatter.reshape(e * n_blocks, p, p),
        rep_mean.reshape(e * n_blocks, p),
        np.tile(rows, e),
    ).reshape(e, n_blocks, p)
    covs = []
    for j in range(e):
        reps = to_monic(thetas[j], j)  # (G, q)
        dev = reps - reps.mean(axis=0)
        covs.append((n_blocks - 1) / n_blocks * dev.T @ dev)
    return np.stack(covs)
