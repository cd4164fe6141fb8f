"""The simulation-error problem that :class:`clpc.OE` solves (residual, Jacobian, covariance).

The record's simulated samples ``n = s .. T-1`` are cut into ``K`` consecutive segments of
(almost) equal length (``K = min(SEGMENTS, (T - s) // MIN_SEGMENT)``, at least 1). Each
segment is simulated from the input alone, started from the **measured** outputs just
before it (multiple shooting), and the residual is the simulation error of every segment.

Why several starts and not one: a free run started from measured outputs gives every mode of
``1/A`` an initial amplitude, also a mode that the numerator (nearly) cancels and that the
input never excites. With a single start the search can tune such a pole/zero pair to make
that one start's transient fit a slow drift of the record (measured on the dryer record at
``N = 4, 5`` on parts of 300-480 samples: a pair at ``z = 0.998`` with a zero ``1e-4`` from
it, one start's training fit 1.3-1.5 points better than least squares, a later start's free
run 2-90 % where least squares gets 90 %). A model is used from a measured start anywhere
(held-out scoring, :func:`clpc.identify`'s origins): several starts in the objective make
that transient cost what it costs in use. On noise-free data every segment is fitted
exactly by the system, so the optimum is unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from clpc.lpc.reflection import MAX_KAPPA, poly_from_reflection
from clpc.lpc.uncertainty import covariance_from_jacobian

__all__ = ["MIN_SEGMENT", "SEGMENTS", "SimulationError"]

#: Most segments (measured starts) of the simulation error.
SEGMENTS = 4
#: Fewest simulated samples per segment (shorter records get fewer segments).
MIN_SEGMENT = 50


def _signal() -> Any:
    from scipy import signal  # imported when used: scipy.signal costs ~0.8 s

    return signal


@dataclass
class SimulationError:
    """One output's simulation-error problem (rows ``n = s .. T-1``, in time order).

    Parameters
    ----------
    y : ndarray, shape (T,)
        Measured output.
    phi_u : ndarray, shape (T - s, m (nb + 1))
        Input lags ``u_i(n - nk - l)`` of rows ``n = s .. T-1``.
    na : int
        Denominator order (>= 1).
    s : int
        First simulated sample (the structure's ``max_lag``).
    segments : int
        Most segments (see the module docstring); 1: one free run from ``s``.
    """

    y: np.ndarray
    phi_u: np.ndarray
    na: int
    s: int
    segments: int = SEGMENTS
    starts: np.ndarray = field(init=False)
    _pos: np.ndarray = field(init=False, repr=False)
    _valid: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        m = self.y.size - self.s
        k = max(1, min(self.segments, m // MIN_SEGMENT))
        bounds = self.s + np.round(np.arange(k + 1) * m / k).astype(int)
        self.starts, lengths = bounds[:-1], np.diff(bounds)
        rows = np.arange(int(lengths.max()))[:, None]
        self._valid = rows < lengths[None, :]  # (L, K): padding after each segment's end
        self._pos = np.where(self._valid, self.starts[None, :] + rows, self.s) - self.s

    def _rows(self, arr: np.ndarray) -> np.ndarray:
        """(L, K, ...) segment-major array -> its valid rows in time order."""
        return np.swapaxes(arr, 0, 1)[self._valid.T]

    def _past(self) -> np.ndarray:
        """Measured outputs before each segment, shape (na, K): ``y(start-1), y(start-2)``..."""
        return np.stack([self.y[st - self.na : st][::-1] for st in self.starts], axis=1)

    def split(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """``x = [rho (na); b; k]`` -> ``a``, ``da/drho``, ``b``, ``k``."""
        t = np.tanh(x[: self.na])
        a, da = poly_from_reflection(MAX_KAPPA * t)
        return a, da[1:] * (MAX_KAPPA * (1.0 - t**2))[None, :], x[self.na : -1], float(x[-1])

    def simulate(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``a`` and ``y_hat(n)`` for ``n >= s``, each segment started from the measured ``y``."""
        a, _, b, k = self.split(x)
        forced = (self.phi_u @ b + k)[self._pos]
        signal = _signal()
        past = self._past()
        zi = np.stack([signal.lfiltic([1.0], a, past[:, i]) for i in range(past.shape[1])], 1)
        return a, self._rows(signal.lfilter([1.0], a, forced, axis=0, zi=zi)[0])

    def residual(self, x: np.ndarray) -> np.ndarray:
        """Simulation errors ``y(n) - y_hat(n)``, ``n = s .. T-1``."""
        return self.y[self.s :] - self.simulate(x)[1]

    def monic_jacobian(self, x: np.ndarray) -> np.ndarray:
        """``d residual / d (a_1..a_na, b, k)``, shape (T - s, na + len(b) + 1).

        ``d y_hat / d a_l = -y_hat(n-l) / A(q)`` (measured ``y`` before the segment's start,
        zero initial state), ``d y_hat / d b = u(n-nk-l) / A(q)``, ``d y_hat / d k = 1 / A(q)``.
        """
        a = self.split(x)[0]
        n_rows, n_seg = self._valid.shape
        y_hat = np.zeros((n_rows, n_seg))
        y_hat.T[self._valid.T] = self.simulate(x)[1]
        full = np.vstack([self._past()[::-1], y_hat])  # (na + L, K)
        lags = [full[self.na - lag : self.na - lag + n_rows] for lag in range(1, self.na + 1)]
        cols = np.concatenate(
            [
                -np.stack(lags, axis=2),
                self.phi_u[self._pos],
                np.ones((n_rows, n_seg, 1)),
            ],
            axis=2,
        )
        return -self._rows(_signal().lfilter([1.0], a, cols, axis=0))

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """``d residual / d x`` (``x = [rho; b; k]``: the chain rule through ``a(rho)``)."""
        _, da_drho, _, _ = self.split(x)
        jac = self.monic_jacobian(x)
        return np.hstack([jac[:, : self.na] @ da_drho, jac[:, self.na :]])

    def covariance(self, x: np.ndarray, lmap: np.ndarray) -> tuple[np.ndarray, int]:
        """Covariance of the monic vector of this output at the optimum ``x`` (see OE).

        ``s^2 (J^T J)^-1`` with ``J`` taken with respect to ``(a_1..a_na, b, k)`` directly
        (not ``rho``: its ``tanh`` flattens near the stability bound), plus the effect of the
        noise on the measured start values of every segment: the estimate moves by
        ``-(J^T J)^-1 J^T (e - G delta)`` (``G``: each start value's free response in its
        segment); the start values of a later segment are samples of the residual ``e``
        itself, those before ``s`` are not. The ``(a, b)`` block is carried to
        ``np.r_[den[1:], num]`` by ``lmap`` (:func:`monic_map`, ``b``'s sign flipped).
        """
        jac, res = self.monic_jacobian(x), self.residual(x)
        cov, dof = covariance_from_jacobian(jac, res)
        s2 = float(res @ res) / dof
        signal, a = _signal(), self.split(x)[0]
        n_rows, n_seg = self._valid.shape
        base = np.column_stack(
            [
                signal.lfilter([1.0], a, np.zeros(n_rows), zi=signal.lfiltic([1.0], a, past))[0]
                for past in np.eye(self.na)  # a unit y(start-1-i), the others 0
            ]
        ).reshape(n_rows, self.na)
        g = np.zeros((n_rows, n_seg, n_seg * self.na))
        for i in range(n_seg):  # loop over the segments, not over samples
            g[:, i, i * self.na : (i + 1) * self.na] = base
        jg = self._rows(g).T @ jac  # (K na, P): J^T G, transposed
        w = jac.copy()  # (I - G S)^T J: residual = e - G S e, S picks the start values from e
        for i in range(1, n_seg):
            for lag in range(self.na):  # start value y(start_i - 1 - lag) = residual row
                w[self.starts[i] - 1 - lag - self.s] -= jg[i * self.na + lag]
        h0 = cov @ jg[: self.na].T / s2  # the first segment's start values (before s)
        inv = cov / s2
        cov = s2 * (inv @ (w.T @ w) @ inv + h0 @ h0.T)
        n_ab = cov.shape[0] - 1  # drop the offset k
        flip = np.r_[np.ones(self.na), -np.ones(n_ab - self.na)]
        cov_x = flip[:, None] * cov[:n_ab, :n_ab] * flip[None, :]
        return lmap @ cov_x @ lmap.T, dof
