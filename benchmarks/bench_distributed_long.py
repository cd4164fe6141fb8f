"""One long record on a Dask cluster vs one process (issue 27 items 2 and 5).

Data: the process of ``bench_clpc.py`` (white Gaussian input through the 2nd-order ARX system
``A = 1 - 1.5 q^-1 + 0.7 q^-2``, ``B = 0.5 + 0.3 q^-1 + 0.1 q^-2``, equation noise 0.1, white
measurement noise 0.02), ``--samples`` samples (default 1e7) written block by block to a
``(T, 2)`` ``.npy`` file ``[u, y]`` in a temporary folder. Settings: ``order=2``,
``W=201``, ``C=12`` (the paper's Table 1).

Runs, all in one invocation:

* ``single``: ``CLPC().run(u, y)`` in a fresh subprocess (the record loaded into memory first,
  not timed; the trace kept);
* ``run_long N``: :func:`clpc.distributed.run_long` on a ``LocalCluster`` of ``N`` worker
  processes (one thread each): the workers read their memory-mapped slices of the ``.npy``
  file; the trace's rows come back to this process (as ``run`` returns them);
* ``track_long N``: :func:`clpc.distributed.track_long`: the workers write the trace as a
  partitioned Parquet dataset; only the arrays of the summary, the updates of the report's
  figures and the last updates come back (Dask's size estimates of the results);
* like with like for ``track_long``, whose work includes writing the trace and the summary
  that ``CLPC.run`` does not: ``clpc track FILE -u 0 -y 1 --format parquet --out OUT`` in
  one fresh process (:func:`clpc.workflows.track_file`: the Parquet trace file, the summary,
  the figures and ``report.html``; warmed up on a short record first, so the plotting
  imports are not timed), against ``clpc track ... --workers N`` on the same cluster
  (``clpc_track N``: :func:`clpc.distributed.track_command.track_settings`, i.e.
  ``track_long`` then the same report, warmed up the same way);
* the machine alone (``machine_control.py``, in a fresh process before each round): the
  same pieces solved one after the other, then by two plain forked processes, no Dask -
  what this machine gives two processes that minute, against which ``run_long`` on 2
  workers is read too.

Every cluster is started once per ``N``, warmed up on a short record (numba's compiled
kernel is loaded in each worker, the report's imports in this process), then timed. The
``run_long`` trace is compared with the single-process trace array by array (SHA-256 of
every array: bit for bit).

Each distributed run is repeated ``--repeat`` times and the fastest kept; before each round
of the distributed runs the two references run once each (in fresh processes), so that on
a shared machine both sides meet the same load, and the fastest of all their runs is the
reference.
Reported: wall time, samples/s, speed-up over ``single``; pieces; the time the workers spent
computing (summed over the task stream, by task: solve, piece info, finish); the CPU time
of each worker process and of this process (the client and the local cluster's scheduler:
receiving, joining or scanning the parts) - on a loaded machine the CPU times say more than
the wall time; the scheduler overhead per piece = (N x wall - computing) / pieces (time a
worker was not computing: scheduling, transfers, waiting for a core or for the client);
bytes per piece sent between
workers (the workers' ``transfer_incoming_log``, Dask's size estimates) and to this process
(Dask's sizes of the finishes' results: with ``run_long`` on one machine only the windows'
levels, the rows being in the shared trace); peak RSS of each worker and of this process (added by
the run). The load average is printed before and after: the machine may be shared. The
median runs of each side are compared too: on a virtual machine whose own speed moves by a
third from minute to minute, the best of a few runs can be one lucky minute.

Usage::

    python benchmarks/bench_distributed_long.py             # 1e7 samples, 1 and 2 workers
    python benchmarks/bench_distributed_long.py --quick     # 1e6 samples (~1 min)
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
from scipy import signal

DEN = np.array([1.0, -1.5, 0.7])
NUM = np.array([0.5, 0.3, 0.1])
EQ_NOISE, MEAS_NOISE = 0.1, 0.02
SEED = 20240607
#: the distributed runs: run_long and track_long (against CLPC.run), and clpc track
#: --workers (track_long and the report; against clpc track in one process)
MODES = ("run_long", "track_long", "clpc_track")


def generate_npy(path: Path, n: int, block: int = 1_000_000) -> None:
    """``n`` samples of the benchmark process into a ``(n, 2)`` ``.npy`` file ``[u, y]``."""
    rng = np.random.default_rng(SEED)
    out = np.lib.format.open_memmap(path, mode="w+", dtype=np.float64, shape=(n, 2))
    zi_u, zi_e = np.zeros(2), np.zeros(2)
    for lo in range(0, n, block):
        m = min(block, n - lo)
        u = rng.standard_normal(m)
        yu, zi_u = signal.lfilter(NUM, DEN, u, zi=zi_u)
        ye, zi_e = signal.lfilter([1.0], DEN, EQ_NOISE * rng.standard_normal(m), zi=zi_e)
        out[lo : lo + m, 0] = u
        out[lo : lo + m, 1] = yu + ye + MEAS_NOISE * rng.standard_normal(m)
    out.flush()
    del out


def digests(trace: Any) -> dict[str, str]:
    """SHA-256 of every array of a trace (equal digests: bit-for-bit equal arrays)."""
    arrays = {f: getattr(trace, f) for f in ("index", "time", "rows", "not_enough_data")}
    arrays.update(trace.arrays)
    return {
        k: hashlib.sha256(np.ascontiguousarray(v).tobytes()).hexdigest() for k, v in arrays.items()
    }


def _peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def track_settings_of(path: str, out: Path) -> Any:
    """``clpc track PATH -u 0 -y 1 --format parquet --out OUT`` (default appraiser settings)."""
    import clpc.workflows as wf

    record = wf.RecordSpec(path, ("0",), ("1",))
    return wf.TrackSettings(record, str(out), wf.AppraiserSettings(), fmt="parquet")


def single_track(path: str, repeat: int) -> dict[str, Any]:
    """``clpc track`` in this process (call it in a fresh one): trace file, summary, report."""
    import clpc.workflows as wf

    with tempfile.TemporaryDirectory() as tmpdir:
        tmp = Path(tmpdir)
        warm = tmp / "warm.npy"
        np.save(warm, np.load(path, mmap_mode="r")[:50_000])
        wf.track_file(track_settings_of(str(warm), tmp / "warm"))  # imports, compiled kernel
        best = (np.inf, np.inf)
        for i in range(repeat):
            t0, c0 = time.perf_counter(), time.process_time()
            result = wf.track_file(track_settings_of(path, tmp / f"out{i}"))
            best = min(best, (time.perf_counter() - t0, time.process_time() - c0))
    return {"wall": best[0], "cpu": best[1], "updates": result.summary["updates"]}


def single_long(path: str, repeat: int, parts: int = 6) -> dict[str, Any]:
    """``track_long``'s work in this process (call it in a fresh one), one step after another.

    ``CLPC().run`` on the record in memory, its trace written as ``parts`` Parquet files
    as the workers write them (:func:`clpc.distributed.part_file.write_part`), and the
    summary scanned from the same arrays as ``track_long``'s client scans
    (:class:`clpc.appraiser.scanned.ScannedTrace`, :func:`clpc.report.trace_summary`): the
    like-with-like reference of ``track_long``.
    """
    import dataclasses

    from clpc import CLPC
    from clpc.appraiser.scanned import ScannedTrace
    from clpc.distributed.long_track import SUMMARY_KEYS
    from clpc.distributed.part_file import write_part
    from clpc.report import trace_summary

    data = np.load(path)
    u, y = np.ascontiguousarray(data[:, 0]), np.ascontiguousarray(data[:, 1])
    del data
    CLPC().run(u[:20_000], y[:20_000])  # warm-up: the compiled kernel loaded
    best = (np.inf, np.inf)
    with tempfile.TemporaryDirectory() as tmpdir:
        for i in range(repeat):
            t0, c0 = time.perf_counter(), time.process_time()
            trace = CLPC().run(u, y)
            scanned = ScannedTrace(Path(tmpdir))
            cuts = np.linspace(0, len(trace), parts + 1).astype(int)
            for k, (lo, hi) in enumerate(itertools.pairwise(cuts)):
                rows = trace.view(lo, hi)
                write_part(rows, Path(tmpdir) / f"out{i}" / f"part-{k:06d}.parquet")
                keep = {key: v for key, v in rows.arrays.items() if key in SUMMARY_KEYS}
                scanned.add(dataclasses.replace(rows, arrays=keep))
            summary = trace_summary(scanned)
            scanned.close()
            del trace
            best = min(best, (time.perf_counter() - t0, time.process_time() - c0))
    return {"wall": best[0], "cpu": best[1], "updates": summary["updates"]}


def single(path: str, repeat: int) -> dict[str, Any]:
    """The single-process run (in this process: call it in a fresh one)."""
    from clpc import CLPC

    data = np.load(path)
    u, y = np.ascontiguousarray(data[:, 0]), np.ascontiguousarray(data[:, 1])
    del data
    CLPC().run(u[:20_000], y[:20_000])  # warm-up: the compiled kernel loaded
    before = _peak_rss_mb()
    best = (np.inf, np.inf)
    trace = None
    for _ in range(repeat):
        trace = None
        t0, c0 = time.perf_counter(), time.process_time()
        trace = CLPC().run(u, y)
        best = min(best, (time.perf_counter() - t0, time.process_time() - c0))
    return {
        "wall": best[0],
        "cpu": best[1],
        "updates": len(trace),
        "digests": digests(trace),
        "rss_added_mb": _peak_rss_mb() - before,
    }


def _task_seconds(stream: list[dict[str, Any]]) -> dict[str, float]:
    out: dict[str, float] = {}
    for task in stream:
        name = str(task["key"]).split("-")[0].strip("('")
        for ss in task["startstops"]:
            if ss["action"] == "compute":
                out[name] = out.get(name, 0.0) + ss["stop"] - ss["start"]
    return out


def _incoming_bytes(client: Any) -> int:
    logs = client.run(
        lambda dask_worker: sum(d["total"] for d in dask_worker.transfer_incoming_log)
    )
    return int(sum(logs.values()))


def distributed_runs(
    path: str, n_workers: int, tmp: Path, repeat: int = 1, between: Any = None
) -> list[dict[str, Any]]:
    """``run_long`` and ``track_long`` on a local cluster of ``n_workers`` processes.

    ``between()``, if given, is called before each round of the modes (the references run
    there, in turn with the distributed runs, so that both meet the same load).
    """
    import distributed

    from clpc import CLPC
    from clpc.distributed import dask_client, run_long, track_long
    from clpc.distributed.sources import NpySource
    from clpc.distributed.track_command import track_settings

    source = NpySource(path, (0,), (1,))
    warm = tmp / "warm.npy"
    np.save(warm, np.load(path, mmap_mode="r")[:50_000])
    rows = []
    with dask_client(workers=n_workers) as client:
        for _ in range(2):  # every worker loads the kernel
            run_long(CLPC(), NpySource(str(warm), (0,), (1,)), client=client, piece_samples=10_000)
        # the report's imports in this process, as the single clpc track's warm-up does
        track_settings(track_settings_of(str(warm), tmp / "warm"), client=client)
        for mode in [m for _ in range(repeat) for m in MODES]:
            if mode == MODES[0] and between is not None:
                between()
            base = _incoming_bytes(client)
            rss0 = _peak_rss_mb()
            cpu0 = client.run(time.process_time)
            with distributed.get_task_stream(client) as ts:
                t0, c0 = time.perf_counter(), time.process_time()
                if mode == "run_long":
                    trace = run_long(CLPC(), source, client=client)
                    wall = time.perf_counter() - t0
                    updates = len(trace)
                elif mode == "track_long":
                    result = track_long(CLPC(), source, tmp / f"out{n_workers}", client=client)
                    wall = time.perf_counter() - t0
                    updates = result.summary["updates"]
                    result.close()
                else:  # clpc track --workers N: track_long, then the report
                    done, _ = track_settings(
                        track_settings_of(path, tmp / f"cli{n_workers}"), client=client
                    )
                    wall = time.perf_counter() - t0
                    updates = done.summary["updates"]
                client_cpu = time.process_time() - c0
            cpu1 = client.run(time.process_time)
            worker_cpu = [cpu1[w] - cpu0[w] for w in cpu1 if w in cpu0]
            equal = None
            if mode == "run_long":  # checked after the timing
                equal = digests(trace)  # compared with the single process's in main
                del trace
            seconds = _task_seconds(ts.data)
            pieces = sum(1 for t in ts.data if str(t["key"]).startswith("solve_piece"))
            computing = sum(seconds.values())
            # what the finishes sent back: Dask's sizes of the results (run_long: the rows,
            # or only the levels when the workers wrote the rows into the shared trace;
            # track_long: summary arrays, figures' and last rows)
            to_client = sum(
                t.get("nbytes", 0)
                for t in ts.data
                if str(t["key"]).startswith(("finish_piece", "write_piece"))
            )
            worker_rss = client.run(
                lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
            )
            rows.append(
                {
                    "mode": mode,
                    "workers": n_workers,
                    "wall": wall,
                    "client_cpu": client_cpu,
                    "worker_cpu": worker_cpu,
                    "updates": updates,
                    "equal": equal,
                    "pieces": pieces,
                    "seconds": seconds,
                    "overhead_per_piece": (n_workers * wall - computing) / pieces,
                    "between_workers_per_piece": (_incoming_bytes(client) - base) / pieces,
                    "to_client_per_piece": to_client / pieces,
                    "worker_peak_rss_mb": max(worker_rss.values()),
                    "client_rss_added_mb": _peak_rss_mb() - rss0,
                }
            )
    return rows


def _ratios(row: dict[str, Any], ref: dict[str, Any]) -> str:
    """The run's speed-ups: against ``CLPC.run``, and like with like for the written trace."""
    wall = row["wall"]
    if row["mode"] == "clpc_track":  # like with like: against clpc track in one process
        return f"{ref['track']['wall'] / wall:5.2f}x clpc track"
    out = f"{ref['wall'] / wall:5.2f}x CLPC.run"
    if row["mode"] == "track_long":  # and against the same work done in one process
        out += f", {ref['long']['wall'] / wall:5.2f}x its work in one process"
    return out


