r"""The CLPC kernel's per-window solve: block statistics, exact window merge and LPC solve.

Plain ``numba.njit(cache=True)`` functions (:func:`solve_one`, :func:`solve_windows`); the
rules of the solution are :mod:`clpc.core.rules`, the eigen-solver
:mod:`clpc.core.small_eigh`: nothing here restates them.

A window's numbers depend only on its own rows, never on how a record was chunked, so
``run``, ``push`` in any chunks and ``step`` give bit-identical results.

Windows (section V; ``docs/clpc.md``): update ``j`` closes after lag row ``e = C j`` and
uses rows ``[s, e)``, ``s = max(0, e - W)``: the window grows until it holds ``W`` rows,
then slides. Cut the lag rows into blocks ``[l B, (l + 1) B)`` of ``B`` rows, a multiple
of ``C`` (:func:`clpc.appraiser.kernel_setup.block_rows`: ``B = C`` unless ``C`` is small
against ``sqrt(W)``); a window is::

    tail: rows of s's block  +  the full blocks  +  head: rows of e's block before e

(with ``B = C`` the head is empty). The blocks are aligned to absolute row numbers, so
the pieces of a window do not depend on how the record was chunked either.

Each block is summarised once by its count, mean and centered scatter (two-pass,
:func:`clpc.appraiser.blocks.piece_stats`); the full blocks are one suffix and one prefix
sum of the segments of :mod:`clpc.appraiser.segments`; the tail and the head are summed
two-pass per window, or, when ``C < B``, taken from the chained row sums of
:mod:`clpc.appraiser.row_sums`. The (at most four) pieces are merged with the formula of
Chan, Golub and LeVeque (:func:`clpc.appraiser.segments.merge_pieces`)::

    n = sum n_k,   mean = sum n_k mean_k / n,
    A = sum A_k + sum n_k (mean_k - mean)(mean_k - mean)^T

Every term is centered, so offsets (positions around 1e4 rad) and long records lose no
digits.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from clpc.appraiser.blocks import BlockCache, gather_blocks, piece_stats, piece_step
from clpc.appraiser.kernel_types import Solved, WindowPlan, Work, new_work
from clpc.appraiser.row_sums import head_row, tail_row
from clpc.appraiser.segments import full_blocks, merge_pieces, segment_blocks
from clpc.appraiser.window_chains import WindowChains, chains_of, new_chains
from clpc.core.rules import NO_TRANSFORM, SolveSettings, is_excited
from clpc.core.small_eigh import sym_eig
from clpc.core.solution import channel_scales, solve_from_eig, solved_matrix

__all__ = ["solve_chained", "solve_one", "solve_windows"]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def solve_one(
    scat: np.ndarray,
    mean: np.ndarray,
    n_rows: float,
    plan: WindowPlan,
    s: SolveSettings,
    work: Work,
    out: tuple[np.ndarray, np.ndarray],
) -> tuple[float, float, float, float, int, int, bool]:
    """LPC of one window: the solved problem, its eigenpairs, then :func:`solve_from_eig`.

    ``out = (theta (p,), eigenvalues (p,))``; ``work`` from :func:`new_work`. A
    non-finite window is degenerate.
    """
    theta, eigenvalues = out
    p = scat.shape[0]
    mat, tmat, vecs, vals, raw, ework, phi, scales = work
    finite = True
    for a in range(p):
        for b in range(p):
            if not math.isfinite(scat[a, b]):
                finite = False
    channel_scales(scat, n_rows, plan.col_channel, s.n_channels, scales)
    if s.transform_mode == NO_TRANSFORM:  # the solved problem is A itself (T = I, unused)
        ok = finite and sym_eig(scat, vals, vecs, ework, True)
        if ok:
            for a in range(p):
                raw[a] = vals[a]
    else:
        solved_matrix(scat, s.transform_mode, plan.transform, scales, tmat, mat)
        ok = finite and sym_eig(mat, vals, vecs, ework, True)
        if ok:
            ok = sym_eig(scat, raw, mat, ework, False)  # the paper's eigenvalues, for D
    if not ok:
        for a in range(p):
            theta[a] = 0.0
            eigenvalues[a] = 0.0
        return 0.0, 0.0, 1.0, 0.0, 1, 0, True
    return solve_from_eig(
        scat,
        mean,
        n_rows,
        (vals, vecs, raw),
        (tmat, scales),
        s,
        plan.col_channel,
        (phi, theta, eigenvalues),
    )


@numba.njit(cache=True, nogil=True, error_model="numpy")
def solve_windows(
    samples: np.ndarray,
    first_row: int,
    windows: tuple[int, int],
    plan: WindowPlan,
    s: SolveSettings,
    out: Solved,
    cache: BlockCache,
) -> None:
    """Solve windows ``j0 .. j0 + count - 1`` (``windows = (j0, count)``) of every equation.

    ``samples`` (n, channels): lag row ``r`` (absolute) has its newest sample at
    ``samples[r - first_row]``. Windows with fewer than ``plan.min_rows`` rows are not
    solved (their outputs are zero and flagged degenerate). A channel's quantization step
    in a window (for :func:`clpc.core.rules.is_excited`) is its smallest nonzero change
    between consecutive samples of the window. ``cache`` (:class:`BlockCache`) supplies the
    blocks an earlier call summarised and keeps the newest (updated in place).
    """
    solve_chained(samples, first_row, windows, (plan, s), out, cache, new_chains(plan))


@numba.njit(cache=True, nogil=True, error_model="numpy")
def solve_chained(
    samples: np.ndarray,
    first_row: int,
    windows: tuple[int, int],
    settings: tuple[WindowPlan, SolveSettings],
    out: Solved,
    cache: BlockCache,
    chains: WindowChains,
) -> None:
    """:func:`solve_windows` with the chained sums an earlier call left in ``chains``.

    ``chains`` (:mod:`clpc.appraiser.window_chains`) is updated in place; the windows must
    come after those of the call that left it (``step``'s updates, in order).
    """
    plan, s = settings
    j0, count = windows
    n_eq, p = plan.chan.shape
    window, cluster, size = plan.window, plan.cluster, plan.block
    first = -first_row
    b_lo = -(-max(0, cluster * j0 - window) // size)  # the first full block of any window
    n_blocks = max(0, cluster * (j0 + count - 1) // size - b_lo)
    b_mean = np.empty((n_blocks, p))
    b_scat = np.empty((n_blocks, p, p))
    b_step = np.empty(n_blocks)
    t_mean = np.empty((1, p))  # the tail piece (one row, as the pieces merge_pieces takes)
    t_scat = np.empty((1, p, p))
    h_mean = np.empty((1, p))  # the head piece
    h_scat = np.empty((1, p, p))
    mean = np.empty(p)
    scat = np.empty((p, p))
    seg = segment_blocks(window, size)
    chained = size > cluster  # tails and heads move inside a block: chain their rows
    z = np.empty((size, p))  # the rows of one piece
    work = new_work(p)
    c_lo, c_hi = cache.span[0], cache.span[1]
    for eq in range(n_eq):
        chan = plan.chan[eq]
        lag = plan.lag[eq]
        gather_blocks(
            samples,
            (chan, lag, first, b_lo, n_blocks, size),
            (cache.mean[eq], cache.scat[eq], cache.step[eq], c_lo, c_hi),
            z,
            (b_mean, b_scat, b_step),
        )
        chain, row_sums = chains_of(chains, eq)
        for w in range(count):
            j = j0 + w
            e = cluster * j
            start = max(0, e - window)
            out.n_rows[w] = e - start
            if e - start < plan.min_rows:
                for a in range(p):
                    out.theta[w, eq, a] = 0.0
                    out.eigenvalues[w, eq, a] = 0.0
                out.c[w, eq] = 0.0
                out.noise_variance[w, eq] = 0.0
                out.separation[w, eq] = 1.0
                out.a0_weight[w, eq] = 0.0
                out.n_null[w, eq] = 0
                out.n_input_relations[w, eq] = 0
                out.degenerate[w, eq] = True
                out.excited[w, eq] = False
                continue
            # rows [start, e) = tail [start, full_lo B) + blocks + head [full_hi B, e)
            full_lo = -(-start // size)
            full_hi = max(e // size, full_lo)
            t_end = min(full_lo * size, e)
            h_start = min(max(full_hi * size, t_end), e)
            t_size = t_end - start
            h_size = e - h_start
            where = (chan, lag, first)
            tail = (float(t_size), t_mean, t_scat, 0)
            if t_size > 0 and chained and t_end == (start // size + 1) * size:
                i_t = tail_row(samples, where, start, size, row_sums)
                tail = (float(t_size), row_sums.tail_mean, row_sums.tail_scat, i_t)
            elif t_size > 0:
                piece_stats(samples, chan, lag, first, (start, t_end), z, (t_mean[0], t_scat[0]))
            head = (float(h_size), h_mean, h_scat, 0)
            if h_size > 0 and chained and h_start % size == 0:
                i_h = head_row(samples, where, e, size, row_sums)
                head = (float(h_size), row_sums.head_mean, row_sums.head_scat, i_h)
            elif h_size > 0:
                piece_stats(samples, chan, lag, first, (h_start, e), z, (h_mean[0], h_scat[0]))
            # the output's quantization step in the window (column 0 is y(n))
            step = piece_step(samples, chan[0], first, (start, t_end))
            step = min(step, piece_step(samples, chan[0], first, (h_start, e)))
            n_s, i_s, n_p, i_p, f_step = full_blocks(
                (b_mean, b_scat, b_step, b_lo, size), (full_lo, full_hi), (seg, chain)
            )
            step = min(step, f_step)
            pieces = (
                tail,
                (n_s, chain.suffix_mean, chain.suffix_scat, i_s),
                (n_p, chain.prefix_mean, chain.prefix_scat, i_p),
                head,
            )
            n_w = merge_pieces(pieces, chain.dev, (mean, scat))
            res = solve_one(
                scat, mean, n_w, plan, s, work, (out.theta[w, eq], out.eigenvalues[w, eq])
            )
            out.c[w, eq] = res[0]
            out.noise_variance[w, eq] = res[1]
            out.separation[w, eq] = res[2]
            out.a0_weight[w, eq] = res[3]
            out.n_null[w, eq] = res[4]
            out.n_input_relations[w, eq] = res[5]
            out.degenerate[w, eq] = res[6]
            out.excited[w, eq] = is_excited(scat, n_w, step, s.n_out_cols)
    if cache.mean.shape[1] > 0 and n_blocks > 0:
        cache.span[0] = b_lo + max(0, n_blocks - cache.mean.shape[1])
        cache.span[1] = b_lo + n_blocks
