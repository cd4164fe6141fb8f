"""How one long record is cut into pieces that workers appraise on their own.

The appraiser's update ``j`` (1-based) closes after lag row ``e = C j`` and solves the rows
``[max(0, e - W), e)``; lag row ``r`` holds the decimated samples ``r .. r + m`` (``m``: the
largest lag). The kernel summarises rows in blocks ``[l C, (l + 1) C)`` at absolute positions
and adds the part of a block a window starts in on its own (:mod:`clpc.appraiser.kernel`), so
a window's numbers depend on its rows only, never on where a batch of windows starts.

A piece is a run of consecutive updates ``j_lo .. j_hi``. Its worker reads the decimated
samples from the start of the block holding the first window's first row,
``C floor(max(0, C j_lo - W) / C)``, to the newest sample of the last window,
``C j_hi + m - 1``: an overlap with the previous piece of at most ``W + m - 1`` samples (the
window, the lags, and the cluster phase that aligns the first block). With decimation
(factor ``f``), decimated sample ``k`` is raw sample ``k f`` filtered from the record's start;
a piece starts its filter :func:`warmup` raw samples earlier (see that function).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import NamedTuple

__all__ = ["Layout", "Piece", "warmup"]

#: the filter's start-up is forgotten to below this fraction of the signal
FORGOTTEN = 1e-20


@functools.cache
def warmup(factor: int) -> int:
    """Raw samples a piece's decimation filter runs before its first kept sample.

    The anti-alias filter (:func:`clpc.appraiser.decimation.decimation_filter`) is recursive:
    its state at raw sample ``a`` depends on every sample before it. A piece starts the
    filter at rest ``warmup(f)`` samples before ``a`` (a multiple of ``f``, so that the same
    samples are kept); the start-up's effect then decays as ``r ** n`` (``r``: the largest
    pole radius) to below :data:`FORGOTTEN`. What remains is rounding: the kept samples
    agree with the single-process filter's to a few units in the last place, not bit for bit.

    Parameters
    ----------
    factor : int
        Decimation factor (1: no filter, no warm-up).

    Returns
    -------
    int
        Raw samples, a multiple of ``factor`` (0 for ``factor == 1``).
    """
    if factor == 1:
        return 0
    from scipy import signal  # imported when used: scipy.signal costs ~0.8 s

    from clpc.appraiser.decimation import decimation_filter

    _, poles, _ = signal.sos2zpk(decimation_filter(factor))
    radius = float(max(abs(poles)))
    # 4 poles of nearly equal radius: the decay is ~ n^3 r^n; twice the plain r^n count
    n = 2 * math.ceil(math.log(FORGOTTEN) / math.log(radius))
    return -(-n // factor) * factor


class Piece(NamedTuple):
    """One piece of a record: updates ``j_lo .. j_hi`` and the samples they need.

    ``kept = (k_lo, k_hi)``: decimated samples ``k_lo .. k_hi - 1``; ``raw = (lo, hi)``: the
    raw samples read (the warm-up included); the piece's kept samples are raw samples
    ``k_lo f, (k_lo + 1) f, ...``.
    """

    number: int
    j_lo: int
    j_hi: int
    kept: tuple[int, int]
    raw: tuple[int, int]

    @property
    def updates(self) -> int:
        """Updates of the piece."""
        return self.j_hi - self.j_lo + 1


@dataclass(frozen=True)
class Layout:
    """A record's windows: sizes, largest lag and decimation.

    Parameters
    ----------
    window, cluster : int
        ``W`` and ``C`` of the appraiser.
    max_lag : int
        ``m``, the largest lag of a lag row.
    factor : int
        Decimation factor (1: none).
    """

    window: int
    cluster: int
    max_lag: int
    factor: int = 1

    def kept(self, n_raw: int) -> int:
        """Decimated samples of a record of ``n_raw`` samples (raw ``0, f, 2f, ...``)."""
        return 0 if n_raw <= 0 else (n_raw - 1) // self.factor + 1

    def updates(self, n_raw: int) -> int:
        """Updates of a record of ``n_raw`` samples."""
        return max(self.kept(n_raw) - self.max_lag, 0) // self.cluster

    def first_sample(self, j_lo: int) -> int:
        """First decimated sample that updates ``j_lo ..`` read (block-aligned window start)."""
        c = self.cluster
        return max(0, c * j_lo - self.window) // c * c

    def piece(self, number: int, updates: tuple[int, int], n_raw: int) -> Piece:
        """The piece of updates ``updates = (j_lo, j_hi)`` of a record of ``n_raw`` samples."""
        j_lo, j_hi = updates
        f = self.factor
        k_lo = self.first_sample(j_lo)
        k_hi = self.cluster * j_hi + self.max_lag
        raw_lo = max(0, k_lo * f - warmup(f))
        raw_hi = min(n_raw, (k_hi - 1) * f + 1)
        return Piece(number, j_lo, j_hi, (k_lo, k_hi), (raw_lo, raw_hi))

    def pieces(self, n_raw: int, piece_samples: int) -> list[Piece]:
        """Pieces of about ``piece_samples`` decimated samples covering every update.

        Parameters
        ----------
        n_raw : int
            Raw samples of the record.
        piece_samples : int
            New decimated samples per piece (at least one cluster's worth is used).

        Returns
        -------
        list of Piece
            In time order; empty when the record has no update.
        """
        total = self.updates(n_raw)
        per = max(1, piece_samples // self.cluster)
        return [
            self.piece(i, (j, min(j + per - 1, total)), n_raw)
            for i, j in enumerate(range(1, total + 1, per))
        ]