def _show(row: dict[str, Any], n: int, ref: dict[str, Any]) -> None:
    secs, wall = row["seconds"], row["wall"]
    info = secs.get("piece_info", 0.0)
    finish = sum(secs.get(k, 0.0) for k in ("finish_piece", "write_piece", "write_shared_piece"))
    print(
        f"{row['mode']:10s} {row['workers']} worker(s): wall {wall:7.2f} s  "
        f"{n / wall:10.3g} samples/s  speed-up {_ratios(row, ref)}  "
        f"equal to single: {row['equal']}"
    )
    print(
        f"    {row['pieces']} pieces; computing {sum(secs.values()):.2f} s (solve "
        f"{secs.get('solve_piece', 0.0):.2f}, piece info {info:.2f}, finish {finish:.2f})"
        f"; CPU: workers {' + '.join(f'{c:.2f}' for c in row['worker_cpu'])} s, this "
        f"process (client and scheduler) {row['client_cpu']:.2f} s"
        f"; scheduler overhead per piece {1e3 * row['overhead_per_piece']:.1f} ms"
    )
    print(
        f"    bytes per piece: between workers {row['between_workers_per_piece'] / 1e3:.1f} kB, "
        f"to the client {row['to_client_per_piece'] / 1e6:.2f} MB; peak RSS: worker "
        f"{row['worker_peak_rss_mb']:.0f} MB, client added {row['client_rss_added_mb']:.0f} MB"
    )


