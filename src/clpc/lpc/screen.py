"""The structure screen of :func:`clpc.identify`: every ``(na, nb, nk)`` by fast least squares.

Output error and LPC cost tens to hundreds of milliseconds per fit; least squares on a small
Gram matrix costs microseconds. So :func:`clpc.identify` first scores **every** structure in
its ranges (``na``, ``nb`` and ``nk`` independently, up to ``na = 10`` and ``nk = 5`` by
default) as a least-squares ARX model at the same rolling origins as the candidates
(:func:`clpc.lpc.comparison.rolling_origin`), and fits the expensive estimators on the few
best structures only (MATLAB's ``arxstruc``/``selstruc`` step, scored by the free run on
later data instead of the one-step loss).

At each origin and for each output, one lag matrix holds every column any structure needs
(``y(n-1..n-NA)``, ``u_i(n-0..n-NK-NB)``) over the same rows; its centered Gram matrix is
formed once, and each structure solves the normal equations of its own columns. Each fit is
then simulated from the input alone on the scored part, started from the measured outputs
before it, exactly as the candidates are (:func:`clpc.lpc.comparison.fold_fits`), and scored
by its free-run fit %. Forming the Gram matrix squares the condition number of the lag
matrix: good enough to rank structures; the chosen ones are refitted by
:class:`clpc.ARX` (``lstsq``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.data import IOData
from clpc.lpc import heldout
from clpc.model.structure import Structure

__all__ = ["PARSIMONY", "Screen", "screen"]

#: Points of mean held-out free-run fit a structure with fewer parameters may give away.
PARSIMONY = 1.0
#: Memory for the input part of the screened simulations, simulated a block of structures
#: at a time [bytes].
DRIVE_BYTES = 32 * 2**20


@dataclass(frozen=True)
class Screen:
    """Every structure's least-squares held-out free run.

    Attributes
    ----------
    structures : list of Structure
        The structures screened.
    windows : ndarray, shape (n_structures, n_origins, n_outputs)
        Free-run fit % of each structure's least-squares fit at each origin, per output
        (``-inf`` when it diverges).
    n_params : ndarray of int, shape (n_structures,)
        Coefficients per output equation (``na + n_blocks (nb + 1)``).
    """

    structures: list[Structure]
    windows: np.ndarray
    n_params: np.ndarray

    @property
    def score(self) -> np.ndarray:
        """Mean free-run fit % over the origins and outputs, shape (n_structures,)."""
        with np.errstate(invalid="ignore"):
            return self.windows.mean(axis=(1, 2))

    def best(self, among: np.ndarray | None = None, parsimony: float = PARSIMONY) -> int:
        """Index of the structure with the fewest parameters within ``parsimony`` of the best.

        Among equals in size, the higher score. ``among``: a boolean mask of the structures
        to choose from (default all).
        """
        score = np.where(np.isfinite(self.score), self.score, -np.inf)
        pool = np.ones(score.size, dtype=bool) if among is None else among
        top = np.max(score[pool])
        idx = np.flatnonzero(pool)
        if not math.isfinite(top):
            return int(min(idx, key=lambda i: self.n_params[i]))
        near = idx[score[idx] >= top - parsimony]
        return int(min(near, key=lambda i: (self.n_params[i], -score[i])))

    def shortlist(self, size: int) -> list[int]:
        """The structures the expensive estimators are fitted on, best first.

        :meth:`best`; then the same rule among the structures with a lower ``na`` than the
        first, then among those with another delay: least squares under output noise needs
        more poles than the process has (its equation error is coloured) and can prefer a
        wrong delay, so the shortlist keeps the alternatives the consistent estimators (OE)
        may do better with.
        """
        picks = [self.best()]
        first = self.structures[picks[0]]
        nk = np.array([s.nk for s in self.structures])
        na = np.array([s.na for s in self.structures])
        for among in (na < first.na, nk != first.nk):
            among = among.copy()
            among[picks] = False  # each structure once
            if len(picks) < size and among.any():
                picks.append(self.best(among))
        return picks

    def rows(self) -> list[dict[str, Any]]:
        """One dict per structure: ``na``, ``nb``, ``nk``, ``n_params``, ``free_run``."""
        return [
            {"na": s.na, "nb": s.nb, "nk": s.nk, "n_params": int(p), "free_run": float(f)}
            for s, p, f in zip(self.structures, self.n_params, self.score, strict=True)
        ]


def screen(
    folds: list[tuple[IOData, IOData]],
    structures: list[Structure],
    mode: str,
) -> Screen:
    """Score every structure as a least-squares ARX at every origin (see the module).

    Parameters
    ----------
    folds : list of (IOData, IOData)
        The (fitted, scored) parts at each origin.
    structures : list of Structure
        The structures to score.
    mode : {"siso", "paired", "miso"}
        MIMO mode: output ``j`` uses every input (``"miso"``) or input ``j`` only.

    Returns
    -------
    Screen
    """
    n_out = folds[0][0].n_outputs
    n_in = folds[0][0].n_inputs
    blocks = n_in if mode == "miso" else 1
    lags = _LagSet(structures, blocks)
    windows = np.empty((len(structures), len(folds), n_out))
    for o, (est, val) in enumerate(folds):
        for j in range(n_out):
            cols = list(range(n_in)) if mode == "miso" else [j]
            coef, k = lags.solve(est.y[:, j], est.u[:, cols])
            windows[:, o, j] = lags.free_runs(coef, k, val.y[:, j], val.u[:, cols])
    n_params = np.array([s.na + blocks * (s.nb + 1) for s in structures])
    return Screen(list(structures), windows, n_params)


class _LagSet:
    """Every lag column the structures need, and each structure's columns among them.

    Columns: ``y(n-1) .. y(n-NA)``, then per input ``u_i(n) .. u_i(n-NU+1)``.
    """

    def __init__(self, structures: list[Structure], n_inputs: int) -> None:
        self.na = max(s.na for s in structures)
        self.nu = max(s.nk + s.nb for s in structures) + 1  # input lags 0..nu-1
        self.n_inputs = n_inputs
        self.start = max(self.na, self.nu - 1)
        width = self.na + n_inputs * self.nu
        self.mask = np.zeros((len(structures), width), dtype=bool)
        self.orders = np.array([s.na for s in structures])
        for i, s in enumerate(structures):
            self.mask[i, : s.na] = True
            for b in range(n_inputs):
                first = self.na + b * self.nu + s.nk
                self.mask[i, first : first + s.nb + 1] = True

    def _matrix(self, y: np.ndarray, u: np.ndarray) -> np.ndarray:
        """Rows ``n = start .. T-1``: every lag column, then ``y(n)``."""
        rows = y.size - self.start
        mat = np.empty((rows, self.na + self.n_inputs * self.nu + 1))
        for lag in range(1, self.na + 1):
            mat[:, lag - 1] = y[self.start - lag : y.size - lag]
        for i in range(self.n_inputs):
            for lag in range(self.nu):
                mat[:, self.na + i * self.nu + lag] = u[self.start - lag : y.size - lag, i]
        mat[:, -1] = y[self.start :]
        return mat

    def solve(self, y: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every structure's least-squares coefficients (zero off its columns) and intercept.

        Returns ``coef`` of shape (n_structures, n_columns) and ``k`` (n_structures,).
        """
        mat = self._matrix(y, u)
        means = mat.mean(axis=0)
        mat -= means
        full = mat.T @ mat
        gram, cross = full[:-1, :-1], full[:-1, -1]
        m = self.mask
        stack = gram * (m[:, :, None] & m[:, None, :])
        stack[:, np.arange(m.shape[1]), np.arange(m.shape[1])] += ~m  # 1 off the columns
        rhs = np.where(m, cross, 0.0)
        try:
            coef = np.linalg.solve(stack, rhs[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:  # a singular structure: each on its own, by lstsq
            coef = np.stack(
                [np.linalg.lstsq(g, r, rcond=None)[0] for g, r in zip(stack, rhs, strict=True)]
            )
        k = means[-1] - coef @ means[:-1]
        return coef, k

    def free_runs(
        self, coef: np.ndarray, k: np.ndarray, y: np.ndarray, u: np.ndarray
    ) -> np.ndarray:
        """Each structure's free-run fit % on ``y[start:]``, from the measured ``y`` before."""
        from scipy import signal  # imported when used: scipy.signal costs ~0.8 s

        mat = self._matrix(y, u)
        inputs = mat[:, self.na : -1]
        past = y[self.start - 1 :: -1][: self.na]  # y(start-1), y(start-2), ...
        target = y[self.start :]
        out = np.empty(coef.shape[0])
        # the input part of every structure's simulation, a block of structures at a time:
        # memory O(rows), not O(rows * n_structures)
        block = max(1, DRIVE_BYTES // max(1, 8 * target.size))
        with np.errstate(all="ignore"):
            for first in range(0, coef.shape[0], block):
                chosen = slice(first, first + block)
                drive = inputs @ coef[chosen, self.na :].T  # (rows, block)
                drive += k[chosen]
                for s, na in enumerate(self.orders[chosen], start=first):
                    den = np.concatenate([[1.0], -coef[s, :na]])
                    # lfilter's transposed direct-form state for the measured past outputs
                    zi = np.array([den[m + 1 :] @ past[: na - m] for m in range(na)])
                    sim = signal.lfilter([1.0], den, drive[:, s - first], zi=-zi)[0]
                    out[s] = heldout.fit_percent(target, sim)
        return out
