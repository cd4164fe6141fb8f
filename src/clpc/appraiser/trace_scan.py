"""Counts, convergence and the steady-state model of a trace read in parts, in bounded memory.

A trace of a long record does not fit in memory (a year at 1 kHz with ``C = 12`` is 2.6e9
updates); ``clpc track`` writes it to a file part by part. :class:`TraceScan` reads the parts
once, in order, and keeps what the summary needs: the counts, the state of the convergence
search, running sums from the convergence point on, and the rows after that point spilled to
a scratch file (:class:`RowSpill`) for the one second pass the variations need (deviations
from the mean, which is known only at the end). Memory is O(one part) whatever the length.

:func:`clpc.appraiser.convergence.convergence` runs this scan over a whole in-memory trace,
so a record gives the same convergence fed at once or in parts, bit for bit: every sum runs
in update order (:func:`sequential_sum`), wherever the parts are cut.
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["RowSpill", "ScanState", "sequential_mean", "sequential_sum", "usable"]

#: rows read back per block in the second pass
BLOCK_ROWS = 16_384


def usable(trace: Any) -> np.ndarray:
    """Updates that count for convergence and the steady state, shape ``(len(trace),)``.

    Accepted, holding a model and from a trusted window, for every equation (traces
    without a ``trusted`` column: accepted and holding a model).

    Parameters
    ----------
    trace : Trace
        A CLPC trace.

    Returns
    -------
    ndarray of bool, shape (n_updates,)
    """
    arrays = trace.arrays
    ok = arrays["accepted"].all(axis=1) & arrays["has_model"].all(axis=1)
    trusted = arrays.get("trusted")
    if trusted is not None:
        ok = ok & trusted.all(axis=1)
    return np.asarray(ok, dtype=bool)


def sequential_sum(rows: np.ndarray, total: np.ndarray | None = None) -> np.ndarray | None:
    """``total + rows[0] + rows[1] + ...``, added strictly in this order.

    A running sum (``cumsum``, never numpy's pairwise summation), so a sum over parts
    equals the sum over the whole bit for bit wherever the parts are cut; ``None`` when
    there is nothing to add.
    """
    if rows.shape[0] == 0:
        return total
    if total is not None:
        rows = np.concatenate([total[None], rows])
    return np.cumsum(rows, axis=0)[-1]


def sequential_mean(rows: np.ndarray) -> np.ndarray:
    """Mean along the first axis from :func:`sequential_sum` (``rows`` not empty)."""
    return np.asarray(sequential_sum(rows)) / rows.shape[0]


class RowSpill:
    """Rows of ``theta`` (E, p) and ``D`` (E,) appended in order and read back in blocks.

    In memory (``folder=None``) or in two raw float64 files in a temporary folder under
    ``folder``, removed by :meth:`close`.

    Parameters
    ----------
    folder : Path, optional
        Where the scratch folder is made (e.g. beside the output); ``None`` keeps the rows
        in memory (an in-memory trace is there already).
    """

    def __init__(self, folder: Path | None = None) -> None:
        self._parts: list[tuple[np.ndarray, np.ndarray]] = []
        self._dir = None if folder is None else tempfile.TemporaryDirectory(dir=folder)
        self._shape: tuple[int, ...] | None = None
        self.rows = 0

    def append(self, theta: np.ndarray, d: np.ndarray) -> None:
        """Append rows: ``theta`` of shape (m, E, p), ``d`` of shape (m, E)."""
        if theta.shape[0] == 0:
            return
        self._shape = theta.shape[1:]
        self.rows += theta.shape[0]
        if self._dir is None:
            self._parts.append((theta.copy(), d.copy()))
            return
        base = Path(self._dir.name)
        with open(base / "theta.bin", "ab") as ft, open(base / "d.bin", "ab") as fd:
            np.ascontiguousarray(theta, dtype=np.float64).tofile(ft)
            np.ascontiguousarray(d, dtype=np.float64).tofile(fd)

    def blocks(self) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """The rows in order, as ``(theta, d)`` blocks of at most :data:`BLOCK_ROWS`."""
        if self._dir is None or self._shape is None:
            yield from self._parts
            return
        shape = self._shape
        width = int(np.prod(shape))
        base = Path(self._dir.name)
        with open(base / "theta.bin", "rb") as ft, open(base / "d.bin", "rb") as fd:
            while True:
                theta = np.fromfile(ft, dtype=np.float64, count=BLOCK_ROWS * width)
                if theta.size == 0:
                    return
                m = theta.size // width
                yield (
                    theta.reshape(m, *shape),
                    np.fromfile(fd, np.float64, m * shape[0]).reshape(m, shape[0]),
                )

    def close(self) -> None:
        """Remove the scratch files (nothing in memory mode)."""
        self._parts = []
        if self._dir is not None:
            self._dir.cleanup()


class ScanState:
    """The convergence search over updates fed in order, and the sums after its start.

    Parameters
    ----------
    theta_tol, D_tol : float
        Tolerances of :meth:`clpc.Trace.convergence`.
    consecutive : int
        Quasi-constant updates in a row that make convergence.
    spill : RowSpill
        Where the rows after the start go for the second pass.
    """

    def __init__(self, theta_tol: float, D_tol: float, consecutive: int, spill: RowSpill):
        self.theta_tol, self.D_tol, self.consecutive = theta_tol, D_tol, consecutive
        self.spill = spill
        self.n = 0
        self.trusted: int | None = None  # None: the trace has no trusted column
        self.start = -1  # global row of the convergence point (-1: not found)
        self.start_at: tuple[int, float] = (-1, float("nan"))  # its sample index and time
        self._run = 0  # quasi-constant updates in a row ending at the last row
        self._prev: tuple[bool, np.ndarray, np.ndarray] | None = None
        self._recent: dict[str, np.ndarray] = {}  # the last `consecutive` rows
        self.sums: dict[str, np.ndarray | None] = {"theta": None, "D": None, "c": None}
        self.used = 0  # usable updates from the start on
        self.last_usable: tuple[np.ndarray, np.ndarray] | None = None  # (theta, c)
        self.last_model: tuple[np.ndarray, np.ndarray] | None = None
        self.n_usable = 0
        self.n_model = 0

    def add(self, part: Any) -> None:
        """Feed the next updates (a :class:`clpc.Trace` part, in time order)."""
        m = len(part)
        if m == 0:
            return
        a = part.arrays
        acc = usable(part)
        theta, d, c = a["theta"], a["D"], a["c"]
        model = np.asarray(a["accepted"].all(axis=1) & a["has_model"].all(axis=1), dtype=bool)
        if "trusted" in a:
            self.trusted = (self.trusted or 0) + int(a["trusted"].all(axis=1).sum())
        self._fallbacks(acc, model, theta, c)
        rows = {"theta": theta, "D": d, "c": c, "acc": acc}
        rows["index"], rows["time"] = np.asarray(part.index), np.asarray(part.time, dtype=float)
        if self.start < 0:  # the quiet updates matter until the convergence point is found
            self._search(self._quiet(acc, theta, d), rows)
        else:
            self._accumulate(rows)
        self.n += m

    def _fallbacks(self, acc: np.ndarray, model: np.ndarray, theta: Any, c: Any) -> None:
        """The last usable update, and the last accepted one with a model."""
        self.n_usable += int(acc.sum())
        self.n_model += int(model.sum())
        if acc.any():
            k = int(np.flatnonzero(acc)[-1])
            self.last_usable = (theta[k].copy(), c[k].copy())
        if model.any():
            k = int(np.flatnonzero(model)[-1])
            self.last_model = (theta[k].copy(), c[k].copy())

    def _quiet(self, acc: np.ndarray, theta: np.ndarray, d: np.ndarray) -> np.ndarray:
        """Updates that moved less than the tolerances since the previous one (both usable)."""
        quiet = np.zeros(acc.shape[0], dtype=bool)
        if self._prev is None:
            prev_acc, prev_theta, prev_d = acc[:-1], theta[:-1], d[:-1]
            first = 1
        else:
            p_acc, p_theta, p_d = self._prev
            prev_acc = np.concatenate([[p_acc], acc[:-1]])
            prev_theta = np.concatenate([p_theta[None], theta[:-1]])
            prev_d = np.concatenate([p_d[None], d[:-1]])
            first = 0
        cur = slice(first, None)
        dtheta = np.linalg.norm(theta[cur] - prev_theta, axis=2).max(axis=1)
        scale = np.maximum(np.abs(d[cur]), np.finfo(float).tiny)
        with np.errstate(over="ignore"):  # D = 0 (a degenerate window): inf, not quiet
            dd = (np.abs(d[cur] - prev_d) / scale).max(axis=1)
        quiet[cur] = acc[cur] & prev_acc & (dtheta < self.theta_tol) & (dd < self.D_tol)
        self._prev = (bool(acc[-1]), theta[-1].copy(), d[-1].copy())
        return quiet

    def _search(self, quiet: np.ndarray, rows: dict[str, np.ndarray]) -> None:
        """Look for ``consecutive`` quiet updates in a row; from there on, accumulate."""
        k = self.consecutive
        run = self._run
        for j, q in enumerate(quiet.tolist()):
            run = run + 1 if q else 0
            if run == k:
                self.start = self.n + j - k + 1
                kept = {
                    key: np.concatenate([self._recent.get(key, v[:0]), v])
                    for key, v in rows.items()
                }
                offset = self.start - (self.n - self._recent_len())
                self.start_at = (int(kept["index"][offset]), float(kept["time"][offset]))
                self._accumulate({key: v[offset:] for key, v in kept.items()})
                self._recent = {}
                return
        self._run = run
        both = {
            key: np.concatenate([self._recent.get(key, v[:0]), v])[-k:] for key, v in rows.items()
        }
        self._recent = both

    def mean(self, key: str) -> np.ndarray:
        """Mean of ``key`` (``"theta"``, ``"D"``, ``"c"``) of the usable updates after the start.

        The same as :func:`sequential_mean` of the rows, bit for bit.
        """
        total = self.sums[key]
        if total is None or not self.used:
            raise ValueError("no usable update after the convergence point")
        return np.asarray(total / self.used)

    def _recent_len(self) -> int:
        return int(self._recent["acc"].shape[0]) if self._recent else 0

    def _accumulate(self, rows: dict[str, np.ndarray]) -> None:
        """Add the usable rows to the sums and the spill."""
        acc = rows["acc"]
        for key in ("theta", "D", "c"):
            self.sums[key] = sequential_sum(rows[key][acc], self.sums[key])
        self.used += int(acc.sum())
        self.spill.append(rows["theta"][acc], rows["D"][acc])
