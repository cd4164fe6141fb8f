"""Input and output noise variances from the eigenvalue structure (DIPCA-like).

With white measurement noise of variance ``s_y`` on the output and ``s_u`` on the input, the lag
vector's noise covariance is ``W = diag(s_y, ..., s_y, s_u, ..., s_u)``. If the system's order is
``N`` and the lag vector is built with a larger order ``L = N + e``, the noise-free data satisfy
``m = e + 1`` independent linear relations (the system's and its shifts), collected in the
columns of ``Theta`` (p x m). For the true ``W`` the residual covariance of those relations is
exactly the noise's:

    Theta^T A Theta / n  =  Theta^T W Theta  =  s_y Theta_y^T Theta_y + s_u Theta_u^T Theta_u

and ``Theta`` spans the ``m`` smallest generalized eigenvectors of ``(A, W)``. The iteration
alternates the two: the relations for the current ``W``, then ``(s_y, s_u)`` by least squares
on the ``m (m + 1) / 2`` distinct entries of that matrix equation (the dynamic iterative PCA of
Narasimhan and Shah, 2008, restricted to one input and one output). It needs ``m >= 2`` (one
relation cannot tell the two variances apart), hence ``extra_lags >= 1``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.data import DataError, as_iodata
from clpc.lpc.regressors import Structure, siso_regressor

__all__ = ["NoiseEstimate", "estimate_noise_variances"]


@dataclass(frozen=True)
class NoiseEstimate:
    """Estimated white-noise variances of a SISO record.

    Attributes
    ----------
    output_variance, input_variance : float
        ``s_y`` and ``s_u`` in the units of ``y`` and ``u`` squared.
    iterations : int
    converged : bool
    """

    output_variance: float
    input_variance: float
    iterations: int
    converged: bool

    @property
    def ratio(self) -> float:
        """``s_u / s_y``, the ``noise_ratio`` of :class:`clpc.LPC`."""
        return self.input_variance / self.output_variance


def estimate_noise_variances(
    u: Any,
    y: Any | None = None,
    *,
    order: int = 2,
    extra_lags: int = 2,
    max_iter: int = 200,
    tol: float = 1e-8,
    dt: float | None = None,
) -> NoiseEstimate:
    """Estimate the input and output noise variances of a SISO record.

    Parameters
    ----------
    u, y, dt
        The record (see :meth:`clpc.LPC.fit`).
    order : int
        The system's order ``N``.
    extra_lags : int
        Extra lags ``e >= 1``: the lag vector has order ``N + e`` and ``e + 1`` relations.
    max_iter, tol
        Iteration limit and relative tolerance on the variances.

    Returns
    -------
    NoiseEstimate
    """
    data = as_iodata(u, y, dt)
    if data.n_inputs != 1 or data.n_outputs != 1:
        raise DataError("noise variance estimation is implemented for one input and one output.")
    if extra_lags < 1:
        raise ValueError(f"extra_lags must be an int >= 1; got {extra_lags!r}.")
    lag = order + extra_lags
    structure = Structure.from_order(lag)
    data.require_samples(4 * (2 * lag + 2), "Noise variance estimation")
    m_rel = extra_lags + 1
    mat = siso_regressor(data.y[:, 0], data.u[:, 0], structure)
    centered = mat - mat.mean(axis=0)
    n = centered.shape[0]
    scat = centered.T @ centered / n
    is_y = np.arange(mat.shape[1]) <= lag
    # start from the smallest eigenvalue of the channel-scaled problem
    var = np.array([np.mean(np.diag(scat)[is_y]), np.mean(np.diag(scat)[~is_y])]) * 1e-2
    converged = False
    iterations = 0
    while iterations < max_iter:
        iterations += 1
        w_sqrt = np.sqrt(np.where(is_y, var[0], var[1]))
        whitened = scat / np.outer(w_sqrt, w_sqrt)
        _, vecs = np.linalg.eigh(whitened)
        theta = vecs[:, :m_rel] / w_sqrt[:, None]  # relations in original units
        lhs = theta.T @ scat @ theta
        gy = theta[is_y].T @ theta[is_y]
        gu = theta[~is_y].T @ theta[~is_y]
        iu = np.triu_indices(m_rel)
        design = np.column_stack([gy[iu], gu[iu]])
        new, *_ = np.linalg.lstsq(design, lhs[iu], rcond=None)
        new = np.maximum(new, 1e-12 * np.maximum(var.max(), 1e-300))
        change = np.max(np.abs(new - var) / new)
        var = new
        if change < tol:
            converged = True
            break
    return NoiseEstimate(float(var[0]), float(var[1]), iterations, converged)
