"""A long record's trace in shared memory (``clpc.distributed.shared_rows``).

The workers of the client's machine solve their pieces straight into the record's trace in
a ``/dev/shm`` file; a worker that does not see the file sends its rows. Either way the
trace equals ``CLPC.run``'s bit for bit; the reference is the single-process run.
"""

from __future__ import annotations

import os
import pickle

import numpy as np
import pytest
from scipy import signal

pytest.importorskip("distributed")

from clpc import CLPC
from clpc.distributed import dask_client, run_long, shared_rows
from clpc.distributed.long_record import plan_record
from clpc.distributed.piece_tasks import (
    RowsInPlace,
    finish_piece,
    next_state,
    piece_info,
    solve_piece,
)
from clpc.distributed.shared_rows import SharedRows

needs_shm = pytest.mark.skipif(not shared_rows.SHM.is_dir(), reason="no /dev/shm")


def _record(n: int, seed: int = 5):
    """A 2nd-order ARX system; no input over samples 3000-7000, where nothing is accepted."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    u[3_000:7_000] = 0.0
    y = signal.lfilter([0.5, 0.3, 0.1], [1.0, -1.5, 0.7], u) + 0.02 * rng.standard_normal(n)
    return u, y


def _arrays(trace):
    out = {f: getattr(trace, f) for f in ("index", "time", "rows", "not_enough_data")}
    return {**out, **trace.arrays}


def _assert_equal(ref, got):
    want, have = _arrays(ref), _arrays(got)
    assert want.keys() == have.keys()
    for key, value in want.items():
        assert have[key].dtype == value.dtype and np.array_equal(have[key], value), key


def _pieces(n, settings, piece_samples):
    plan = plan_record(CLPC(**settings), (1, 1), n)
    pieces = plan.layout.pieces(n, piece_samples)
    pieces[-1] = pieces[-1]._replace(raw=(pieces[-1].raw[0], n))
    return plan, pieces


@needs_shm
@pytest.mark.parametrize("moved", [False, True])
def test_pieces_solved_into_the_shared_trace_give_the_single_process_trace(moved):
    # in this process: the pieces' kernels write into the file; with ``moved`` every solved
    # piece is pickled and unpickled first (a copy, as Dask moves it to another worker),
    # so the finish must write the rows it settles itself
    n, settings = 12_011, {"window_size": 60, "cluster_size": 6}
    u, y = _record(n)
    ref = CLPC(**settings).run(u, y)
    held = ref.has_model & ~ref.accepted
    assert held[(ref.index > 3_500) & (ref.index < 6_500)].all()  # held across pieces
    plan, pieces = _pieces(n, settings, 2_000)
    made = SharedRows.create(plan.state().empty_trace(), len(ref))
    assert made is not None
    shared, trace = made
    try:
        state = plan.initial()
        for piece in pieces:
            lo, hi = piece.raw
            solved = solve_piece((u[lo:hi], y[lo:hi]), plan, piece, shared)
            assert solved.shared
            if moved:
                solved = pickle.loads(pickle.dumps(solved))
            done = finish_piece(solved, plan, state, shared)
            assert isinstance(done, RowsInPlace) and done.start == piece.j_lo - 1
            state = next_state(state, piece_info(solved))
    finally:
        shared.remove()
    assert not (shared_rows.SHM / shared.path.split("/")[-1]).exists()
    _assert_equal(ref, trace)  # the client's map still holds the rows


def test_a_process_that_does_not_see_the_file_sends_its_rows(tmp_path):
    n, settings = 9_007, {"window_size": 60, "cluster_size": 6}
    u, y = _record(n)
    ref = CLPC(**settings).run(u, y)
    plan, pieces = _pieces(n, settings, 3_000)
    made = SharedRows.create(plan.state().empty_trace(), len(ref), folder=tmp_path)
    assert made is not None
    shared = SharedRows(str(tmp_path / "elsewhere"), *(made[0].rows, made[0].slots, made[0].size))
    state, parts = plan.initial(), []
    for piece in pieces:
        lo, hi = piece.raw
        solved = solve_piece((u[lo:hi], y[lo:hi]), plan, piece, shared)
        assert not solved.shared
        parts.append(finish_piece(solved, plan, state, shared))
        state = next_state(state, piece_info(solved))
    assert all(not isinstance(p, RowsInPlace) for p in parts)
    from clpc.appraiser.trace import Trace

    _assert_equal(ref, Trace.concat(parts))
    made[0].remove()


@pytest.fixture(scope="module")
def client():
    with dask_client(workers=2) as c:
        yield c


def _shm_files():
    return set(shared_rows.SHM.glob("clpc-trace-*")) if shared_rows.SHM.is_dir() else set()


@pytest.mark.parametrize("shm", [True, False])
def test_run_long_is_clpc_run_with_or_without_shared_memory(client, monkeypatch, tmp_path, shm):
    if shm and not shared_rows.SHM.is_dir():
        pytest.skip("no /dev/shm")
    if not shm:  # the client cannot make the file: every piece's rows are sent
        monkeypatch.setattr(shared_rows, "SHM", tmp_path / "missing")
    import dask.array as da

    u, y = _record(40_009)
    ref = CLPC().run(u, y)
    before = _shm_files()
    got = run_long(CLPC(), da.from_array(u, chunks=7_000), da.from_array(y, chunks=9_000),
                   client=client, piece_samples=6_000)  # fmt: skip
    _assert_equal(ref, got)
    levels = (got.meta["window_level"], ref.meta["window_level"])
    np.testing.assert_allclose(*levels, rtol=1e-12, atol=1e-13)  # as test_distributed_long
    assert _shm_files() == before  # the file is removed when the record is done


@needs_shm
def test_the_file_is_sparse_until_a_writer_reserves_its_rows(monkeypatch):
    plan, _ = _pieces(12_011, {"window_size": 60, "cluster_size": 6}, 2_000)
    like = plan.state().empty_trace()
    shared, trace = SharedRows.create(like, 2_000)
    try:
        assert os.stat(shared.path).st_blocks == 0  # the client zeroes nothing
        whole = shared.open(like, (0, 1_000))
        assert whole is not None
        per_row = sum(a.nbytes for a in _arrays(trace).values()) // len(trace)
        assert os.stat(shared.path).st_blocks * 512 >= 1_000 * per_row
        whole.arrays["theta"][:1_000] = 1.5  # seen through the client's map
        assert np.all(trace.arrays["theta"][:1_000] == 1.5)
    finally:
        shared.remove()
    # a tmpfs without twice the room: no shared trace (the rows are then sent)
    small = os.statvfs_result((4096, 4096, 10, 1, 1, 10, 1, 1, 0, 255))
    monkeypatch.setattr(shared_rows.os, "statvfs", lambda path: small)
    assert SharedRows.create(like, 2_000) is None
