"""Baseline: ordinary least-squares ARX with the same structure as LPC.

Least squares assumes the noise is on ``y(n)`` only (equation error); with noise on both
input and output it is biased, which is where LPC (total least squares) earns its keep.
The model is returned in the same :class:`~clpc.model.LinearModel` as LPC, so the two can be
put side by side.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.lpc.problem import Covariance, FitProblem
from clpc.lpc.regressors import MimoMode, Structure
from clpc.lpc.uncertainty import least_squares_covariance, monic_map
from clpc.model import LinearModel

__all__ = ["ARX", "simulate_arx"]


@dataclass
class ARX:
    """Least-squares ARX: minimise ``sum (y(n) - phi_n^T x - k)^2``.

    Parameters
    ----------
    order, na, nb, nk, mimo
        As for :class:`clpc.LPC` (same structure, same lag matrices).
    uncertainty : bool
        Store the classical covariance ``s^2 (Phi^T Phi)^-1`` (default ``True``;
        :func:`clpc.lpc.uncertainty.least_squares_covariance`). Valid when the noise is
        white and enters the equation (``A y = B u + e``); with noise on the output only or
        on the input the estimate is biased and the intervals do not cover.
    assess : bool
        Store the held-out fit and residual tests (default ``True``; as :class:`clpc.LPC`).
    """

    order: int = 2
    na: int | None = None
    nb: int | None = None
    nk: int = 0
    mimo: MimoMode | None = None
    uncertainty: bool = True
    assess: bool = True

    def structure(self) -> Structure:
        """The :class:`Structure` these settings describe."""
        return Structure.from_settings(self.order, self.na, self.nb, self.nk)

    def fit(self, u: Any, y: Any | None = None, dt: float | None = None) -> LinearModel:
        """Least-squares fit; returns a :class:`LinearModel` (``theta`` unit norm, a0 > 0).

        Parameters
        ----------
        u : IOData or array_like, shape (T,) or (T, n_inputs)
            The record, or its inputs.
        y : array_like, shape (T,) or (T, n_outputs), optional
            Outputs (when ``u`` is not an :class:`IOData`).
        dt : float, optional
            Sample time [s] (when ``u`` is not an :class:`IOData`).

        Returns
        -------
        LinearModel
            With the classical covariance when ``uncertainty``; the held-out assessment is
            offered on demand when ``assess``.
        """
        problem = FitProblem.prepare(self, (u, y, dt), "An ARX fit")
        data, structure, mode = problem.data, problem.structure, problem.mode
        mats = problem.regressors()
        mean = mats.mean(axis=1)
        thetas = np.empty((mats.shape[0], mats.shape[2]))
        covs, dofs, no_cov = [], [], ""
        for j, (m, z) in enumerate(zip(mats, mean, strict=False)):
            centered = m - z
            # y(n) = -[a1..; b..] . rest  ->  theta = [1, x]
            x, *_ = np.linalg.lstsq(centered[:, 1:], -centered[:, 0], rcond=None)
            thetas[j] = np.concatenate([[1.0], x])
            if self.uncertainty and not no_cov:
                resid = -centered[:, 0] - centered[:, 1:] @ x
                try:
                    cov_x, dof = least_squares_covariance(centered[:, 1:], resid)
                except ValueError as exc:  # rank-deficient regressors: no finite covariance
                    no_cov = f"output {data.output_names[j]}: {exc}"
                    continue
                lmap = monic_map(structure, data.n_inputs, mode, j)
                covs.append(lmap @ cov_x @ lmap.T)
                dofs.append(dof)
        thetas /= np.linalg.norm(thetas, axis=1, keepdims=True)
        c = np.einsum("kp,kp->k", mean, thetas)
        covariance = None
        if no_cov:
            covariance = Covariance(note=no_cov)
        elif self.uncertainty:
            covariance = Covariance(np.stack(covs), np.array(dofs), "least squares")
        return problem.model(self, thetas, c, {"method": "least-squares"}, covariance)


def simulate_arx(den: Any, num: Any, u: Any, noise: Any | None = None) -> np.ndarray:
    """Simulate ``A(q) y = B(q) u + e`` with monic ``den`` and ``num`` (ascending ``z^-1``).

    Parameters
    ----------
    den : array_like, shape (na + 1,)
        ``[1, a1, ..., a_na]``.
    num : array_like, shape (nb + 1,)
        ``[b0, ..., b_nb]`` (leading zeros for a delay).
    u : array_like, shape (T,)
        Input.
    noise : array_like, shape (T,), optional
        Equation error ``e``.

    Returns
    -------
    ndarray, shape (T,)
    """
    from scipy import signal  # imported when used: scipy.signal costs ~0.8 s

    y = signal.lfilter(np.asarray(num, float), np.asarray(den, float), np.asarray(u, float))
    if noise is not None:
        y = y + signal.lfilter([1.0], np.asarray(den, float), np.asarray(noise, float))
    return y
