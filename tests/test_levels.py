"""Each window's mean output (``meta["window_level"]``) against direct means of its samples."""

from __future__ import annotations

import numpy as np
import pytest

from clpc import CLPC
from clpc.appraiser.levels import window_means


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


def test_window_means_equal_cumsum_differences_bit_for_bit_in_any_order():
    _, y = _record(5000, 2)
    rng = np.random.default_rng(0)
    first = np.sort(rng.integers(0, 4000, 300))
    last = first + rng.integers(0, 900, 300)
    order = np.concatenate([np.arange(300), rng.permutation(300)])  # forwards, then shuffled
    got = window_means(y, first[order], last[order])
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
