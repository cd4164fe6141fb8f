"""The simulation-error problem that :class:`clpc.OE` solves (residual, Jacobian, covariance).

The residual is the simulation error of several free runs of the model, each simulated from
the input alone and started from the **measured** outputs just before it:

* one run over the whole record, samples ``n = s .. T-1`` (the classic output-error
  objective);
* with ``full_run`` (default) and a record of at least ``2 MIN_SEGMENT`` simulated samples, one
  more run from each later segment start: the samples are cut into ``K = min(SEGMENTS,
  (T - s) // MIN_SEGMENT)`` consecutive segments of (almost) equal length, and segments ``2 ..
  K`` are run on their own (their samples also appear in the whole run, so they count twice).
  ``full_run=False`` gives pure multiple shooting (the first segment ends where the second
  starts); ``segments=1``, the whole run alone.

Why later starts: a free run started from measured outputs gives every mode of ``1/A`` an
initial amplitude, also a mode that the numerator (nearly) cancels and that the input never
excites. With a single start the search can tune such a pole/zero pair so that one start's
transient fits a slow drift of the record (measured on the dryer record at ``N = 4, 5`` on
parts of 300-480 samples: a pair at ``z = 0.998`` with a zero ``1e-4`` from it, one start's
training fit 1.3-1.5 points better than least squares, a later start's free run 2-90 %
where least squares gets 90 %). A model is used from a measured start anywhere (held-out
scoring, :func:`clpc.identify`'s origins): later starts in the objective make that transient
cost what it costs in use.

Why the whole run as well: segments alone (multiple shooting) accept a near-integrator
(poles at 0.9997-1.0) that fits each 150-sample segment but drifts over a longer run
(ballbeam ``N = 4``: validation free run -1106 % against 25 % for the one-start fit); the
whole run makes the drift cost over the record's length. On noise-free data every run is
fitted exactly by the system, so the optimum is unchanged. ``benchmarks/oe_starts.py``
compares the three objectives on the project's real records.
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


def _initial_state(a: np.ndarray, past: np.ndarray) -> np.ndarray:
    """``lfilter([1], a)``'s state after the outputs ``past`` (shape (na, R), newest first).

    ``zi[m] = -sum_{p > m} a[p] y(-(p - m))`` (``scipy.signal.lfiltic`` with ``b = [1]``),
    for every column at once.
    """
    na = a.size - 1
    idx = np.arange(na)[:, None] + np.arange(1, na + 1)[None, :]  # p = m + 1 + j
    h = -np.where(idx <= na, a[np.minimum(idx, na)], 0.0)
    return h @ past


@dataclass(frozen=True)
class _Block:
    """Free runs of (almost) equal length, simulated side by side as the columns of one filter.

    ``pos`` (L, R): sample ``n - s`` of each run's row; ``valid`` (L, R): rows before each run's
    end (the rest is padding); ``starts`` (R,): each run's first sample ``n``.
    """

    starts: np.ndarray
    pos: np.ndarray
    valid: np.ndarray

    @classmethod
    def of(cls, starts: np.ndarray, lengths: np.ndarray, s: int) -> _Block:
        rows = np.arange(int(lengths.max()))[:, None]
        valid = rows < lengths[None, :]
        return cls(starts, np.where(valid, starts[None, :] + rows, s) - s, valid)

    def rows(self, arr: np.ndarray) -> np.ndarray:
        """(L, R, ...) run-major array -> its valid rows, run after run."""
        return np.swapaxes(arr, 0, 1)[self.valid.T]


@dataclass
class SimulationError:
    """One output's simulation-error problem (the runs of the module docstring).

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
    full_run : bool
        The first run goes on to the record's end (default; see the module docstring).

    Notes
    -----
    The residual holds the runs one after the other, the first (from ``s``) first: with
    ``full_run`` its first ``T - s`` rows are the whole run, every sample once.
    """

    y: np.ndarray
    phi_u: np.ndarray
    na: int
    s: int
    segments: int = SEGMENTS
    full_run: bool = True
    starts: np.ndarray = field(init=False)
    _blocks: tuple[_Block, ...] = field(init=False, repr=False)
    _times: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        m = self.y.size - self.s
        k = max(1, min(self.segments, m // MIN_SEGMENT))
        bounds = self.s + np.round(np.arange(k + 1) * m / k).astype(int)
        self.starts, lengths = bounds[:-1], np.diff(bounds)
        if self.full_run and k > 1:  # the whole run, then the later segments side by side
            self._blocks = (
                _Block.of(self.starts[:1], np.array([m]), self.s),
                _Block.of(self.starts[1:], lengths[1:], self.s),
            )
        else:
            self._blocks = (_Block.of(self.starts, lengths, self.s),)
        self._times = np.concatenate([blk.rows(blk.pos) for blk in self._blocks])

    def _past(self, starts: np.ndarray) -> np.ndarray:
        """Measured outputs before each run, shape (na, R): ``y(start-1), y(start-2)``..."""
        return np.stack([self.y[st - self.na : st][::-1] for st in starts], axis=1)

    def split(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """``x = [rho (na); b; k]`` -> ``a``, ``da/drho``, ``b``, ``k``."""
        t = np.tanh(x[: self.na])
        a, da = poly_from_reflection(MAX_KAPPA * t)
        return a, da[1:] * (MAX_KAPPA * (1.0 - t**2))[None, :], x[self.na : -1], float(x[-1])

    def _runs(self, x: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
        """``a`` and each block's free runs ``y_hat``, shape (L, R) (padded)."""
        a, _, b, k = self.split(x)
        forced = self.phi_u @ b + k
        signal = _signal()
        runs = []
        for block in self._blocks:
            zi = _initial_state(a, self._past(block.starts))
            runs.append(signal.lfilter([1.0], a, forced[block.pos], axis=0, zi=zi)[0])
        return a, runs

    def simulate(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``a`` and ``y_hat`` of every run (the residual's rows), each from the measured ``y``."""
        a, runs = self._runs(x)
        return a, np.concatenate([blk.rows(r) for blk, r in zip(self._blocks, runs, strict=True)])

    def targets(self) -> np.ndarray:
        """The measured ``y(n)`` of every row of the residual."""
        return self.y[self.s :][self._times]

    def times(self) -> np.ndarray:
        """The sample ``n - s`` of every row of the residual."""
        return self._times

    def residual(self, x: np.ndarray) -> np.ndarray:
        """Simulation errors ``y(n) - y_hat(n)`` of every run, the runs one after the other."""
        return self.targets() - self.simulate(x)[1]

    def monic_jacobian(self, x: np.ndarray) -> np.ndarray:
        """``d residual / d (a_1..a_na, b, k)``, shape (rows, na + len(b) + 1).

        ``d y_hat / d a_l = -y_hat(n-l) / A(q)`` (measured ``y`` before the run's start,
        zero initial state), ``d y_hat / d b = u(n-nk-l) / A(q)``, ``d y_hat / d k = 1 / A(q)``.
        Each block's columns are filled in place, filtered at once, and the filter's output
        is written straight into the result, run after run: no stacked, masked or
        concatenated copies (the padding past a shorter run's end is filtered too, and never
        read).
        """
        a, runs = self._runs(x)
        signal = _signal()
        jac = np.empty((self._times.size, self.na + self.phi_u.shape[1] + 1))
        row = 0
        for block, y_hat in zip(self._blocks, runs, strict=True):
            n_rows, n_runs = y_hat.shape
            full = np.vstack([self._past(block.starts)[::-1], y_hat])  # (na + L, R)
            cols = np.empty((n_rows, n_runs, jac.shape[1]))
            for lag in range(1, self.na + 1):
                np.negative(full[self.na - lag : self.na - lag + n_rows], out=cols[:, :, lag - 1])
            cols[:, :, self.na : -1] = self.phi_u[block.pos]
            cols[:, :, -1] = 1.0
            filtered = signal.lfilter([1.0], a, cols, axis=0)
            for r, length in enumerate(block.valid.sum(axis=0)):
                np.negative(filtered[:length, r], out=jac[row : row + length])
                row += length
        return jac

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """``d residual / d x`` (``x = [rho; b; k]``: the chain rule through ``a(rho)``)."""
        _, da_drho, _, _ = self.split(x)
        jac = self.monic_jacobian(x)
        jac[:, : self.na] = jac[:, : self.na] @ da_drho
        return jac

    def covariance(self, x: np.ndarray, lmap: np.ndarray) -> tuple[np.ndarray, int]:
        """Covariance of the monic vector of this output at the optimum ``x`` (see OE).

        A sandwich around ``(J^T J)^-1``, ``J`` taken with respect to ``(a_1..a_na, b, k)``
        directly (not ``rho``: its ``tanh`` flattens near the stability bound). With ``e`` the
        output noise of samples ``s .. T-1``, the residual is ``P e - G S e - G_0 e_0``:
        ``P`` picks each row's sample (a sample in two runs counts twice), ``G`` is the free
        response of each run to its measured start values, which are samples of ``e``
        (``S``) for a later run and samples before ``s`` (``e_0``) for the first. The
        estimate moves by ``-(J^T J)^-1 J^T`` times that, so

            C = s^2 (J^T J)^-1 [J^T (P - G S)(P - G S)^T J + J^T G_0 G_0^T J] (J^T J)^-1,

        ``s^2`` the first run's mean square over ``T - s - P`` (every sample once). The
        ``(a, b)`` block is carried to ``np.r_[den[1:], num]`` by ``lmap``
        (:func:`monic_map`, ``b``'s sign flipped).
        """
        jac, res = self.monic_jacobian(x), self.residual(x)
        cov, dof = covariance_from_jacobian(jac, res)
        inv = cov / (float(res @ res) / dof)  # (J^T J)^-1, its rank checked
        m = self.y.size - self.s
        once = res[:m]  # the first run (or, without full_run, all runs): every sample once
        dof = m - jac.shape[1]
        if dof < 1:
            raise ValueError(f"{m} samples leave no degrees of freedom for {jac.shape[1]}.")
        s2 = float(once @ once) / dof
        signal, a = _signal(), self.split(x)[0]
        w = np.zeros((m, jac.shape[1]))  # (P - G S)^T J
        np.add.at(w, self.times(), jac)
        first, h0 = 0, np.zeros((jac.shape[1], self.na))
        for block in self._blocks:
            n_rows, n_runs = block.valid.shape
            zi = _initial_state(a, np.eye(self.na))  # a unit y(start-1-i), the others 0
            base = signal.lfilter([1.0], a, np.zeros((n_rows, self.na)), axis=0, zi=zi)[0]
            for r in range(n_runs):  # loop over the runs, not over samples
                length = int(block.valid[:, r].sum())
                jg = base[:length].T @ jac[first : first + length]  # (na, P): (G^T J) of run r
                first += length
                start = int(block.starts[r]) - self.s
                if start == 0:
                    h0 = inv @ jg.T  # start values before s
                    continue
                for lag in range(self.na):  # start value y(start - 1 - lag) is noise sample
                    w[start - 1 - lag] -= jg[lag]
        cov = s2 * (inv @ (w.T @ w) @ inv + h0 @ h0.T)
        n_ab = cov.shape[0] - 1  # drop the offset k
        flip = np.r_[np.ones(self.na), -np.ones(n_ab - self.na)]
        cov_x = flip[:, None] * cov[:n_ab, :n_ab] * flip[None, :]
        return lmap @ cov_x @ lmap.T, dof
