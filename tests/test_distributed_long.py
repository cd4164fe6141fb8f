"""One long record on a Dask cluster (issue 27 item 2): the trace equals ``CLPC.run``'s.

A real LocalCluster of 2 worker processes; records of 1e4-3e4 samples cut into many
pieces with awkward lengths (pieces that start mid-cluster, a last piece shorter than a
window, W and C dividing nothing). The reference is the single-process ``CLPC(...).run``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy import signal

pytest.importorskip("distributed")
da = pytest.importorskip("dask.array")

from clpc import CLPC, DataError  # noqa: E402
from clpc.appraiser.decimation import decimate  # noqa: E402
from clpc.distributed import open_source, run_long  # noqa: E402
from clpc.distributed.pieces import Layout, warmup  # noqa: E402


def _record(n: int, seed: int = 3, quiet: tuple[int, int] | None = None):
    """A 2nd-order ARX system under white input; ``quiet``: a stretch of zero input."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    if quiet is not None:
        u[quiet[0] : quiet[1]] = 0.0
    y = signal.lfilter([0.5, 0.3, 0.1], [1.0, -1.5, 0.7], u) + 0.02 * rng.standard_normal(n)
    return u, y


def _assert_same(ref, got, exact: bool = True):
    assert len(got) == len(ref) > 0
    for f in ("index", "rows", "not_enough_data", "time"):
        assert np.array_equal(getattr(got, f), getattr(ref, f)), f
    assert got.arrays.keys() == ref.arrays.keys()
    for key, want in ref.arrays.items():
        have = got.arrays[key]
        assert have.dtype == want.dtype and have.shape == want.shape, key
        if exact or want.dtype.kind in "bi":
            assert np.array_equal(have, want), key
        else:
            np.testing.assert_allclose(have, want, rtol=1e-12, atol=1e-12, err_msg=key)
    assert got.sample_time == ref.sample_time
    assert (got.input_names, got.output_names) == (ref.input_names, ref.output_names)
    np.testing.assert_allclose(
        got.meta["window_level"], ref.meta["window_level"], rtol=1e-12, atol=1e-13
    )
    assert {k: v for k, v in got.meta.items() if k != "window_level"} == {
        k: v for k, v in ref.meta.items() if k != "window_level"
    }


def test_pieces_cover_every_update_once_with_the_rows_their_windows_need():
    for w, c, m, f in [(201, 12, 2, 1), (50, 7, 3, 1), (40, 5, 2, 3), (13, 13, 1, 1)]:
        lay = Layout(w, c, m, f)
        n_raw = 10_007
        pieces = lay.pieces(n_raw, 333)
        js = np.concatenate([np.arange(p.j_lo, p.j_hi + 1) for p in pieces])
        assert np.array_equal(js, np.arange(1, lay.updates(n_raw) + 1))
        for p in pieces:
            k_lo, k_hi = p.kept
            for j in (p.j_lo, p.j_hi):  # window j: rows [max(0, Cj - W), Cj), samples r..r+m
                assert k_lo <= max(0, c * j - w) and c * j - 1 + m < k_hi
            assert k_lo % c == 0  # block-aligned: the kernel's blocks start there
            assert p.raw[0] % f == 0 and p.raw[0] <= k_lo * f and (k_hi - 1) * f < p.raw[1]
            assert p.raw[1] <= n_raw


@pytest.mark.parametrize(
    ("n", "settings", "piece"),
    [
        (20_011, {}, 1_000),  # the paper's W = 201, C = 12; pieces start mid-cluster
        (12_347, {"window_size": 50, "cluster_size": 7, "order": 3}, 333),
        (10_003, {"window_size": 64, "cluster_size": 16, "guard": False}, 4_099),
        # pieces of several kernel batches (> 2048 updates) and blocks of 8 rows (C = 2):
        # pieces start at multiples of C, not of the block
        (30_011, {"window_size": 50, "cluster_size": 2}, 9_002),
    ],
)
def test_a_dask_record_gives_the_single_process_trace_bit_for_bit(client, n, settings, piece):
    u, y = _record(n)
    ref = CLPC(**settings).run(u, y)
    got = run_long(
        CLPC(**settings),
        da.from_array(u, chunks=1_777),
        da.from_array(y, chunks=2_500),
        client=client,
        piece_samples=piece,
    )
    _assert_same(ref, got)


