"""The appraiser's sample buffer against a plain list of every sample kept."""

from __future__ import annotations

import numpy as np

from clpc.appraiser.buffer import SampleBuffer


def test_appends_and_forgets_keep_exactly_the_live_samples_in_one_store():
    rng = np.random.default_rng(5)
    buf = SampleBuffer(3)
    record = np.empty((0, 3))
    keep_from = 0
    stores: list[np.ndarray] = []  # held, so that no address is reused
    for _ in range(60):  # chunks of varying size; forget all but the last 40 samples
        new = rng.standard_normal((int(rng.integers(1, 500)), 3))
        buf.append(new)
        record = np.vstack([record, new])
        keep_from = max(keep_from, len(record) - 40)
        buf.drop_before(keep_from)
        store = buf.flushed()[0]
        if not any(store is seen for seen in stores):
            stores.append(store)
        np.testing.assert_array_equal(buf.data, record[keep_from:])
        assert buf.start == keep_from
        store, first = buf.flushed()
        np.testing.assert_array_equal(store[keep_from - first : len(record) - first], buf.data)
    # the live rows move to the front of the same store when it has room (no new store
    # for every other chunk): a handful of stores, as the largest chunk grows
    assert len(stores) <= 8


def test_samples_kept_aside_join_before_an_append():
    buf = SampleBuffer(2)
    buf.append(np.array([[1.0, 2.0]]))
    buf.pending.extend([3.0, 4.0, 5.0, 6.0])
    buf.append(np.array([[7.0, 8.0]]))
    np.testing.assert_array_equal(buf.data, [[1, 2], [3, 4], [5, 6], [7, 8]])
    buf.drop_before(3)
    np.testing.assert_array_equal(buf.since(0), [[7, 8]])
