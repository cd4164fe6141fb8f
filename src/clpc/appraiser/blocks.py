r"""The statistics of a CLPC window's pieces: blocks, tail and head, the cache.

Plain ``numba.njit(cache=True)`` functions called by :func:`clpc.appraiser.kernel.solve_windows`
(with ``NUMBA_DISABLE_JIT=1`` they run as plain Python). Lag rows are cut into blocks
``[k B, (k + 1) B)`` aligned to absolute row numbers (``docs/clpc.md``); a window is::

    tail: rows of s's block  +  the full blocks  +  head: rows of e's block before e
    \_ computed per window _/    \_ once per block _/   \_____ computed per window ____/

Each piece is summarised by its count, mean and centered scatter (two-pass,
:func:`piece_stats`; merged by :mod:`clpc.appraiser.segments`, the tail and head chained
row by row by :mod:`clpc.appraiser.row_sums` when ``C < B``). Every term is centered, so
offsets (positions around 1e4 rad) and long records lose no digits. A block's statistics
are a function of its rows alone, so the blocks an earlier call summarised are reused bit
for bit (:class:`BlockCache`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

__all__ = ["BlockCache", "gather_blocks", "new_cache", "piece_stats", "piece_step"]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def piece_stats(
    samples: np.ndarray,
    chan: np.ndarray,
    lag: np.ndarray,
    first: int,
    rows: tuple[int, int],
    z: np.ndarray,
    out: tuple[np.ndarray, np.ndarray],
) -> None:
    """Mean and centered scatter (two-pass) of lag rows ``rows[0] .. rows[1] - 1``.

    Row ``r`` is the lag vector whose newest sample is ``samples[first + r]``, gathered once
    into ``z`` (at least ``rows[1] - rows[0]`` rows of ``p``) and centered there; ``out =
    (mean (p,), scat (p, p))``. The scatter is accumulated row by row over whole rows of
    ``scat`` (the inner loop vectorises); ``z_a z_b = z_b z_a`` keeps it exactly symmetric.
    """
    lo, hi = rows
    mean, scat = out
    p = mean.shape[0]
    n = hi - lo
    for a in range(p):
        mean[a] = 0.0
        for b in range(p):
            scat[a, b] = 0.0
    for r in range(n):
        for a in range(p):
            value = samples[first + lo + r - lag[a], chan[a]]
            z[r, a] = value
            mean[a] += value
    for a in range(p):
        mean[a] /= n
    for r in range(n):
        for a in range(p):
            z[r, a] -= mean[a]
        for a in range(p):
            z_a = z[r, a]
            for b in range(p):
                scat[a, b] += z_a * z[r, b]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def piece_step(samples: np.ndarray, channel: int, first: int, rows: tuple[int, int]) -> float:
    """The smallest nonzero change of one channel over the newest samples of rows ``rows``.

    Its quantization step as far as the piece shows (``inf`` when it does not change):
    row ``r``'s newest sample ``samples[first + r]`` against the one before it.
    """
    lo, hi = rows
    best = math.inf
    for r in range(lo, hi):
        d = abs(samples[first + r, channel] - samples[first + r - 1, channel])
        if d > 0 and d < best:
            best = d
    return best


class BlockCache(NamedTuple):
    """Statistics of the newest blocks, kept between kernel calls (see :func:`new_cache`).

    A block's statistics are a function of its rows alone, so a block summarised by an
    earlier call is reused bit for bit: ``step`` then summarises one new block per update
    instead of the whole window. Blocks ``span[0] .. span[1] - 1`` are held, block ``k``
    at ring position ``k % M`` (``M`` = the second axis; 0: no cache).
    """

    mean: np.ndarray  #: (E, M, p)
    scat: np.ndarray  #: (E, M, p, p)
    step: np.ndarray  #: (E, M)
    span: np.ndarray  #: (2,) int64


def new_cache(shape: tuple[int, int], ring: int) -> BlockCache:
    """An empty :class:`BlockCache` of ``ring`` blocks per equation (0: caching off).

    ``shape = (E, p)``: equations and parameters per equation.
    """
    n_eq, p = shape
    return BlockCache(
        np.zeros((n_eq, ring, p)),
        np.zeros((n_eq, ring, p, p)),
        np.zeros((n_eq, ring)),
        np.zeros(2, np.int64),
    )


@numba.njit(cache=True, nogil=True, error_model="numpy")
def gather_blocks(
    samples: np.ndarray,
    where: tuple[np.ndarray, np.ndarray, int, int, int, int],
    cache: tuple[np.ndarray, np.ndarray, np.ndarray, int, int],
    z: np.ndarray,
    blocks: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> None:
    """Statistics of blocks ``b_lo .. b_lo + n - 1`` of one equation, from the cache or rows.

    ``where = (chan, lag, first, b_lo, n, size)``; ``cache = (mean (M, p), scat (M, p, p),
    step (M,), lo, hi)``: one equation's ring and the blocks it holds; ``blocks = (b_mean,
    b_scat, b_step)``. The newest ``min(n, M)`` blocks are written back into the ring.
    """
    chan, lag, first, b_lo, n, size = where
    c_mean, c_scat, c_step, c_lo, c_hi = cache
    b_mean, b_scat, b_step = blocks
    ring = c_mean.shape[0]
    p = c_mean.shape[1]
    for b in range(n):
        k = b_lo + b
        if c_lo <= k < c_hi:
            pos = k % ring
            for a in range(p):
                b_mean[b, a] = c_mean[pos, a]
                for c in range(p):
                    b_scat[b, a, c] = c_scat[pos, a, c]
            b_step[b] = c_step[pos]
        else:
            lo = k * size
            piece_stats(samples, chan, lag, first, (lo, lo + size), z, (b_mean[b], b_scat[b]))
            b_step[b] = piece_step(samples, chan[0], first, (lo, lo + size))
    if ring == 0:
        return
    for b in range(max(0, n - ring), n):
        pos = (b_lo + b) % ring
        for a in range(p):
            c_mean[pos, a] = b_mean[b, a]
            for c in range(p):
                c_scat[pos, a, c] = b_scat[b, a, c]
        c_step[pos] = b_step[b]
