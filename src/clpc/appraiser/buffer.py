"""The appraiser's sample buffer: the samples the next windows need, nothing older.

Samples are kept as rows ``[u | y]`` after decimation; ``start`` is the absolute index of
the first kept sample. :meth:`clpc.CLPC.step` keeps scalar samples aside in ``pending``
(plain floats, no array work) until an update needs them.
"""

from __future__ import annotations

import numpy as np

__all__ = ["SampleBuffer"]


class SampleBuffer:
    """Decimated samples from absolute index ``start`` on.

    The samples live in a store with spare rows at the end: appending copies the new rows
    into it and forgetting old ones moves a pointer, so an update costs no reallocation
    (the live rows are moved to the front only when the spare rows run out).

    Parameters
    ----------
    n_columns : int
        Inputs plus outputs.
    """

    def __init__(self, n_columns: int) -> None:
        self._use(np.empty((0, n_columns)), 0, 0)
        self.start = 0
        #: the values of samples kept aside by step(), row after row (plain floats)
        self.pending: list[float] = []

    def _use(self, store: np.ndarray, lo: int, hi: int) -> None:
        """Keep the samples in ``store`` (C-contiguous), live rows ``lo .. hi - 1``."""
        self._store = store
        self._flat = store.reshape(-1)  # the same memory, one value after another
        self._lo, self._hi = lo, hi

    @property
    def data(self) -> np.ndarray:
        """The live samples (a C-contiguous view), shape (n, channels)."""
        return self._store[self._lo : self._hi]

    @data.setter
    def data(self, values: np.ndarray) -> None:
        store = np.array(values, dtype=np.float64, order="C")
        self._use(store, 0, store.shape[0])

    def flush(self) -> None:
        """Move the samples kept aside into ``data`` (their values copied straight in)."""
        pending = self.pending
        if pending:
            n_columns = self._store.shape[1]
            n = len(pending) // n_columns
            self._reserve(n)
            at = self._hi * n_columns
            self._flat[at : at + len(pending)] = pending
            self._hi += n
            self.pending = []

    def flushed(self) -> tuple[np.ndarray, int]:
        """:meth:`flush`, then the whole store and the absolute index of its first row.

        The store holds the live rows (and rows forgotten or not yet written around them,
        never to be read): a kernel reading sample ``k`` at row ``k - index`` needs no view.
        """
        self.flush()
        return self._store, self.start - self._lo

    def append(self, new: np.ndarray) -> None:
        """Append decimated samples (after the pending ones)."""
        self.flush()
        n = new.shape[0]
        self._reserve(n)
        self._store[self._hi : self._hi + n] = new
        self._hi += n

    def _reserve(self, n: int) -> None:
        """Room for ``n`` more rows after the live ones (moved to the front if needed)."""
        if self._hi + n > self._store.shape[0]:
            live = self._hi - self._lo
            if live + n <= self._store.shape[0]:  # room at the front: the live rows move there
                store = self._store
                store[:live] = store[self._lo : self._hi].copy()  # (they may overlap)
            else:
                store = np.empty((2 * (live + n), self._store.shape[1]))
                store[:live] = self._store[self._lo : self._hi]
            self._use(store, 0, live)

    def drop_before(self, sample: int) -> None:
        """Forget samples older than absolute index ``sample``."""
        drop = sample - self.start
        if drop > 0:
            self._lo = min(self._lo + drop, self._hi)
            self.start = sample

    def since(self, sample: int) -> np.ndarray:
        """Samples from absolute index ``sample`` on (a view)."""
        self.flush()
        return self.data[max(sample - self.start, 0) :]
