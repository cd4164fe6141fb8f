"""A window's pieces from chained sums (segments of blocks; rows of a block), against the rows."""

from __future__ import annotations

import numpy as np
import pytest

from clpc.appraiser.kernel_setup import block_rows
from clpc.appraiser.row_sums import RowSums, head_row, tail_row
from clpc.appraiser.segments import ChainSums, full_blocks, merge_pieces, merge_two, segment_blocks

P = 4


def _rows(n_rows: int, seed: int = 1) -> np.ndarray:
    """Rows with an offset of 1e4 and unit steps (digits a raw, uncentered sum would lose)."""
    rng = np.random.default_rng(seed)
    return 1e4 + rng.standard_normal((n_rows, P)).cumsum(axis=0)


def _chain(seg: int) -> ChainSums:
    """Segment sums holding nothing (as ``window_chains.new_chains`` gives per equation)."""
    sums = [np.empty((seg, P)), np.empty((seg, P, P)), np.empty(seg)]
    return ChainSums(*sums, *[a.copy() for a in sums], np.full(3, -1), np.empty(P))


def _row_sums(size: int) -> RowSums:
    """Row sums holding nothing (as ``window_chains.new_chains`` gives per equation)."""
    sums = [np.empty((size, P)), np.empty((size, P, P))]
    return RowSums(*sums, *[a.copy() for a in sums], np.full(4, -1), np.empty(P), np.empty(P))


