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

    Parameters
    ----------
    n_columns : int
        Inputs plus outputs.
    """

    def __init__(self, n_columns: int) -> None:
        self.data = np.empty((0, n_columns))
        self.start = 0
        self.pending: list[Any] = []  # samples kept aside by step(): arrays or (u, y)

    def flush(self) -> None:
        """Move the samples kept aside into ``data``."""
        if self.pending:
            block = np.array(self.pending, dtype=np.float64).reshape(len(self.pending), -1)
            self.pending = []
            self.append(block)

    def append(self, new: np.ndarray) -> None:
        """Append decimated samples (after the pending ones)."""
        self.flush()
        self.data = np.vstack([self.data, new]) if self.data.size else new.copy()

    def take_pending(self) -> np.ndarray:
        """The samples kept aside, as an array, removed from ``pending``."""
        block = np.array(self.pending, dtype=np.float64).reshape(len(self.pending), -1)
        self.pending = []
        return block

    def drop_before(self, sample: int) -> None:
        """Forget samples older than absolute index ``sample``."""
        drop = sample - self.start
        if drop > 0:
            self.data = self.data[drop:].copy()
            self.start = sample

    def since(self, sample: int) -> np.ndarray:
        """Samples from absolute index ``sample`` on (a view)."""
        self.flush()
        return self.data[max(sample - self.start, 0) :]
