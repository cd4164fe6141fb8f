"""A long record's trace in shared memory (``clpc.distributed.shared_rows``).

The workers of the client's machine solve their pieces straight into the record's trace in
a ``/dev/shm`` file; a worker that does not see the file sends its rows. Either way the
trace equals ``CLPC.run``'s bit for bit; the reference is the single-process run.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from scipy import signal

pytest.importorskip("distributed")

from clpc import CLPC
from clpc.distributed import run_long, shared_rows
from clpc.distributed.long_record import plan_record
from clpc.distributed.piece_tasks import (
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
@pytest.mark.parametrize("seen", [(True,), (True, False)])
def test_pieces_in_the_shared_trace_settled_by_the_client_give_the_single_process_trace(seen):
    # in this process: the pieces' kernels write into the file and the client settles them
    # in its own map; with (True, False) every other piece is solved by a process that
    # does not see the file and its rows are sent (put into the map by the client)
    from clpc.distributed.long_record import _Joined

    n, settings = 12_011, {"window_size": 60, "cluster_size": 6}
    u, y = _record(n)
    ref = CLPC(**settings).run(u, y)
    held = ref.has_model & ~ref.accepted
    assert held[(ref.index > 3_500) & (ref.index < 6_500)].all()  # held across pieces
    plan, pieces = _pieces(n, settings, 2_000)
    made = SharedRows.create(plan.state().empty_trace(), len(ref), ((1,), (1,)))
    assert made is not None
    shared = made[0]
    blind = SharedRows(shared.path + "-elsewhere", shared.rows, shared.slots, shared.size)
    joined = _Joined(plan, made)
    try:
        state = plan.initial()
        for piece, sees in zip(pieces, seen * len(pieces), strict=False):
            lo, hi = piece.raw
            solved = solve_piece((u[lo:hi], y[lo:hi]), plan, piece, shared if sees else blind)
            info = piece_info(solved)
            assert solved.shared == info.shared == sees
            part = joined.settle(piece, info, state) if sees else finish_piece(solved, plan, state)
            joined.add(part)
            state = next_state(state, info)
    finally:
        shared.remove()
    assert not os.path.exists(shared.path)
    got = joined.result()  # the client's map still holds the rows
    _assert_equal(ref, got)
    levels = (got.meta["window_level"], ref.meta["window_level"])
    np.testing.assert_allclose(*levels, rtol=1e-12, atol=1e-13)


@needs_shm
def test_a_second_run_of_a_piece_leaves_the_rows_the_client_settled():
    # Dask re-runs a solve whose worker died, maybe after the client heard from the first
    # run and settled its rows in place: the re-run must not write them again
    from clpc.distributed.long_record import _Joined

    n, settings = 12_011, {"window_size": 60, "cluster_size": 6}
    u, y = _record(n)
    ref = CLPC(**settings).run(u, y)
    plan, pieces = _pieces(n, settings, 2_000)
    made = SharedRows.create(plan.state().empty_trace(), len(ref), ((1,), (1,)))
    assert made is not None
    shared, joined, state = made[0], _Joined(plan, made), plan.initial()
    held = [p for p in pieces if 3_500 < p.raw[0] < 6_000]  # starts holding an older model
    assert held
    try:
        for piece in pieces:
            lo, hi = piece.raw
            solved = solve_piece((u[lo:hi], y[lo:hi]), plan, piece, shared)
            assert solved.shared
            joined.add(joined.settle(piece, piece_info(solved), state))
            state = next_state(state, piece_info(solved))
        for piece in held:  # the re-runs, after the client settled the pieces
            lo, hi = piece.raw
            again = solve_piece((u[lo:hi], y[lo:hi]), plan, piece, shared)
            assert not again.shared  # solved into its own arrays
            assert not again.trace.has_model[0].all()  # unsettled: would have undone the settle
    finally:
        shared.remove()
    assert not list(shared_rows.SHM.glob(os.path.basename(shared.path) + "*"))
    _assert_equal(ref, joined.result())


def test_a_process_that_does_not_see_the_file_sends_its_rows(tmp_path):
    n, settings = 9_007, {"window_size": 60, "cluster_size": 6}
    u, y = _record(n)
    ref = CLPC(**settings).run(u, y)
    plan, pieces = _pieces(n, settings, 3_000)
    like = plan.state().empty_trace()
    made = SharedRows.create(like, len(ref), ((1,), (1,)), folder=tmp_path)
    assert made is not None
    shared = SharedRows(str(tmp_path / "elsewhere"), *(made[0].rows, made[0].slots, made[0].size))
    state, parts = plan.initial(), []
    for piece in pieces:
        lo, hi = piece.raw
        solved = solve_piece((u[lo:hi], y[lo:hi]), plan, piece, shared)
        assert not solved.shared and not piece_info(solved).shared
        parts.append(finish_piece(solved, plan, state))
        state = next_state(state, piece_info(solved))
    from clpc.appraiser.trace import Trace

    _assert_equal(ref, Trace.concat(parts))
    made[0].remove()


@needs_shm
def test_a_claim_made_as_the_record_ends_does_not_outlive_it(monkeypatch):
    # a late re-run of a piece opens the file just before the client removes it, then
    # claims its rows: the claim is taken back, nothing is left in /dev/shm
    n, settings = 6_011, {"window_size": 60, "cluster_size": 6}
    plan, _ = _pieces(n, settings, 2_000)
    like = plan.state().empty_trace()
    made = SharedRows.create(like, 900, ((1,), (1,)))
    assert made is not None
    shared, real_open = made[0], os.open

    def open_then_end(path, flags, *mode):
        if flags & os.O_EXCL:  # the claim: the client ends the record just before it
            shared.remove()
        return real_open(path, flags, *mode)

    monkeypatch.setattr(shared_rows.os, "open", open_then_end)
    assert shared.open(like, (0, 100)) is None
    monkeypatch.undo()
    assert not list(shared_rows.SHM.glob(os.path.basename(shared.path) + "*"))


@pytest.mark.parametrize("shm", [True, False])
def test_run_long_is_clpc_run_with_or_without_shared_memory(
    client, monkeypatch, tmp_path, shm, own_shm, shm_files
):
    if shm and not shared_rows.SHM.is_dir():
        pytest.skip("no /dev/shm")
    if not shm:  # the client cannot make the file: every piece's rows are sent
        monkeypatch.setattr(shared_rows, "SHM", tmp_path / "missing")
    import dask.array as da

    u, y = _record(40_009)
    ref = CLPC().run(u, y)
    before = shm_files()
    got = run_long(CLPC(), da.from_array(u, chunks=7_000), da.from_array(y, chunks=9_000),
                   client=client, piece_samples=6_000)  # fmt: skip
    _assert_equal(ref, got)
    levels = (got.meta["window_level"], ref.meta["window_level"])
    np.testing.assert_allclose(*levels, rtol=1e-12, atol=1e-13)  # as test_distributed_long
    assert shm_files() == before  # the file is removed when the record is done


@needs_shm
def test_the_file_is_sparse_until_a_writer_reserves_its_rows(monkeypatch):
    plan, _ = _pieces(12_011, {"window_size": 60, "cluster_size": 6}, 2_000)
    like = plan.state().empty_trace()
    shared, mapped = SharedRows.create(like, 2_000, ((1,),))
    trace = mapped.trace
    try:
        assert os.stat(shared.path).st_blocks == 0  # the client zeroes nothing
        other = shared.open(like, (0, 1_000))
        assert other is not None
        per_row = sum(a.nbytes for a in _arrays(trace).values()) // len(trace) + 8
        assert os.stat(shared.path).st_blocks * 512 >= 1_000 * per_row
        other.trace.arrays["theta"][:1_000] = 1.5  # seen through the client's map
        other.extra[0][:1_000] = 2.5
        assert np.all(trace.arrays["theta"][:1_000] == 1.5) and np.all(
            mapped.extra[0][:1_000] == 2.5
        )
    finally:
        shared.remove()
    # a tmpfs without twice the room: no shared trace (the rows are then sent)
    small = os.statvfs_result((4096, 4096, 10, 1, 1, 10, 1, 1, 0, 255))
    monkeypatch.setattr(shared_rows.os, "statvfs", lambda path: small)
    assert SharedRows.create(like, 2_000, ((1,),)) is None