def test_the_fsm_state_is_carried_across_pieces_without_an_accepted_update(client):
    # zero input over 3000 samples: no window there is trusted, the held model crosses
    # several pieces of 500 samples unchanged
    u, y = _record(12_000, quiet=(4_000, 7_000))
    ref = CLPC(window_size=60, cluster_size=6).run(u, y)
    held = ~ref.accepted & ref.has_model
    assert held.sum() > 3 * 500 // 6  # more than 3 pieces of held updates
    got = run_long(
        CLPC(window_size=60, cluster_size=6),
        da.from_array(u, chunks=3_000),
        da.from_array(y, chunks=3_000),
        client=client,
        piece_samples=500,
    )
    _assert_same(ref, got)


def test_clpc_run_takes_a_dask_array_and_multichannel_records(client):
    rng = np.random.default_rng(5)
    u = rng.standard_normal((9_001, 2))
    y = np.column_stack(
        [
            signal.lfilter([0.4, 0.2], [1.0, -0.6], u[:, 0]),
            signal.lfilter([1.0], [1, -0.3], u[:, 1]),
        ]
    ) + 0.01 * rng.standard_normal((9_001, 2))
    ref = CLPC(order=1, window_size=80, cluster_size=9).run(u, y)
    # CLPC.run hands the dask array to the distributed runner (a local cluster of its own)
    got = CLPC(order=1, window_size=80, cluster_size=9).run(
        da.from_array(u, chunks=(2_000, 2)), da.from_array(y, chunks=(3_000, 2))
    )
    _assert_same(ref, got)
    # one of the two in memory (it goes to the workers as a dask array)
    got = run_long(CLPC(order=1, window_size=80, cluster_size=9), u, da.from_array(y),
                   client=client, piece_samples=2_000)  # fmt: skip
    _assert_same(ref, got)


