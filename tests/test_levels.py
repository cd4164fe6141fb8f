"""Each window's mean output (``meta["window_level"]``) against direct means of its samples."""

from __future__ import annotations

import numpy as np
import pytest

from clpc import CLPC
from clpc.analysis.operating_point import window_means
from clpc.appraiser.levels import window_levels


def _record(n: int, n_out: int, seed: int = 3) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = np.empty((n, n_out))
    for k in range(n_out):  # an offset far from zero, a slow drift and noise
        y[:, k] = 1e4 * (k + 1) + np.cumsum(u) * 0.01 + 0.1 * rng.standard_normal(n)
    return u, y


@pytest.mark.parametrize(
    ("n_out", "settings"),
    [
        (1, {"window_size": 61, "cluster_size": 5}),
        (2, {"window_size": 40, "cluster_size": 1}),
        (1, {"window_size": 61, "cluster_size": 3, "decimate_to": 0.004, "dt": 0.001}),
    ],
)
def test_run_levels_are_the_windows_direct_means(n_out, settings):
    u, y = _record(3000, n_out)
    trace = CLPC(order=2, **settings).run(u, y if n_out > 1 else y[:, 0])
    factor = 4 if "decimate_to" in settings else 1
    levels = trace.meta["window_level"]
    assert levels.shape == (len(trace), n_out)
    for i in range(len(trace)):
        last = min(int(trace.index[i]) * factor, len(u) - 1)
        first = min(max((int(trace.index[i]) - int(trace.rows[i]) + 1) * factor, 0), last)
        np.testing.assert_allclose(levels[i], y[first : last + 1].mean(axis=0), rtol=1e-13)


def test_window_levels_equal_cumsum_differences_bit_for_bit_in_any_order():
    _, y = _record(5000, 2)
    rng = np.random.default_rng(0)
    first = np.sort(rng.integers(0, 4000, 300))
    last = first + rng.integers(0, 900, 300)
    order = np.concatenate([np.arange(300), rng.permutation(300)])  # forwards, then shuffled
    # a window of `rows` samples ending at `index` (no decimation): first..last
    got = window_levels(y, last[order], last[order] - first[order] + 1)
    ref = np.empty_like(got)
    for k in range(2):
        col = y[:, k]
        centred = col - col.mean()
        csum = np.concatenate([[0.0], np.cumsum(centred)])
        count = last[order] - first[order] + 1
        ref[:, k] = (csum[last[order] + 1] - csum[first[order]]) / count + col.mean()
    np.testing.assert_array_equal(got, ref)
    spans = zip(first[order], last[order], strict=True)
    direct = np.array([y[a : b + 1].mean(axis=0) for a, b in spans])
    np.testing.assert_allclose(got, direct, rtol=1e-12)


def test_window_levels_of_a_decimated_piece_are_its_windows_direct_means():
    _, y = _record(6000, 2)
    factor, offset = 3, 1500  # the piece holds record samples 1500 .. 5999
    index = np.arange(700, 2000, 7)  # decimated samples; windows of 30-200 lag vectors
    rows = np.random.default_rng(1).integers(30, 200, index.size)
    got = window_levels(y[offset:], index, rows, factor, (offset, 6000))
    for i, (k, r) in enumerate(zip(index, rows, strict=True)):
        last = min(k * factor, 5999)
        first = min(max((k - r + 1) * factor, 0), last)
        np.testing.assert_allclose(got[i], y[first : last + 1].mean(axis=0), rtol=1e-12)


def test_window_levels_allocate_only_their_result():
    import tracemalloc

    _, y = _record(200_000, 1)
    index = np.arange(300, 200_000, 4, dtype=np.int64)
    rows = np.full(index.size, 201, dtype=np.int64)
    window_levels(y, index[:10], rows[:10])  # compiled before measuring
    tracemalloc.start()
    got = window_levels(y, index, rows)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert peak <= got.nbytes + 64_000, (peak, got.nbytes)  # no array of the windows' length


def test_operating_point_window_means_are_the_cumsum_formula_and_check_the_record():
    _, y = _record(3000, 1)
    v = y[:, 0]
    index = np.arange(59, 3000, 5)  # windows of samples 0..59, ..., 2940..2999
    rows = np.full(index.size, 60)
    csum = np.concatenate([[0.0], np.cumsum(v - v.mean())])
    ref = (csum[index + 1] - csum[index + 1 - rows]) / rows + v.mean()
    np.testing.assert_array_equal(window_means(v, index, rows), ref)
    with pytest.raises(ValueError, match="the record has 2999"):
        window_means(v[:-1], index, rows)


def test_window_levels_refuse_a_window_outside_the_samples():
    _, y = _record(1000, 1)
    with pytest.raises(ValueError, match="outside the samples"):
        window_levels(y[500:], np.array([700]), np.array([300]), 1, (500, 1000))  # from 401
