"""The appraiser's sample buffer: the samples the next windows need, nothing older.

Samples are kept as rows ``[u | y]`` after decimation; ``start`` is the absolute index of
the first kept sample. :meth:`clpc.CLPC.step` keeps scalar samples aside in ``pending``
(plain floats, no array work) until an update needs them.
"""

from __future__ import annotations

from typing import Any

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
        self._store = np.empty((0, n_columns))
        self._lo = 0  # live rows are _store[_lo:_hi]
        self._hi = 0
        self.start = 0
        self.pending: list[Any] = []  # samples kept aside by step(): arrays or (u, y)

    @property
    def data(self) -> np.ndarray:
        """The live samples (a C-contiguous view), shape (n, channels)."""
        return self._store[self._lo : self._hi]

    @data.setter
    def data(self, values: np.ndarray) -> None:
        self._store = np.array(values, dtype=np.float64, order="C")
        self._lo, self._hi = 0, self._store.shape[0]

    def flush(self) -> None:
        """Move the samples kept aside into ``data``."""
        if self.pending:
            self.append(self.take_pending())

    def append(self, new: np.ndarray) -> None:
        """Append decimated samples (after the pending ones)."""
        self.flush()
        n = new.shape[0]
        if self._hi + n > self._store.shape[0]:
            live = self._hi - self._lo
            store = np.empty((2 * (live + n), new.shape[1]))
            store[:live] = self._store[self._lo : self._hi]
            self._store, self._lo, self._hi = store, 0, live
        self._store[self._hi : self._hi + n] = new
        self._hi += n

    def take_pending(self) -> np.ndarray:
        """The samples kept aside, as an array, removed from ``pending``."""
        block = np.array(self.pending, dtype=np.float64).reshape(len(self.pending), -1)
        self.pending = []
        return block

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
