"""A bounded, evenly thinned copy of a growing trace (for figures and summaries)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from clpc.appraiser.trace import Trace

__all__ = ["ThinnedTrace"]


class ThinnedTrace:
    """Keep a bounded, evenly thinned copy of a growing trace.

    Parameters
    ----------
    max_updates : int
        Updates are kept one in ``stride``; when more than ``2 * max_updates`` are held the
        stride doubles and every other kept update is dropped.
    """

    def __init__(self, max_updates: int = 20_000) -> None:
        if max_updates < 1:
            raise ValueError(f"max_updates must be >= 1; got {max_updates}.")
        self.max_updates = int(max_updates)
        self.stride = 1
        self.seen = 0
        self._parts: list[Trace] = []
        self._held = 0

    def add(self, part: Trace) -> None:
        """Take the updates of ``part`` whose running number is a multiple of ``stride``."""
        n = len(part)
        if not n:
            return
        numbers = self.seen + np.arange(n)
        self.seen += n
        keep = np.flatnonzero(numbers % self.stride == 0)
        if keep.size:
            self._parts.append(part.take(keep))
            self._held += keep.size
        while self._held > 2 * self.max_updates:
            self._thin()

    def _thin(self) -> None:
        merged = Trace.concat(self._parts)
        # kept updates are numbered 0, s, 2s, ...: keep the multiples of 2s
        self.stride *= 2
        merged = merged.take(np.arange(0, len(merged), 2))
        self._parts = [merged]
        self._held = len(merged)

    def trace(self) -> Trace:
        """The thinned trace (every ``stride``-th update)."""
        merged = Trace.concat(self._parts)
        meta = dict(merged.meta, thinned_stride=self.stride, updates_total=self.seen)
        return replace(merged, meta=meta)