def _stats(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    mean = rows.mean(axis=0)
    centred = rows - mean
    return mean, centred.T @ centred


def test_merges_equal_the_direct_statistics_and_skip_empty_pieces():
    rows = _rows(30)
    parts = [_stats(rows[:7]), _stats(rows[7:19]), _stats(rows[19:])]
    means = np.array([m for m, _ in parts] + [np.full(P, np.nan)])  # row 3: never read
    scats = np.array([a for _, a in parts] + [np.full((P, P), np.nan)])
    m_ref, a_ref = _stats(rows)
    out = np.empty((1, P)), np.empty((1, P, P))
    two, dev = _stats(rows[7:]), np.empty(P)
    merge_two((12.0, means, scats, 1), (11.0, means, scats, 2), (0.0, *out, 0), dev)
    np.testing.assert_allclose(out[0][0], two[0], rtol=1e-14)
    np.testing.assert_allclose(out[1][0], two[1], rtol=1e-11, atol=1e-13 * np.abs(two[1]).max())
    mean, scat = np.empty(P), np.empty((P, P))
    pieces = ((7.0, means, scats, 0), (0.0, means, scats, 3), (12.0, means, scats, 1),
              (11.0, means, scats, 2))  # fmt: skip
    assert merge_pieces(pieces, dev, (mean, scat)) == 30.0
    np.testing.assert_allclose(mean, m_ref, rtol=1e-14)
    np.testing.assert_allclose(scat, a_ref, rtol=1e-11, atol=1e-13 * np.abs(a_ref).max())
    assert np.array_equal(scat, scat.T) and np.array_equal(out[1][0], out[1][0].T)
    nothing = ((0.0, means, scats, 3),) * 4
    assert merge_pieces(nothing, dev, (mean, scat)) == 0.0
    assert not mean.any() and not scat.any()


def _windows(window: int, cluster: int, n_rows: int):
    """Each update's full blocks ``(lo, hi)`` as the kernel cuts them (``window_solve``)."""
    size = block_rows(window, cluster)
    for j in range(1, n_rows // cluster + 1):
        e = cluster * j
        start = max(0, e - window)
        full_lo = -(-start // size)
        yield j, full_lo, max(e // size, full_lo)


@pytest.mark.parametrize(
    ("window", "cluster"),
    [(201, 12), (201, 1), (201, 5), (40, 1), (61, 3), (9, 4), (7, 20), (30, 30), (25, 13)],
)
def test_full_blocks_equal_the_rows_directly_and_do_not_depend_on_the_batch(window, cluster):
    size = block_rows(window, cluster)
    seg = segment_blocks(window, size)
    rows = _rows(12 * window + 3 * cluster)
    n_blocks = len(rows) // size
    b_mean, b_scat = np.empty((n_blocks, P)), np.empty((n_blocks, P, P))
    b_step = np.arange(n_blocks, 0, -1.0)  # a block's "step": the later, the smaller
    for k in range(n_blocks):
        b_mean[k], b_scat[k] = _stats(rows[k * size : (k + 1) * size])
    windows = list(_windows(window, cluster, n_blocks * size))

    def solve(first: int, last: int) -> dict[int, tuple]:
        """Windows ``first .. last - 1`` in one batch: only their own blocks are given."""
        b_lo = windows[first][1]
        b_hi = max(w[2] for w in windows[first:last])
        blocks = (b_mean[b_lo:b_hi], b_scat[b_lo:b_hi], b_step[b_lo:b_hi], b_lo, size)
        chain = _chain(seg)
        got = {}
        for j, lo, hi in windows[first:last]:
            n_s, i_s, n_p, i_p, step = full_blocks(blocks, (lo, hi), (seg, chain))
            pieces = (
                (n_s, chain.suffix_mean, chain.suffix_scat, i_s),
                (n_p, chain.prefix_mean, chain.prefix_scat, i_p),
                (0.0, chain.suffix_mean, chain.suffix_scat, 0),
                (0.0, chain.suffix_mean, chain.suffix_scat, 0),
            )
            mean, scat = np.empty(P), np.empty((P, P))
            n = merge_pieces(pieces, chain.dev, (mean, scat))
            got[j] = (n, step, mean, scat)
        return got

    batch = solve(0, len(windows))
    for j, lo, hi in windows:
        n, step, mean, scat = batch[j]
        if hi == lo:  # C > W - B: windows without a full block
            assert n == 0 and step == np.inf and not mean.any() and not scat.any()
            continue
        assert n == size * (hi - lo) and step == b_step[hi - 1]
        m_ref, a_ref = _stats(rows[lo * size : hi * size])
        np.testing.assert_allclose(mean, m_ref, rtol=1e-14)
        np.testing.assert_allclose(scat, a_ref, rtol=1e-10, atol=1e-12 * np.abs(a_ref).max())
    for i in range(0, len(windows), max(1, len(windows) // 7)):  # one at a time, as step
        alone = solve(i, i + 1)
        j = windows[i][0]
        assert alone[j][:2] == batch[j][:2]
        assert np.array_equal(alone[j][2], batch[j][2])
        assert np.array_equal(alone[j][3], batch[j][3])


def test_tail_and_head_rows_equal_the_rows_directly_and_do_not_depend_on_the_batch():
    size, n = 7, 200
    samples = _rows(n)[:, :2]  # two channels; lag rows [y(k), y(k-1), u(k), u(k-1)]
    where = (np.array([0, 0, 1, 1]), np.array([0, 1, 0, 1]), 0)
    lag_rows = np.column_stack([samples[1:, 0], samples[:-1, 0], samples[1:, 1], samples[:-1, 1]])

    def row(r: int) -> np.ndarray:  # lag row r has its newest sample at samples[r]
        return lag_rows[r - 1]

    def pieces(starts: list[int]) -> list[tuple]:
        sums, got = _row_sums(size), []
        for start in starts:  # in increasing order, as the kernel asks
            end = start + 3 * size
            i_t = tail_row(samples, where, start, size, sums)
            i_h = head_row(samples, where, end, size, sums)
            got.append(
                (
                    (sums.tail_mean[i_t].copy(), sums.tail_scat[i_t].copy()),
                    (sums.head_mean[i_h].copy(), sums.head_scat[i_h].copy()),
                )
            )
        return got

    starts = list(range(1, n - 4 * size))
    batch = pieces(starts)
    for start, (tail, head) in zip(starts, batch, strict=True):
        end = start + 3 * size
        tail_rows = np.array([row(r) for r in range(start, (start // size + 1) * size)])
        head_rows = np.array([row(r) for r in range((end - 1) // size * size, end)])
        for got, rows in ((tail, tail_rows), (head, head_rows)):
            m_ref, a_ref = _stats(rows)
            np.testing.assert_allclose(got[0], m_ref, rtol=1e-14)
            scale = max(np.abs(a_ref).max(), 1.0)
            np.testing.assert_allclose(got[1], a_ref, rtol=1e-10, atol=1e-12 * scale)
            assert np.array_equal(got[1], got[1].T)
    for k in range(0, len(starts), 9):  # one window at a time, as step
        alone = pieces([starts[k]])[0]
        for got, ref in zip(alone, batch[k], strict=True):
            assert np.array_equal(got[0], ref[0]) and np.array_equal(got[1], ref[1])
