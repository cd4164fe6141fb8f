"""The chained sums a kernel call works with, for every equation (:class:`WindowChains`).

The suffix and prefix sums of the block segments (:class:`clpc.appraiser.segments.ChainSums`)
and the tail and head row sums (:class:`clpc.appraiser.row_sums.RowSums`) are functions of
the blocks and rows alone, so sums an earlier call chained stay right for later windows:
``step`` keeps one :class:`WindowChains` in its packed state
(:func:`clpc.appraiser.step_kernel.pack_state`) and each update extends the chains by a block
or a row, instead of chaining the window's segments anew. A batch call starts from
:func:`new_chains` (nothing held). Either way a window gets the same bits.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from clpc.appraiser.kernel_types import WindowPlan
from clpc.appraiser.row_sums import RowSums
from clpc.appraiser.segments import ChainSums, segment_blocks

__all__ = ["WindowChains", "chain_floats", "chain_sizes", "chains_in", "chains_of", "new_chains"]


class WindowChains(NamedTuple):
    """Per equation ``e``: index ``[e, 0]`` suffix or tail sums, ``[e, 1]`` prefix or head sums.

    ``L`` blocks per segment, ``R`` rows per block when rows are chained (else 1); see
    :func:`chain_sizes`.
    """

    sums_mean: np.ndarray  #: (E, 2, L, p)
    sums_scat: np.ndarray  #: (E, 2, L, p, p)
    sums_step: np.ndarray  #: (E, 2, L)
    rows_mean: np.ndarray  #: (E, 2, R, p)
    rows_scat: np.ndarray  #: (E, 2, R, p, p)
    chain_at: np.ndarray  #: (E, 3) int64, ChainSums.at (-1: nothing held)
    row_at: np.ndarray  #: (E, 4) int64, RowSums.at (-1: nothing held)
    work: np.ndarray  #: (2, p) work space


@numba.njit(cache=True, nogil=True, error_model="numpy")
def chain_sizes(window: int, block: int, cluster: int) -> tuple[int, int]:
    """``(L, R)``: blocks per segment, and rows per block when ``C < B`` (else 1)."""
    return segment_blocks(window, block), block if block > cluster else 1


@numba.njit(cache=True, nogil=True, error_model="numpy")
def chain_floats(shape: tuple[int, int], sizes: tuple[int, int]) -> int:
    """Floats of a :class:`WindowChains` of ``shape = (E, p)`` and ``sizes = (L, R)``."""
    n_eq, p = shape
    seg, rows = sizes
    return 2 * n_eq * (seg * (p * p + p + 1) + rows * (p * p + p)) + 2 * p


@numba.njit(cache=True, nogil=True, error_model="numpy")
def chains_in(
    floats: np.ndarray, ints: np.ndarray, shape: tuple[int, int], sizes: tuple[int, int]
) -> WindowChains:
    """A :class:`WindowChains` as views of ``floats`` and ``ints`` (``step``'s packed state).

    ``floats``: :func:`chain_floats` entries, ``ints``: ``7 E``, both 1-d and contiguous.
    """
    n_eq, p = shape
    seg, rows = sizes
    a = 2 * n_eq * seg * p
    b = a + a * p
    c = b + 2 * n_eq * seg
    d = c + 2 * n_eq * rows * p
    e = d + 2 * n_eq * rows * p * p
    return WindowChains(
        floats[:a].reshape((n_eq, 2, seg, p)),
        floats[a:b].reshape((n_eq, 2, seg, p, p)),
        floats[b:c].reshape((n_eq, 2, seg)),
        floats[c:d].reshape((n_eq, 2, rows, p)),
        floats[d:e].reshape((n_eq, 2, rows, p, p)),
        ints[: 3 * n_eq].reshape((n_eq, 3)),
        ints[3 * n_eq : 7 * n_eq].reshape((n_eq, 4)),
        floats[e : e + 2 * p].reshape((2, p)),
    )


@numba.njit(cache=True, nogil=True, error_model="numpy")
def new_chains(plan: WindowPlan) -> WindowChains:
    """:class:`WindowChains` holding nothing, for the windows of ``plan``."""
    shape = plan.chan.shape
    sizes = chain_sizes(plan.window, plan.block, plan.cluster)
    ints = np.full(7 * shape[0], -1, np.int64)
    return chains_in(np.empty(chain_floats(shape, sizes)), ints, shape, sizes)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def chains_of(chains: WindowChains, eq: int) -> tuple[ChainSums, RowSums]:
    """Equation ``eq``'s segment sums and row sums: views of ``chains``."""
    c = chains
    segments = ChainSums(
        c.sums_mean[eq, 0],
        c.sums_scat[eq, 0],
        c.sums_step[eq, 0],
        c.sums_mean[eq, 1],
        c.sums_scat[eq, 1],
        c.sums_step[eq, 1],
        c.chain_at[eq],
        c.work[0],
    )
    rows = RowSums(
        c.rows_mean[eq, 0], c.rows_scat[eq, 0], c.rows_mean[eq, 1], c.rows_scat[eq, 1],
        c.row_at[eq], c.work[1], c.work[0],
    )  # fmt: skip
    return segments, rows
