"""``track_long``'s pieces in the record's trace in shared memory (``shared_track``).

The workers of the client's machine solve their pieces into a ``/dev/shm`` file; the client
settles them there, a worker writes each piece's Parquet file from its own map of the file,
and the client frees a piece's memory once the file is written and the piece scanned. The
dataset and the summary equal ``CLPC.run``'s trace and ``clpc track``'s summary, with the
shared trace and without it.
"""

from __future__ import annotations

import dataclasses
import os
from concurrent.futures import Future
from pathlib import Path

import numpy as np
import pytest
from scipy import signal

pytest.importorskip("distributed")

from clpc import CLPC
from clpc.distributed import open_source, shared_rows, track_long
from clpc.distributed.long_record import plan_record
from clpc.distributed.long_track import SUMMARY_KEYS
from clpc.distributed.part_file import write_piece
from clpc.distributed.piece_tasks import next_state, piece_info, solve_piece
from clpc.distributed.shared_rows import SharedRows
from clpc.distributed.shared_track import SharedPieces

needs_shm = pytest.mark.skipif(not shared_rows.SHM.is_dir(), reason="no /dev/shm")


def _record(n: int, seed: int = 11):
    """A 2nd-order ARX system; no input over samples 3000-7000 (models held across pieces)."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    u[3_000:7_000] = 0.0
    y = signal.lfilter([0.5, 0.3, 0.1], [1.0, -1.5, 0.7], u) + 0.02 * rng.standard_normal(n)
    return u, y


@pytest.mark.parametrize("shm", [True, False])
def test_track_long_settles_its_pieces_in_shared_memory_and_writes_the_same_dataset(
    client, monkeypatch, tmp_path, shm, own_shm, shm_files
):
    import pandas as pd

    from clpc.appraiser.tracefile import trace_columns
    from clpc.report import trace_summary

    if shm and not shared_rows.SHM.is_dir():
        pytest.skip("no /dev/shm")
    if not shm:  # the client cannot make the file: every piece is settled by its worker
        monkeypatch.setattr(shared_rows, "SHM", tmp_path / "missing")
    u, y = _record(30_011)
    np.save(tmp_path / "rec.npy", np.column_stack([u, y]))
    settings = {"window_size": 90, "cluster_size": 10}
    ref = CLPC(**settings).run(u, y)
    before = shm_files()
    source = open_source(tmp_path / "rec.npy", (0,), (1,))
    done = track_long(CLPC(**settings), source, tmp_path / "out", client=client,
                      piece_samples=2_000)  # fmt: skip
    done.close()
    assert done.parts > 10
    assert done.in_place == (done.parts if shm else 0)
    assert shm_files() == before  # the file is removed
    table = pd.read_parquet(tmp_path / "out" / "trace").sort_values("index")
    named = dataclasses.replace(ref, input_names=("col0",), output_names=("col1",))
    names, want = trace_columns(named)
    assert list(table.columns) == names
    assert np.array_equal(table.to_numpy(dtype=np.float64), want)
    assert done.summary == trace_summary(named)
    assert np.array_equal(done.appraised.recent.index, ref.index[-20:])
    assert np.array_equal(done.appraised.recent.arrays["theta"], ref.arrays["theta"][-20:])


@needs_shm
def test_release_frees_the_pages_of_whole_rows_and_keeps_the_others():
    plan = plan_record(CLPC(window_size=60, cluster_size=6), (1, 1), 60_000)
    like = plan.state().empty_trace()
    shared, mapped = SharedRows.create(like, 9_000, ((1,),))
    try:
        other = shared.open(like, (0, 9_000))  # a writer reserves and fills every row
        assert other is not None
        other.trace.arrays["D"][:] = 2.0
        other.extra[0][:] = 3.0
        full = os.stat(shared.path).st_blocks
        shared.release(mapped, (1_000, 6_000))
        assert os.stat(shared.path).st_blocks < 0.5 * full  # more than half the rows freed
        d, c = mapped.trace.arrays["D"], mapped.extra[0]
        for kept in (slice(0, 1_000), slice(6_000, 9_000)):  # the rows around: untouched
            assert np.all(d[kept] == 2.0) and np.all(c[kept] == 3.0)
        assert np.all(d[1_600:5_400] == 0.0)  # freed pages read as zeros (512 rows a page)
    finally:
        shared.remove()


class _Client:
    """Runs each task at once in this process; its futures are done when ``done`` says."""

    def __init__(self) -> None:
        self.futures: list[Future] = []

    def submit(self, fn, *args, **_dask_keywords):
        fut: Future = Future()
        fut.set_result(fn(*args))
        self.futures.append(fut)
        return fut


@needs_shm
def test_a_pieces_rows_are_freed_only_after_the_summary_took_them(tmp_path):
    # every piece's file is written at once (before the client takes the piece): the rows
    # of a piece not taken yet must stay, or its summary would read zeros
    n, settings = 20_011, {"window_size": 60, "cluster_size": 6}
    u, y = _record(n)
    ref = CLPC(**settings).run(u, y)
    plan = plan_record(CLPC(**settings), (1, 1), n, levels=False)
    pieces = plan.layout.pieces(n, 3_000)
    pieces[-1] = pieces[-1]._replace(raw=(pieces[-1].raw[0], n))
    made = SharedRows.create(plan.state().empty_trace(), len(ref), ((1,),))
    assert made is not None
    seen: list[tuple[int, np.ndarray]] = []

    def sink(part):  # the summary's arrays as the sink sees them, copied
        seen.append((int(part.summary.index[0]), part.summary.arrays["theta"].copy()))

    folder = str(tmp_path / "parts")
    pending = SharedPieces(_Client(), plan, made, folder, (SUMMARY_KEYS, (1, 20)), sink)
    state, parts = plan.initial(), []
    try:
        for piece in pieces:  # solved, settled and written, none taken yet
            lo, hi = piece.raw
            solved = solve_piece((u[lo:hi], y[lo:hi]), plan, piece, made[0])
            assert solved.shared
            info = piece_info(solved)
            parts.append(pending.finish(piece, info, state, None))
            state = next_state(state, info)
        for part in parts:
            pending.take(part)
        pending.wait()
    finally:
        made[0].remove()
    assert pending.pieces == len(pieces)
    starts = [int(np.searchsorted(ref.index, first)) for first, _ in seen]
    for (_, theta), start in zip(seen, starts, strict=True):
        assert np.array_equal(theta, ref.arrays["theta"][start : start + len(theta)])
    # the files are those a worker writes from its own rows
    import pandas as pd

    mine = pd.read_parquet(Path(folder))
    state = plan.initial()
    for piece in pieces:
        lo, hi = piece.raw
        solved = solve_piece((u[lo:hi], y[lo:hi]), plan, piece)
        write_piece(solved, plan, state, str(tmp_path / "own"), SUMMARY_KEYS, (1, 20))
        state = next_state(state, piece_info(solved))
    own = pd.read_parquet(tmp_path / "own")
    assert np.array_equal(mine.to_numpy(dtype=float), own.to_numpy(dtype=float))


@needs_shm
def test_a_worker_killed_while_it_solves_or_writes_leaves_the_dataset_and_summary(tmp_path):
    """SIGKILL a worker busy with a piece: Dask reruns its tasks; the dataset is equal."""
    import signal as signals
    import threading
    import time

    import distributed
    import pandas as pd

    from clpc.appraiser.tracefile import trace_columns
    from clpc.report import trace_summary

    u, y = _record(400_000)
    np.save(tmp_path / "rec.npy", np.column_stack([u, y]))
    ref = CLPC().run(u, y)
    named = dataclasses.replace(ref, input_names=("col0",), output_names=("col1",))
    killed: dict = {}
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as c,
    ):
        c.wait_for_workers(2)
        pids = c.run(os.getpid)  # worker address -> its process id

        def kill_a_busy_worker() -> None:
            deadline = time.monotonic() + 60
            while not killed and time.monotonic() < deadline:
                busy = [
                    (a, k)
                    for a, keys in c.processing().items()
                    for k in keys
                    if a in pids and ("solve" in str(k) or "write_shared" in str(k))
                ]
                if busy:
                    os.kill(pids[busy[0][0]], signals.SIGKILL)
                    killed.update(pid=pids[busy[0][0]], task=str(busy[0][1]))
                time.sleep(0.005)

        killer = threading.Thread(target=kill_a_busy_worker)
        killer.start()
        source = open_source(tmp_path / "rec.npy", (0,), (1,))
        done = track_long(CLPC(), source, tmp_path / "out", client=c, piece_samples=20_000)
        done.close()
        killer.join()
    assert killed, "no worker was busy with a piece"
    table = pd.read_parquet(tmp_path / "out" / "trace").sort_values("index")
    assert np.array_equal(table.to_numpy(dtype=np.float64), trace_columns(named)[1])
    assert done.summary == trace_summary(named)