def _show_control(controls: list[dict[str, float]], rows: dict[int, list[dict[str, Any]]]) -> None:
    """The machine control's runs, and ``run_long`` on 2 workers against it (medians)."""
    print(
        f"\nthe machine alone (machine_control.py: the same {controls[0]['pieces']:.0f} pieces, "
        "no Dask, one process then two plain processes; one before each round):"
    )
    for c in controls:
        print(
            f"  sequential {c['sequential']:5.2f} s  two processes {c['parallel']:5.2f} s  "
            f"{c['ratio']:.2f}x"
        )
    two = [r["wall"] for r in rows.get(2, []) if r["mode"] == "run_long"]
    if two:
        plain = statistics.median(c["parallel"] for c in controls)
        print(
            f"  median {statistics.median(c['ratio'] for c in controls):.2f}x; run_long on 2 "
            f"workers (median {statistics.median(two):.2f} s) takes "
            f"{statistics.median(two) / plain:.2f}x the two plain processes' wall "
            f"(median {plain:.2f} s)"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=float, default=1e7)
    parser.add_argument("--quick", action="store_true", help="1e6 samples")
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeat", type=int, default=1, help="repetitions of each run (best kept)")
    parser.add_argument("--single-worker", nargs=2, help=argparse.SUPPRESS)
    parser.add_argument("--single-track", nargs=2, help=argparse.SUPPRESS)
    parser.add_argument("--single-long", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.single_long:
        print(json.dumps(single_long(args.single_long[0], int(args.single_long[1]))))
        return
    if args.single_worker:
        print(json.dumps(single(args.single_worker[0], int(args.single_worker[1]))))
        return
    if args.single_track:
        print(json.dumps(single_track(args.single_track[0], int(args.single_track[1]))))
        return
    n = int(1e6 if args.quick else args.samples)
    print(f"load average before: {os.getloadavg()}; cores: {os.cpu_count()}")
    with tempfile.TemporaryDirectory() as tmpdir:
        tmp = Path(tmpdir)
        path = tmp / "record.npy"
        t0 = time.perf_counter()
        generate_npy(path, n)
        took = time.perf_counter() - t0
        print(f"record: {n:.3g} samples, {path.stat().st_size / 1e6:.0f} MB ({took:.1f} s)")
        env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
        singles: list[dict[str, Any]] = []
        tracks: list[dict[str, Any]] = []
        longs: list[dict[str, Any]] = []
        flags = (("--single-worker", singles), ("--single-track", tracks), ("--single-long", longs))

        controls: list[dict[str, float]] = []  # the machine's own two-process speed-up
        control_cmd = [sys.executable, str(Path(__file__).with_name("machine_control.py"))]

        def references() -> None:  # one run of each, each in a fresh process
            commands = [([sys.executable, __file__, f, str(path), "1"], out) for f, out in flags]
            for cmd, out in [*commands, ([*control_cmd, str(path)], controls)]:
                done = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env)
                out.append(json.loads(done.stdout))

        rows = {
            w: distributed_runs(str(path), w, tmp, args.repeat, references) for w in args.workers
        }
        ref = min(singles, key=lambda r: r["wall"])
        ref["track"] = track = min(tracks, key=lambda r: r["wall"])
        ref["long"] = long = min(longs, key=lambda r: r["wall"])
        print("\nevery run of the references (in order; one of each before each round):")
        for name, runs in (("CLPC.run", singles), ("clpc track", tracks), ("its work", longs)):
            print(f"  {name:10s} " + "  ".join(f"{r['wall']:.2f} s" for r in runs))
        print(
            f"\nsingle      wall {ref['wall']:7.2f} s  cpu {ref['cpu']:7.2f} s  "
            f"{n / ref['wall']:10.3g} samples/s  {ref['updates']} updates  "
            f"peak RSS added {ref['rss_added_mb']:.0f} MB  (best of {len(singles)})"
        )
        print(
            f"clpc track  wall {track['wall']:7.2f} s  cpu {track['cpu']:7.2f} s  "
            f"{n / track['wall']:10.3g} samples/s  {track['updates']} updates "
            f"(one process: Parquet trace file, summary, figures, report; best of {len(tracks)})"
        )
        print(
            f"its work    wall {long['wall']:7.2f} s  cpu {long['cpu']:7.2f} s  "
            f"(track_long's work in one process: CLPC.run, Parquet parts, summary; best of "
            f"{len(longs)})"
        )
        _show_control(controls, rows)
        for runs in rows.values():
            for row in runs:
                if row["mode"] == "run_long":
                    row["equal"] = row["equal"] == ref["digests"]
            print(f"\nevery run on {runs[0]['workers']} worker(s), against the best references:")
            for row in runs:
                cpu = row["client_cpu"] + sum(row["worker_cpu"])
                print(
                    f"  {row['mode']:10s} wall {row['wall']:5.2f} s  CPU {cpu:5.2f} s "
                    f"(client {row['client_cpu']:.2f})  {_ratios(row, ref)}"
                )
            print("best of each:")
            for mode in MODES:
                _show(min((r for r in runs if r["mode"] == mode), key=lambda r: r["wall"]), n, ref)
            # the machine's own speed moves between runs (by a third on the VM this was
            # written on): the medians, each side's runs interleaved, say it more steadily
            mid = {
                "wall": statistics.median(r["wall"] for r in singles),
                "track": {"wall": statistics.median(r["wall"] for r in tracks)},
                "long": {"wall": statistics.median(r["wall"] for r in longs)},
            }
            print(f"median of each (references: CLPC.run {mid['wall']:.2f} s):")
            for mode in MODES:
                wall = statistics.median(r["wall"] for r in runs if r["mode"] == mode)
                ratios = _ratios({"mode": mode, "wall": wall}, mid)
                print(f"  {mode:10s} wall {wall:5.2f} s  {ratios}")
    print(f"\nload average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
