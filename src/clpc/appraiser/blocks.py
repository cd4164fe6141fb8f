r"""The statistics of a CLPC window's pieces: blocks, tails, the exact merge, the block cache.

Plain ``numba.njit(cache=True)`` functions called by :func:`clpc.appraiser.kernel.solve_windows`
(with ``NUMBA_DISABLE_JIT=1`` they run as plain Python). Lag rows are cut into blocks
``[k B, (k + 1) B)`` aligned to absolute row numbers (``docs/clpc.md``); a window is::

    tail  +  full blocks  +  head

Each piece is summarised by its count, mean and centered scatter (two-pass,
:func:`piece_stats`), and pieces are merged with the formula of Chan, Golub and LeVeque
(:func:`merge`)::

    n = sum n_k,   mean = sum n_k mean_k / n,
    A = sum A_k + sum n_k (mean_k - mean)(mean_k - mean)^T

When ``B = C`` every slid window starts at the same offset ``o = (-W) mod B`` inside a
block, so its tail is always the block's *suffix* ``[k B + o, (k + 1) B)``
(:func:`tail_split`). A block is then summarised as its prefix ``[k B, k B + o)`` and its
suffix, merged: each row is read once per window instead of twice (once in its block, once
more in the next window's tail). Everything is a function of the rows alone, never of how a
record was chunked, so ``run``, ``push``, ``step`` and pieces solved on other workers give the
same bits.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

__all__ = [
    "BlockCache",
    "gather_blocks",
    "merge",
    "new_cache",
    "piece_stats",
    "piece_step",
    "tail_split",
]


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

    Row ``r`` is the lag vector whose newest sample is ``samples[first + r]``, built on the
    fly into ``z``; ``out = (mean (p,), scat (p, p))``.
    """
    lo, hi = rows
    mean, scat = out
    p = mean.shape[0]
    n = hi - lo
    for a in range(p):
        mean[a] = 0.0
        for b in range(a + 1):
            scat[a, b] = 0.0
    for r in range(lo, hi):
        for a in range(p):
            mean[a] += samples[first + r - lag[a], chan[a]]
    for a in range(p):
        mean[a] /= n
    for r in range(lo, hi):
        for a in range(p):
            z[a] = samples[first + r - lag[a], chan[a]] - mean[a]
        for a in range(p):
            for b in range(a + 1):
                scat[a, b] += z[a] * z[b]
    for a in range(p):
        for b in range(a):
            scat[b, a] = scat[a, b]


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


@numba.njit(cache=True, nogil=True, error_model="numpy")
def merge(
    blocks: tuple[np.ndarray, np.ndarray, int, int, int],
    pieces: tuple[int, np.ndarray, np.ndarray, int, np.ndarray, np.ndarray],
    dev: np.ndarray,
    out: tuple[np.ndarray, np.ndarray],
) -> float:
    """Merge full blocks, a tail and a head piece into one window (Chan, Golub and LeVeque).

    ``blocks = (b_mean (n, p), b_scat (n, p, p), lo, hi, size)``: blocks ``lo .. hi - 1``
    of ``size`` rows; ``pieces = (t_size, t_mean, t_scat, h_size, h_mean, h_scat)``: the
    tail (the rows before the first full block) and the head (the rows after the last);
    a piece of size 0 is skipped. ``dev`` work space (pieces, p); ``out = (mean, scat)``.
    Returns the row count.
    """
    b_mean, b_scat, lo, hi, size = blocks
    t_size, t_mean, t_scat, h_size, h_mean, h_scat = pieces
    mean, scat = out
    p = mean.shape[0]
    total = t_size + size * (hi - lo) + h_size
    for a in range(p):
        acc = t_size * t_mean[a] if t_size > 0 else 0.0
        for k in range(lo, hi):
            acc += size * b_mean[k, a]
        if h_size > 0:
            acc += h_size * h_mean[a]
        mean[a] = acc / total
    root = math.sqrt(size)
    t_root = math.sqrt(t_size)
    n_dev = hi - lo + 1
    for a in range(p):
        dev[0, a] = t_root * (t_mean[a] - mean[a]) if t_size > 0 else 0.0
        for k in range(lo, hi):
            dev[k - lo + 1, a] = root * (b_mean[k, a] - mean[a])
        if h_size > 0:
            dev[n_dev, a] = math.sqrt(h_size) * (h_mean[a] - mean[a])
    if h_size > 0:
        n_dev += 1
    for a in range(p):
        for b in range(a + 1):
            acc = t_scat[a, b] if t_size > 0 else 0.0
            for k in range(lo, hi):
                acc += b_scat[k, a, b]
            if h_size > 0:
                acc += h_scat[a, b]
            for k in range(n_dev):
                acc += dev[k, a] * dev[k, b]
            scat[a, b] = acc
            scat[b, a] = acc
    return float(total)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def tail_split(window: int, cluster: int, size: int) -> int:
    """Where a slid window's tail starts inside its block: ``(-W) mod B``, or 0.

    Only when ``B = C`` do all windows start at one offset (update ``j`` starts at row
    ``C j - W``); 0 means there is no fixed split (``B != C``, or ``W`` a multiple of
    ``B``: no tail at all) and tails are summarised per window.
    """
    if size != cluster:
        return 0
    return (-window) % size


