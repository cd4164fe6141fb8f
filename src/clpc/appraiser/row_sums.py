r"""A window's tail and head pieces from chained row sums, when updates come every few rows.

With ``C < B`` (:func:`clpc.appraiser.kernel_setup.block_rows`) a window's tail (the rows
of its first block from ``s`` on) and head (the rows of its last block before ``e``) move
by ``C`` rows per update inside the same block for ``B / C`` updates. Instead of summing
them row by row for every window, the rows of a block are chained once, the way
:mod:`clpc.appraiser.segments` chains blocks::

    tail  T_r = z_r + T_(r+1)    from the block's last row down    (the rows r .. of the block)
    head  H_r = H_(r-1) + z_r    from the block's first row up     (the rows .. r of the block)

``+`` adding one lag row to a piece (:func:`add_row`, the merge of Chan, Golub and LeVeque
with a piece of one row). The tail of a window starting at row ``s`` is ``T_s``, its head
ending before ``e`` is ``H_(e-1)``: one row added per row and chain instead of up to ``B``
rows per window. Each chain starts at a block boundary (absolute row numbers) and reads
only the window's rows, so a window's numbers depend only on its rows and position, as
before. A tail that is not a suffix of its block (or a head not a prefix), which only a
window of fewer than ``B`` rows can have, is summed directly by the caller.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

__all__ = ["RowSums", "add_row", "head_row", "tail_row"]

#: where a lag row comes from: ``(chan (p,), lag (p,), first)`` as for ``blocks.piece_stats``
Where = tuple[np.ndarray, np.ndarray, int]


class RowSums(NamedTuple):
    """The chained row sums of the tail's block and of the head's block (one equation).

    Row ``i`` of ``tail_*`` is the sum of rows ``at[0] B + i ..`` of block ``at[0]``;
    ``at[1]`` the first row whose tail sum is held. Row ``i`` of ``head_*`` is the sum of
    rows ``.. at[2] B + i`` of block ``at[2]``; ``at[3]`` the last row whose head sum is
    held.
    """

    tail_mean: np.ndarray  #: (B, p)
    tail_scat: np.ndarray  #: (B, p, p)
    head_mean: np.ndarray  #: (B, p)
    head_scat: np.ndarray  #: (B, p, p)
    at: np.ndarray  #: (4,) int64, -1: nothing held
    z: np.ndarray  #: (p,) work space: one lag row
    dev: np.ndarray  #: (p,) work space


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def add_row(
    piece: tuple[float, np.ndarray, np.ndarray, int],
    sums: RowSums,
    out: tuple[np.ndarray, np.ndarray, int],
) -> None:
    """Add the row ``sums.z`` to the piece ``(n, means, scats, i)`` (``n > 0``) into ``out``.

    ::

        mean = (n mean_1 + z) / (n + 1),   A = A_1 + d d^T,   d = sqrt(n / (n + 1)) (mean_1 - z)

    ``out = (means, scats, i)``, a row other than the piece's. Exactly symmetric.
    """
    n, means, scats, i = piece
    mean, scat, k = out
    z, dev = sums.z, sums.dev
    p = z.shape[0]
    total = n + 1.0
    root = math.sqrt(n / total)
    for a in range(p):
        mean[k, a] = (n * means[i, a] + z[a]) / total
        dev[a] = root * (means[i, a] - z[a])
    for a in range(p):
        dev_a = dev[a]
        for b in range(p):
            scat[k, a, b] = scats[i, a, b] + dev_a * dev[b]


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _first_row(mean: np.ndarray, scat: np.ndarray, k: int, z: np.ndarray) -> None:
    """Row ``k`` = the piece of the one row ``z`` (mean ``z``, scatter 0)."""
    p = z.shape[0]
    for a in range(p):
        mean[k, a] = z[a]
        for b in range(p):
            scat[k, a, b] = 0.0


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _lag_row(samples: np.ndarray, where: Where, r: int, z: np.ndarray) -> None:
    """``z`` = lag row ``r``: ``where = (chan, lag, first)`` as for ``piece_stats``."""
    chan, lag, first = where
    for a in range(z.shape[0]):
        z[a] = samples[first + r - lag[a], chan[a]]


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def tail_row(samples: np.ndarray, where: Where, start: int, size: int, sums: RowSums) -> int:
    """The row of ``sums.tail_*`` holding rows ``start ..`` to the end of their block.

    Windows are asked for in increasing order; the chain of ``start``'s block is extended
    down to ``start`` (every row read is the window's own).
    """
    block = start // size
    base = block * size
    if sums.at[0] != block:
        sums.at[0] = block
        sums.at[1] = base + size
    for r in range(sums.at[1] - 1, start - 1, -1):
        _lag_row(samples, where, r, sums.z)
        i = r - base
        if i == size - 1:
            _first_row(sums.tail_mean, sums.tail_scat, i, sums.z)
        else:
            below = (float(size - 1 - i), sums.tail_mean, sums.tail_scat, i + 1)
            add_row(below, sums, (sums.tail_mean, sums.tail_scat, i))
    sums.at[1] = min(sums.at[1], start)
    return start - base


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def head_row(samples: np.ndarray, where: Where, end: int, size: int, sums: RowSums) -> int:
    """The row of ``sums.head_*`` holding rows from the start of ``end - 1``'s block to it.

    Windows are asked for in increasing order; the chain is extended up to ``end - 1``.
    """
    block = (end - 1) // size
    base = block * size
    if sums.at[2] != block:
        sums.at[2] = block
        sums.at[3] = base - 1
    for r in range(sums.at[3] + 1, end):
        _lag_row(samples, where, r, sums.z)
        i = r - base
        if i == 0:
            _first_row(sums.head_mean, sums.head_scat, 0, sums.z)
        else:
            above = (float(i), sums.head_mean, sums.head_scat, i - 1)
            add_row(above, sums, (sums.head_mean, sums.head_scat, i))
    sums.at[3] = max(sums.at[3], end - 1)
    return end - 1 - base
