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

from clpc.core.compact import compact_repr
from clpc.data import DataError, as_iodata
from clpc.lpc.regressors import Structure, siso_regressor

__all__ = ["RATIO_AGREEMENT", "NoiseEstimate", "estimate_noise_variances"]


#: Two estimates of the variance ratio agree when they are within this factor of each other.
RATIO_AGREEMENT = 2.0
#: A variance at most this fraction of the larger one is at the estimator's floor (clamped).
VARIANCE_FLOOR = 1e-12


@compact_repr
@dataclass(frozen=True)
class NoiseEstimate:
    """Estimated white-noise variances of a SISO record, and whether to believe them.

    Attributes
    ----------
    output_variance, input_variance : float
        ``s_y`` and ``s_u`` in the units of ``y`` and ``u`` squared.
    iterations : int
    converged : bool
        The iteration met its tolerance.
    clamped : bool
        A variance ended at the floor (the equations asked for a negative one): the
        white-noise model does not fit the record.
    order_agreement : float
        Factor between the ratio ``s_u / s_y`` at ``order`` and at ``order + 1`` (1: the
        same; ``inf`` when the second estimate failed). A noise model that the data
        support does not depend on the order of the lag vector.
    reliable : bool
        Converged, not clamped, and ``order_agreement <= RATIO_AGREEMENT``.
    reason : str
        In words, why the estimate is or is not reliable.
    """

    output_variance: float
    input_variance: float
    iterations: int
    converged: bool
    clamped: bool = False
    order_agreement: float = 1.0
    reliable: bool = True
    reason: str = ""

    @property
    def ratio(self) -> float:
        """``s_u / s_y``, the ``noise_ratio`` of :class:`clpc.LPC` (check :attr:`reliable`)."""
        return self.input_variance / self.output_variance


def estimate_noise_variances(
    u: Any,
    y: Any | None = None,
    *,
    order: int = 2,
    extra_lags: int = 2,
    max_iter: int = 1000,
    tol: float = 1e-6,
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
        Iteration limit and relative tolerance on the variances (the iteration converges
        linearly: about 125 iterations for 1e-6 on a 2e4-sample record).

    Returns
    -------
    NoiseEstimate
        With ``reliable`` and ``reason``: the estimate is repeated with one more lag and
        compared. Use it (``LPC(noise_ratio=est.ratio)``) only when ``reliable``.
    """
    first = _estimate(u, y, order, extra_lags, (max_iter, tol), dt)
    try:
        second = _estimate(u, y, order + 1, extra_lags, (max_iter, tol), dt)
        agreement = max(first.ratio / second.ratio, second.ratio / first.ratio)
    except (DataError, ValueError, ZeroDivisionError, np.linalg.LinAlgError):
        agreement = float("inf")
    problems = []
    if not first.converged:
        problems.append(f"did not converge in {first.iterations} iterations")
    if first.clamped:
        problems.append("a variance hit the floor (the white-noise model does not fit)")
    if not agreement <= RATIO_AGREEMENT:
        problems.append(
            f"the ratio changes by a factor {agreement:.3g} from order {order} to "
            f"{order + 1} (more than {RATIO_AGREEMENT:g})"
        )
    reliable = not problems
    reason = (
        "; ".join(problems)
        if problems
        else (
            f"converged in {first.iterations} iterations; the ratio agrees within a factor "
            f"{agreement:.3g} at orders {order} and {order + 1}"
        )
    )
    return NoiseEstimate(
        first.output_variance,
        first.input_variance,
        first.iterations,
        first.converged,
        first.clamped,
        float(agreement),
        reliable,
        reason,
    )


def _estimate(
    u: Any,
    y: Any | None,
    order: int,
    extra_lags: int,
    limits: tuple[int, float],
    dt: float | None,
) -> NoiseEstimate:
    """One run of the iteration (see :func:`estimate_noise_variances`)."""
    max_iter, tol = limits
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
    # start from 1 % of each channel's mean lag variance
    var = np.array([np.mean(np.diag(scat)[is_y]), np.mean(np.diag(scat)[~is_y])]) * 1e-2
    converged = False
    clamped = False
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
        floor = VARIANCE_FLOOR * np.maximum(var.max(), 1e-300)
        clamped = bool(np.any(new <= floor))
        new = np.maximum(new, floor)
        change = np.max(np.abs(new - var) / new)
        var = new
        if change < tol:
            converged = True
            break
    return NoiseEstimate(float(var[0]), float(var[1]), iterations, converged, clamped)