class BlockCache(NamedTuple):
    """Statistics of the newest blocks, kept between kernel calls (see :func:`new_cache`).

    A block's statistics are a function of its rows alone, so a block summarised by an
    earlier call is reused bit for bit: ``step`` then summarises one new block per update
    instead of the whole window. Blocks ``span[0] .. span[1] - 1`` are held, block ``k``
    at ring position ``k % M`` (``M`` = the second axis; 0: no cache), with its suffix
    from :func:`tail_split` on (the next windows' tail; unused without a split).
    """

    mean: np.ndarray  #: (E, M, p)
    scat: np.ndarray  #: (E, M, p, p)
    step: np.ndarray  #: (E, M)
    span: np.ndarray  #: (2,) int64
    tail_mean: np.ndarray  #: (E, M, p)
    tail_scat: np.ndarray  #: (E, M, p, p)
    tail_step: np.ndarray  #: (E, M)


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
        np.zeros((n_eq, ring, p)),
        np.zeros((n_eq, ring, p, p)),
        np.zeros((n_eq, ring)),
    )


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _copy_piece(
    src: tuple[np.ndarray, np.ndarray, float], dest: tuple[np.ndarray, np.ndarray]
) -> float:
    """Copy a piece's mean (p,) and scatter (p, p); returns its step."""
    s_mean, s_scat, step = src
    d_mean, d_scat = dest
    p = s_mean.shape[0]
    for a in range(p):
        d_mean[a] = s_mean[a]
        for c in range(p):
            d_scat[a, c] = s_scat[a, c]
    return step


@numba.njit(cache=True, nogil=True, error_model="numpy")
def gather_blocks(
    samples: np.ndarray,
    where: tuple[np.ndarray, np.ndarray, int, int, int, int, int],
    cache: tuple[np.ndarray, ...],
    work: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    blocks: tuple[np.ndarray, ...],
) -> None:
    """Statistics of blocks ``b_lo .. b_lo + n - 1`` of one equation, from the cache or rows.

    ``where = (chan, lag, first, b_lo, n, size, split)`` (``split`` from
    :func:`tail_split`); ``cache = (mean (M, p), scat (M, p, p), step (M,), tail_mean,
    tail_scat, tail_step, lo, hi)``: one equation's ring and the blocks it holds;
    ``work = (z (p,), dev (>= 2, p), pre_mean (p,), pre_scat (p, p))``; ``blocks = (b_mean
    (n, p), b_scat (n, p, p), b_step (n,), t_mean (n + 1, p), t_scat (n + 1, p, p), t_step
    (n + 1,))``. With ``split > 0`` a block is its prefix and its suffix merged, and the
    suffixes of blocks ``b_lo - 1 .. b_lo + n - 1`` go to ``t_*`` (index ``k - b_lo + 1``;
    block ``b_lo - 1``'s alone: its prefix may be gone). The newest ``min(n, M)`` blocks
    are written back into the ring.
    """
    chan, lag, first, b_lo, n, size, split = where
    c_mean, c_scat, c_step, c_tmean, c_tscat, c_tstep, c_lo, c_hi = cache
    b_mean, b_scat, b_step, t_mean, t_scat, t_step = blocks
    z, dev, pre_mean, pre_scat = work
    ring = c_mean.shape[0]
    lowest = -1 if split > 0 and b_lo > 0 else 0
    for b in range(lowest, n):
        k = b_lo + b
        if c_lo <= k < c_hi:
            pos = k % ring
            if split > 0:
                t_step[b + 1] = _copy_piece(
                    (c_tmean[pos], c_tscat[pos], c_tstep[pos]), (t_mean[b + 1], t_scat[b + 1])
                )
            if b >= 0:
                b_step[b] = _copy_piece(
                    (c_mean[pos], c_scat[pos], c_step[pos]), (b_mean[b], b_scat[b])
                )
            continue
        lo = k * size
        if split == 0:
            piece_stats(samples, chan, lag, first, (lo, lo + size), z, (b_mean[b], b_scat[b]))
            b_step[b] = piece_step(samples, chan[0], first, (lo, lo + size))
            continue
        mid = lo + split
        piece_stats(samples, chan, lag, first, (mid, lo + size), z, (t_mean[b + 1], t_scat[b + 1]))
        t_step[b + 1] = piece_step(samples, chan[0], first, (mid, lo + size))
        if b < 0:
            continue
        piece_stats(samples, chan, lag, first, (lo, mid), z, (pre_mean, pre_scat))
        merge(
            (b_mean, b_scat, 0, 0, size),
            (split, pre_mean, pre_scat, size - split, t_mean[b + 1], t_scat[b + 1]),
            dev,
            (b_mean[b], b_scat[b]),
        )
        b_step[b] = min(piece_step(samples, chan[0], first, (lo, mid)), t_step[b + 1])
    if ring == 0:
        return
    for b in range(max(0, n - ring), n):
        pos = (b_lo + b) % ring
        c_step[pos] = _copy_piece((b_mean[b], b_scat[b], b_step[b]), (c_mean[pos], c_scat[pos]))
        if split > 0:
            c_tstep[pos] = _copy_piece(
                (t_mean[b + 1], t_scat[b + 1], t_step[b + 1]), (c_tmean[pos], c_tscat[pos])
            )
