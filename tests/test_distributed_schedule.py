"""How a long record's pieces reach the client (``clpc.distributed.schedule``).

A worker tells the client a solved piece's few numbers in a Dask event as the solve ends;
the ``piece_info`` task is the fallback when an event is lost. Both give the trace of
``CLPC.run`` bit for bit.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

pytest.importorskip("distributed")
msgpack = pytest.importorskip("msgpack")

from clpc import CLPC  # noqa: E402
from clpc.distributed import run_long, schedule  # noqa: E402
from clpc.distributed.piece_tasks import PieceInfo  # noqa: E402


def _record(n: int):
    rng = np.random.default_rng(11)
    u = rng.standard_normal((n, 2))
    y = signal.lfilter([0.5, 0.3], [1.0, -0.7], u[:, 0]) + 0.3 * u[:, 1]
    return u, y + 0.01 * rng.standard_normal(n)


def test_a_pieces_numbers_cross_an_event_exactly():
    rng = np.random.default_rng(2)
    theta = rng.standard_normal((2, 5)) * np.array([1e-300, 1.0, -0.0, 1e300, np.pi])
    info = PieceInfo(
        rng.standard_normal((2, 3)),
        (theta, np.array([5e-324, -1.0]), np.array([True, False])),
        np.array([False, True]),
        np.array([-1, 7]),
        True,
    )
    msg = msgpack.unpackb(msgpack.packb(schedule._plain(info)))  # as Dask sends an event
    back = schedule._unplain(msg)
    assert back.shared is True
    pairs = [(back.peaks, info.peaks), (back.accepted, info.accepted), (back.first, info.first)]
    for have, want in [*pairs, *zip(back.end, info.end, strict=True)]:
        assert have.dtype == want.dtype and have.shape == want.shape
        assert have.tobytes() == want.tobytes()  # bit for bit (-0.0 and subnormals too)


@pytest.mark.parametrize("events", [True, False])
def test_the_trace_is_clpc_runs_whether_the_events_arrive_or_not(client, monkeypatch, events):
    import dask.array as da

    if not events:  # every event lost: the piece_info tasks tell the client
        monkeypatch.setattr(schedule._News, "hear", lambda self, event: None)
    u, y = _record(30_011)
    kw = {"order": 1, "window_size": 80, "cluster_size": 8}
    ref = CLPC(**kw).run(u, y)
    got = run_long(CLPC(**kw), da.from_array(u, chunks=(4_000, 2)), da.from_array(y, chunks=5_000),
                   client=client, piece_samples=2_500)  # fmt: skip
    for key, want in ref.arrays.items():
        assert np.array_equal(got.arrays[key], want), key
    assert np.array_equal(got.index, ref.index) and np.array_equal(got.rows, ref.rows)
