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
        # per sample and channel: the smallest nonzero change of the channel so far (its
        # quantization step as far as the record shows; inf before any change)
        self.resolution = np.empty((0, n_columns))
        self.start = 0
        self.pending: list[Any] = []  # samples kept aside by step(): arrays or (u, y)
        self.last: np.ndarray | None = None  # the newest sample ever appended
        self.step = np.full(n_columns, np.inf)  # the running smallest nonzero change

    def flush(self) -> None:
        """Move the samples kept aside into ``data``."""
        if self.pending:
            block = np.array(self.pending, dtype=np.float64).reshape(len(self.pending), -1)
            self.pending = []
            self.append(block)

    def append(self, new: np.ndarray) -> None:
        """Append decimated samples (after the pending ones)."""
        self.flush()
        self.resolution = _stack(self.resolution, self._steps(new))
        self.data = _stack(self.data, new)

    def _steps(self, new: np.ndarray) -> np.ndarray:
        """Running smallest nonzero change per channel at each new sample."""
        prev = new[:1] if self.last is None else self.last[None, :]
        change = np.abs(np.diff(np.vstack([prev, new]), axis=0))
        change[~(change > 0)] = np.inf
        change[0] = np.minimum(change[0], self.step)
        steps = np.minimum.accumulate(change, axis=0)
        self.step = steps[-1].copy()
        self.last = new[-1].copy()
        return steps

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
            self.resolution = self.resolution[drop:].copy()
            self.start = sample

    def since(self, sample: int) -> np.ndarray:
        """Samples from absolute index ``sample`` on (a view)."""
        self.flush()
        return self.data[max(sample - self.start, 0) :]


def _stack(old: np.ndarray, new: np.ndarray) -> np.ndarray:
    return np.vstack([old, new]) if old.size else new.copy()
