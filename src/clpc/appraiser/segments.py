r"""A window's full blocks from two chained sums per block (van Herk and Gil-Werman).

The full blocks of a CLPC window (:mod:`clpc.appraiser.window_solve`) are grouped into
segments of ``L`` consecutive blocks aligned to absolute block numbers, ``L`` the fewest
full blocks a sliding window holds (:func:`segment_blocks`). For block ``k`` of segment
``[a L, (a + 1) L)``::

    suffix  S_k = b_k + S_(k+1)      S_((a+1)L - 1) = b_((a+1)L - 1)
    prefix  P_k = P_(k-1) + b_k      P_(aL) = b_(aL)

``+`` is the merge of Chan, Golub and LeVeque of two pieces (:func:`merge_two`), every term
centered. A sliding window's full blocks ``[lo, hi)`` number ``L`` or ``L + 1``, so they
span at most two segments and are ``S_lo + P_(hi-1)``; a growing window's start at block 0
and are ``P_(hi-1)`` or ``S_0 + P_(hi-1)``. That is two merges per block and one per window,
where a merge over every full block of every window cost ``W / B`` block terms per window.

Each sum is a chain fixed by absolute block numbers and the window's own blocks, so a
window's numbers still depend only on its rows and its position: ``run``, ``push`` in any
chunks, ``step`` and the threads of ``n_jobs`` give the same bits. The sums of the
segments a call is at are held in :class:`ChainSums` (``O(L p^2)``, kept by
:class:`clpc.appraiser.window_chains.WindowChains`), computed when the windows (in
increasing order) first need them.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

__all__ = [
    "ChainSums",
    "Piece",
    "full_blocks",
    "merge_pieces",
    "merge_two",
    "segment_blocks",
]

#: a piece of a window: ``(count, means (k, p), scatters (k, p, p), i)``, its statistics row ``i``
Piece = tuple[float, np.ndarray, np.ndarray, int]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def segment_blocks(window: int, size: int) -> int:
    """Blocks ``L`` of a segment: the fewest full blocks of ``size`` rows in ``window`` rows.

    A window starting ``t`` rows before a block boundary (``0 <= t < size``) holds
    ``(window - t) // size`` full blocks, at least ``(window - size + 1) // size`` and at
    most one more; ``L >= 1`` (windows with at most one full block then).
    """
    return max(1, (window - size + 1) // size)


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def merge_two(first: Piece, second: Piece, out: Piece, dev: np.ndarray) -> None:
    """Two pieces of nonzero counts merged into ``out`` (Chan, Golub and LeVeque).

    ::

        mean = (n1 mean1 + n2 mean2) / n,   A = A1 + A2 + d d^T,
        d = sqrt(n1 n2 / n) (mean1 - mean2)

    The arguments are :data:`Piece` tuples; ``out``'s count is not read, and its row is not
    one of the inputs'.
    ``dev`` work space (p,). Entries ``(a, b)`` and ``(b, a)`` add the same terms in the
    same order: the scatter is exactly symmetric.
    """
    n1, mean1, scat1, i1 = first
    n2, mean2, scat2, i2 = second
    _, mean, scat, i = out
    p = mean.shape[1]
    n = n1 + n2
    root = math.sqrt(n1 * n2 / n)
    for a in range(p):
        mean[i, a] = (n1 * mean1[i1, a] + n2 * mean2[i2, a]) / n
        dev[a] = root * (mean1[i1, a] - mean2[i2, a])
    for a in range(p):
        dev_a = dev[a]
        for b in range(p):
            scat[i, a, b] = scat1[i1, a, b] + scat2[i2, a, b] + dev_a * dev[b]


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _add_mean(piece: Piece, mean: np.ndarray) -> None:
    """``mean += n_k mean_k`` of a piece of nonzero count."""
    n_k, means, _, i = piece
    if n_k > 0:
        for a in range(mean.shape[0]):
            mean[a] += n_k * means[i, a]


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _add_scat(piece: Piece, mean: np.ndarray, dev: np.ndarray, scat: np.ndarray) -> None:
    """``scat += A_k + d_k d_k^T`` of a piece of nonzero count (``mean`` the merged mean)."""
    n_k, means, scats, i = piece
    if n_k > 0:
        p = mean.shape[0]
        root = math.sqrt(n_k)
        for a in range(p):
            dev[a] = root * (means[i, a] - mean[a])
        for a in range(p):
            dev_a = dev[a]
            for b in range(p):
                scat[a, b] += scats[i, a, b] + dev_a * dev[b]


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def merge_pieces(
    pieces: tuple[Piece, Piece, Piece, Piece], dev: np.ndarray, out: tuple[np.ndarray, np.ndarray]
) -> float:
    """Up to four pieces merged into ``out = (mean (p,), scat (p, p))``; returns the count.

    The formula of Chan, Golub and LeVeque over the pieces of nonzero count (the others
    are not read)::

        n = sum n_k,  mean = sum n_k mean_k / n,  A = sum (A_k + d_k d_k^T),
        d_k = sqrt(n_k) (mean_k - mean)

    ``dev`` work space (p,). Exactly symmetric, as :func:`merge_two`.
    """
    mean, scat = out
    p = mean.shape[0]
    first, second, third, fourth = pieces
    total = first[0] + second[0] + third[0] + fourth[0]
    for a in range(p):
        mean[a] = 0.0
        for b in range(p):
            scat[a, b] = 0.0
    if total == 0:
        return 0.0
    _add_mean(first, mean)
    _add_mean(second, mean)
    _add_mean(third, mean)
    _add_mean(fourth, mean)
    for a in range(p):
        mean[a] /= total
    _add_scat(first, mean, dev, scat)
    _add_scat(second, mean, dev, scat)
    _add_scat(third, mean, dev, scat)
    _add_scat(fourth, mean, dev, scat)
    return total


class ChainSums(NamedTuple):
    """The suffix and prefix sums of the segments a batch of windows is at.

    Row ``i`` of ``suffix_*`` is block ``at[0] L + i`` of segment ``at[0]``, of
    ``prefix_*`` block ``at[1] L + i``; ``at[2]``: the last block whose prefix is held.
    ``*_step``: the quantization step (a channel's smallest nonzero change) of the sum.
    """

    suffix_mean: np.ndarray  #: (L, p)
    suffix_scat: np.ndarray  #: (L, p, p)
    suffix_step: np.ndarray  #: (L,)
    prefix_mean: np.ndarray  #: (L, p)
    prefix_scat: np.ndarray  #: (L, p, p)
    prefix_step: np.ndarray  #: (L,)
    at: np.ndarray  #: (3,) int64, -1: nothing held
    dev: np.ndarray  #: (p,) work space


#: the blocks of a batch: ``(means (n, p), scatters (n, p, p), steps (n,), b_lo, size)``,
#: block ``b_lo + k`` in row ``k``
Blocks = tuple[np.ndarray, np.ndarray, np.ndarray, int, int]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _suffixes(blocks: Blocks, seg: int, a: int, c: ChainSums) -> None:
    """Suffix sums of segment ``a``, from its last block down to the first one held."""
    b_mean, b_scat, b_step, b_lo, size = blocks
    start, stop = a * seg, (a + 1) * seg
    if stop > b_lo + b_mean.shape[0]:
        raise ValueError("clpc internal error: a window's segment ends after its blocks")
    last, p = stop - 1 - b_lo, b_mean.shape[1]
    for x in range(p):
        c.suffix_mean[seg - 1, x] = b_mean[last, x]
        for y in range(p):
            c.suffix_scat[seg - 1, x, y] = b_scat[last, x, y]
    c.suffix_step[seg - 1] = b_step[last]
    for k in range(stop - 2, max(start, b_lo) - 1, -1):
        i, b = k - start, k - b_lo
        below = (float(size * (stop - 1 - k)), c.suffix_mean, c.suffix_scat, i + 1)
        into = (0.0, c.suffix_mean, c.suffix_scat, i)
        merge_two((float(size), b_mean, b_scat, b), below, into, c.dev)
        c.suffix_step[i] = min(b_step[b], c.suffix_step[i + 1])
    c.at[0] = a


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _prefix(blocks: Blocks, seg: int, k: int, c: ChainSums) -> int:
    """The row of block ``k``'s prefix sum, the held prefixes extended up to it."""
    b_mean, b_scat, b_step, b_lo, size = blocks
    a = k // seg
    start, p = a * seg, b_mean.shape[1]
    if c.at[1] != a:
        if start < b_lo:
            raise ValueError("clpc internal error: a window's segment starts before its blocks")
        for x in range(p):
            c.prefix_mean[0, x] = b_mean[start - b_lo, x]
            for y in range(p):
                c.prefix_scat[0, x, y] = b_scat[start - b_lo, x, y]
        c.prefix_step[0] = b_step[start - b_lo]
        c.at[1] = a
        c.at[2] = start
    for m in range(c.at[2] + 1, k + 1):
        i, b = m - start, m - b_lo
        above = (float(size * i), c.prefix_mean, c.prefix_scat, i - 1)
        into = (0.0, c.prefix_mean, c.prefix_scat, i)
        merge_two(above, (float(size), b_mean, b_scat, b), into, c.dev)
        c.prefix_step[i] = min(c.prefix_step[i - 1], b_step[b])
    c.at[2] = max(c.at[2], k)
    return k - start


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def full_blocks(
    blocks: Blocks, span: tuple[int, int], chain: tuple[int, ChainSums]
) -> tuple[float, int, float, int, float]:
    """The sums that make up full blocks ``span = (lo, hi)`` of a window.

    ``blocks``: every block of the windows asked for (:data:`Blocks`); ``chain = (L,
    sums)``, the :class:`ChainSums` of one equation (windows asked for in increasing
    order). Returns ``(n_suffix, i_suffix, n_prefix, i_prefix, step)``: the count and row
    of the suffix sum and of the prefix sum (count 0: not used) and the blocks'
    quantization step (``inf`` without a block).
    """
    seg, c = chain
    lo, hi = span
    size = blocks[4]
    if hi <= lo:
        return 0.0, 0, 0.0, 0, math.inf
    a_lo, a_hi = lo // seg, (hi - 1) // seg
    if a_hi > a_lo + 1 or (a_hi == a_lo and lo % seg != 0 and hi != (a_lo + 1) * seg):
        raise ValueError("clpc internal error: a window's full blocks span more than two segments")
    if a_hi == a_lo and lo % seg == 0:  # a prefix of one segment
        m = _prefix(blocks, seg, hi - 1, c)
        return 0.0, 0, float(size * (hi - lo)), m, c.prefix_step[m]
    if c.at[0] != a_lo:
        _suffixes(blocks, seg, a_lo, c)
    i = lo - a_lo * seg
    if a_hi == a_lo:  # a suffix of one segment
        return float(size * (hi - lo)), i, 0.0, 0, c.suffix_step[i]
    m = _prefix(blocks, seg, hi - 1, c)
    n_suffix = float(size * (seg - i))
    return n_suffix, i, float(size * (m + 1)), m, min(c.suffix_step[i], c.prefix_step[m])