def test_decimation_agrees_to_rounding_and_the_warmup_is_what_makes_it(client):
    u, y = _record(30_011)
    kw = {"dt": 0.01, "decimate_to": 0.03, "window_size": 40, "cluster_size": 5}
    ref = CLPC(**kw).run(u, y)
    got = run_long(
        CLPC(**kw), da.from_array(u, chunks=4_000), da.from_array(y, chunks=4_000),
        client=client, piece_samples=1_000,
    )  # fmt: skip
    _assert_same(ref, got, exact=False)
    # the filter of a piece started warmup(f) samples early agrees with the whole record's;
    # started at the piece itself it would not
    whole = decimate(y, 3)
    a = 3 * 5_000
    for early, tol in ((warmup(3), 1e-12), (0, None)):
        part = decimate(y[a - early :], 3)[early // 3 :][:2_000]
        diff = np.max(np.abs(part - whole[a // 3 : a // 3 + 2_000]))
        assert diff <= 1e-12 if tol else diff > 1e-6


def test_npy_and_parquet_files_are_read_by_the_workers(client, tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    u, y = _record(15_013)
    table = np.column_stack([np.arange(u.size) * 0.01, u, y])
    np.save(tmp_path / "rec.npy", table)
    pq.write_table(
        pa.table({"t": table[:, 0], "u": u, "y": y}), tmp_path / "rec.parquet", row_group_size=2_048
    )
    ref = CLPC(window_size=70, cluster_size=11).run(u, y)
    for path, cols in (("rec.npy", ((1,), (2,))), ("rec.parquet", (("u",), ("y",)))):
        source = open_source(tmp_path / path, *cols)
        got = run_long(
            CLPC(window_size=70, cluster_size=11), source, client=client, piece_samples=777
        )
        assert got.input_names == source.names()[0]
        got = dataclasses.replace(got, input_names=("u",), output_names=("y",))
        _assert_same(ref, got)


def test_bad_samples_and_short_records_behave_as_in_one_process(client):
    u, y = _record(6_000)
    y[4_321] = np.nan
    with pytest.raises(DataError, match="4321") as single:
        CLPC().run(u, y)
    with pytest.raises(DataError, match="4321") as spread:
        run_long(CLPC(), da.from_array(u, chunks=1_000), da.from_array(y, chunks=1_000),
                 client=client, piece_samples=500)  # fmt: skip
    assert str(spread.value) == str(single.value)
    # a record shorter than one cluster: no update, the same (empty) trace
    u, y = _record(13)
    ref = CLPC().run(u, y)
    got = run_long(CLPC(), da.from_array(u, chunks=50), da.from_array(y, chunks=50), client=client)
    assert len(ref) == len(got) == 0 and got.arrays.keys() == ref.arrays.keys()
    # channels of hopeless scales are refused as in one process
    u, y = _record(3_000)
    with pytest.raises(DataError, match="differ in scale"):
        small, big = da.from_array(u * 1e-9, chunks=1_000), da.from_array(y * 1e9, chunks=1_000)
        run_long(CLPC(), small, big, client=client, piece_samples=500)


def test_the_workers_write_the_trace_as_a_dataset_and_the_summary_reads_all_of_it(client, tmp_path):
    import pandas as pd

    from clpc.appraiser.tracefile import trace_columns
    from clpc.distributed import track_long
    from clpc.report import trace_summary

    u, y = _record(20_003)
    np.save(tmp_path / "rec.npy", np.column_stack([u, y]))
    settings = {"window_size": 90, "cluster_size": 10}
    ref = CLPC(**settings).run(u, y)
    source = open_source(tmp_path / "rec.npy", (0,), (1,))
    for _ in range(2):  # a second run replaces the first run's dataset
        result = track_long(CLPC(**settings), source, tmp_path / "out", client=client,
                            piece_samples=1_500)  # fmt: skip
    assert result.parts == len(list((tmp_path / "out" / "trace").glob("part-*.parquet"))) > 5
    assert not list((tmp_path / "out").glob(".trace*"))  # no staging folder left
    table = pd.read_parquet(tmp_path / "out" / "trace")
    table = table.sort_values("index")
    ref = dataclasses.replace(ref, input_names=("col0",), output_names=("col1",))
    names, want = trace_columns(ref)
    assert list(table.columns) == names
    assert np.array_equal(table.to_numpy(dtype=np.float64), want)
    expected = trace_summary(ref)
    assert result.summary == expected
    assert result.model is not None and result.model_source == expected["model_source"]
    # what the report is made of: the updates clpc track's thinning keeps, the last ones,
    # the record's last samples
    from clpc.appraiser.tracefile import ThinnedTrace
    from clpc.workflows.track import REPORT_SAMPLES

    thin = ThinnedTrace(300)
    thin.add(ref)
    small = track_long(CLPC(**settings), source, tmp_path / "o2", client=client,
                       piece_samples=1_500, figure_updates=300)  # fmt: skip
    figures, want = small.appraised.figures, thin.trace()
    assert want.meta["thinned_stride"] > 1
    assert figures.meta["thinned_stride"] == want.meta["thinned_stride"]
    assert figures.meta["updates_total"] == want.meta["updates_total"] == len(ref)
    assert np.array_equal(figures.index, want.index)
    for key, value in want.arrays.items():
        assert np.array_equal(figures.arrays[key], value), key
    assert np.array_equal(small.appraised.recent.index, ref.index[-20:])
    assert np.array_equal(small.appraised.tail, np.column_stack([u, y])[-REPORT_SAMPLES:])
    assert small.appraised.n_samples == u.size


def test_clpc_track_workers_writes_what_clpc_track_writes(tmp_path):
    import pandas as pd
    from click.testing import CliRunner

    from clpc.cli import cli

    u, y = _record(24_001)
    np.save(tmp_path / "rec.npy", np.column_stack([u, y]))
    common = ["track", str(tmp_path / "rec.npy"), "-u", "0", "-y", "1", "--dt", "0.01"]
    common += ["--window-size", "120", "--cluster-size", "10"]
    runner = CliRunner()
    one = runner.invoke(cli, [*common, "--out", str(tmp_path / "one"), "--format", "parquet"])
    assert one.exit_code == 0, one.output
    two = runner.invoke(cli, [*common, "--out", str(tmp_path / "two"), "--workers", "2"])
    assert two.exit_code == 0, two.output
    single = pd.read_parquet(tmp_path / "one" / "trace.parquet")
    spread = pd.read_parquet(tmp_path / "two" / "trace").sort_values("index")
    assert list(spread.columns) == list(single.columns)
    assert np.array_equal(spread.to_numpy(dtype=float), single.to_numpy(dtype=float))
    # the same summary, advice and model printed; the same report files beside the dataset
    printed = [line for line in one.output.splitlines() if not line.startswith("wrote")]
    assert [line for line in two.output.splitlines() if line in printed] == printed
    figures = {p.name for p in (tmp_path / "one").iterdir() if p.suffix in (".png", ".html")}
    assert "report.html" in figures
    assert figures <= {p.name for p in (tmp_path / "two").iterdir()}
    bad = runner.invoke(cli, [*common[:2], "--workers", "2", "-u", "0", "-y", "1", "--time", "t",
                              "--out", str(tmp_path / "x")])  # fmt: skip
    assert bad.exit_code != 0 and "--dt" in bad.output


def test_each_output_carries_its_own_held_model_across_pieces(client):
    # two outputs; output 1 is zero over 4000 samples, so equation 1 accepts nothing in
    # several pieces while equation 0 accepts in every one: the state a piece starts in
    # comes from different pieces for the two equations
    rng = np.random.default_rng(8)
    u = rng.standard_normal((14_003, 2))
    y = np.column_stack(
        [
            signal.lfilter([0.4, 0.2], [1.0, -0.6], u[:, 0]),
            signal.lfilter([1.0, 0.5], [1, -0.3], u[:, 1]),
        ]
    ) + 0.01 * rng.standard_normal((14_003, 2))
    y[5_000:9_000, 1] = 0.0
    kw = {"order": 1, "window_size": 70, "cluster_size": 7}
    ref = CLPC(**kw).run(u, y)
    held = ~ref.accepted[:, 1] & ref.has_model[:, 1]
    assert held.sum() > 3 * 600 // 7 and ref.accepted[:, 0][held].all()
    u_d, y_d = da.from_array(u, chunks=(3_000, 2)), da.from_array(y, chunks=(3_000, 2))
    got = run_long(CLPC(**kw), u_d, y_d, client=client, piece_samples=600)
    _assert_same(ref, got)


def test_the_long_summary_is_clpc_tracks_bit_for_bit(client, tmp_path):
    import json

    import clpc.workflows as wf
    from clpc.distributed import track_long

    u, y = _record(30_007, quiet=(12_000, 15_000))
    np.save(tmp_path / "rec.npy", np.column_stack([u, y]))
    appraiser = wf.AppraiserSettings(order=2, window_size=90, cluster_size=10)
    record = wf.RecordSpec(str(tmp_path / "rec.npy"), ("0",), ("1",))
    plain = wf.track_file(wf.TrackSettings(record, str(tmp_path / "plain"), appraiser,
                                           chunk_rows=1_000))  # fmt: skip
    source = open_source(tmp_path / "rec.npy", (0,), (1,))
    done = track_long(appraiser.build(None), source, tmp_path / "long", client=client,
                      piece_samples=1_300)  # fmt: skip
    done.close()
    written = (tmp_path / "long" / "summary.json").read_text()
    assert plain.summary["updates"] == len(CLPC(window_size=90, cluster_size=10).run(u, y))
    assert json.loads(written) == done.summary
    # the summary JSON of clpc track (the advice aside: made from the report's data)
    want = {k: v for k, v in plain.summary.items() if k != "advice"}
    assert json.dumps(done.summary, indent=1) == json.dumps(want, indent=1)


def test_a_worker_killed_mid_record_leaves_the_trace_bit_for_bit(tmp_path):
    """SIGKILL a worker while it solves a piece: Dask reruns its pieces, the trace is equal."""
    import os
    import signal as signals
    import threading
    import time

    import distributed

    u, y = _record(400_000)
    ref = CLPC().run(u, y)
    killed: dict = {}
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        client.wait_for_workers(2)
        pids = client.run(os.getpid)  # worker address -> its process id

        def kill_a_busy_worker() -> None:
            deadline = time.monotonic() + 60
            while not killed and time.monotonic() < deadline:
                busy = [
                    a
                    for a, keys in client.processing().items()
                    if a in pids and any("solve" in str(k) for k in keys)
                ]
                if busy:
                    os.kill(pids[busy[0]], signals.SIGKILL)
                    killed.update(pid=pids[busy[0]])
                time.sleep(0.01)

        killer = threading.Thread(target=kill_a_busy_worker)
        killer.start()
        got = run_long(
            CLPC(),
            da.from_array(u, chunks=50_000),
            da.from_array(y, chunks=50_000),
            client=client,
            piece_samples=20_000,
        )
        killer.join()
    assert killed, "no worker was solving a piece"
    _assert_same(ref, got)
