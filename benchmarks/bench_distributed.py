"""A fleet on Dask against one process, in one invocation (issue 27 item 5, the fleet half).

Writes a fleet of ``--records`` Parquet records of ``--samples`` samples (a random +-1 input
held 10 samples through a second-order axis, noise added), then tracks every record

1. in this process, one after the other: :func:`clpc.workflows.fleet_record.track_record`,
   the function a worker runs, so both sides do exactly the same work (trace, figures,
   report per record);
2. with :func:`clpc.track_many` on the ``LocalCluster`` it starts
   (:func:`clpc.distributed.dask_client`) of 1 and of 2 worker processes (one thread each).

Each side is warmed first (one short record per process: imports, numba's cached kernels,
matplotlib), then timed best of ``--repeat``. Printed per run: wall time, samples/s, speed-up
against the single process, and

* **scheduler overhead per record**: ``(workers x wall - sum of the records' own times on
  the workers) / records`` - the time a worker slot was not running a record (scheduling,
  transfers, the client's final table and report, idle at the end), per record;
* **bytes over the network per record**: the pickled task (function reference, record
  source, settings, output folder) and the pickled summary row sent back; the record's
  samples never travel (their size is printed beside).

The machine's load average is printed before and after: on a shared machine the speed-up
of 2 workers is only meaningful when the load is below about 0.5.

    python benchmarks/bench_distributed.py            # 100 records x 1e5 samples (minutes)
    python benchmarks/bench_distributed.py --quick    # 8 records x 2e4 samples
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # the workers inherit it: one core per process

import argparse  # noqa: E402
import pickle  # noqa: E402
import shutil  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from scipy import signal  # noqa: E402

SETTINGS = {"inputs": "u", "outputs": "y", "dt": 0.001}


def write_fleet(folder: Path, n_records: int, n_samples: int) -> list[Path]:
    files = []
    for k in range(n_records):
        rng = np.random.default_rng(k)
        u = np.repeat(rng.choice([-1.0, 1.0], n_samples // 10 + 1), 10)[:n_samples]
        gain = 0.8 if k == n_records // 2 else 1.0
        y = signal.lfilter([0.0, 0.1 * gain, 0.05 * gain], [1.0, -1.5, 0.7], u)
        y += 0.01 * rng.standard_normal(n_samples)
        f = folder / f"axis{k:03d}.parquet"
        pd.DataFrame({"u": u, "y": y}).to_parquet(f)
        files.append(f)
    return files


def single_process(files: list[Path], out: Path) -> tuple[float, float]:
    """Wall and CPU seconds of tracking every record here, one after the other."""
    from clpc.workflows.fleet_record import track_record
    from clpc.workflows.fleet_settings import FleetSettings
    from clpc.workflows.fleet_sources import expand_sources

    settings = FleetSettings.from_keywords(**SETTINGS)
    records = expand_sources([str(f) for f in files])
    t0, c0 = time.perf_counter(), time.process_time()
    rows = [track_record(r, settings, str(out)) for r in records]
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    failed = [r["error"] for r in rows if r["error"]]
    assert not failed, failed
    return wall, cpu


def on_cluster(client, files: list[Path], out: Path) -> tuple[float, list[dict]]:
    """Wall seconds of ``track_many`` on ``client``, and the rows as they came back."""
    from clpc import track_many

    rows: list[dict] = []
    t0 = time.perf_counter()
    result = track_many(
        [str(f) for f in files],
        client=client,
        out=out,
        progress=lambda done, total, row: rows.append(row),
        **SETTINGS,
    )
    wall = time.perf_counter() - t0
    assert result.table["error"].isna().all(), result.table["error"].tolist()
    return wall, rows


def warm_worker(file: str, out: str) -> None:
    """Track a short record in this process (imports, numba's cached kernels, matplotlib)."""
    from clpc.workflows.fleet_record import track_record
    from clpc.workflows.fleet_settings import FleetSettings
    from clpc.workflows.fleet_sources import expand_sources

    settings = FleetSettings.from_keywords(**SETTINGS)
    row = track_record(expand_sources(file)[0], settings, f"{out}-{os.getpid()}")
    assert row["error"] is None, row["error"]


def task_bytes(files: list[Path], out: Path) -> tuple[int, int]:
    """Pickled size of one task's arguments and of one record's file."""
    from clpc.workflows.fleet_record import track_record
    from clpc.workflows.fleet_settings import FleetSettings
    from clpc.workflows.fleet_sources import expand_sources

    settings = FleetSettings.from_keywords(**SETTINGS)
    record = expand_sources(str(files[0]))[0]
    return len(pickle.dumps((track_record, record, settings, str(out)))), files[0].stat().st_size


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=100)
    parser.add_argument("--samples", type=float, default=1e5)
    parser.add_argument("--repeat", type=int, default=1, help="best of this many runs")
    parser.add_argument("--quick", action="store_true", help="8 records x 2e4 samples")
    args = parser.parse_args()
    if args.quick:
        args.records, args.samples = 8, 2e4
    n_rec, n_samp = args.records, int(args.samples)
    from clpc.distributed import dask_client

    print(f"load average before: {os.getloadavg()}")
    print(f"fleet: {n_rec} records x {n_samp} samples (Parquet, dt = 1 ms)")
    with tempfile.TemporaryDirectory(prefix="clpc-bench-fleet-") as tmp:
        root = Path(tmp)
        (root / "data").mkdir()
        (root / "warm").mkdir()
        files = write_fleet(root / "data", n_rec, n_samp)
        warm = write_fleet(root / "warm", 1, 3000)
        warm_worker(str(warm[0]), str(root / "warm"))
        best_single, best_cpu = np.inf, np.inf
        for _ in range(args.repeat):
            shutil.rmtree(root / "single", ignore_errors=True)
            wall, cpu = single_process(files, root / "single")
            best_single, best_cpu = min(best_single, wall), min(best_cpu, cpu)
        total = n_rec * n_samp
        print(
            f"single process: {best_single:.2f} s wall ({best_cpu:.2f} s CPU), "
            f"{total / best_single:.3g} samples/s"
        )
        args_size, file_size = task_bytes(files, root / "x")
        for workers in (1, 2):
            with dask_client(workers=workers) as client:  # as track_many starts one
                client.wait_for_workers(workers)
                client.run(warm_worker, str(warm[0]), str(root / "warm"))
                best, rows = np.inf, []
                for r in range(args.repeat):
                    wall, got = on_cluster(client, files, root / f"w{workers}-{r}")
                    if wall < best:
                        best, rows = wall, got
            busy = sum(row["seconds"] for row in rows)
            busy_cpu = sum(row["cpu_seconds"] for row in rows)
            overhead = (workers * best - busy) / n_rec
            row_bytes = float(np.mean([len(pickle.dumps(row)) for row in rows]))
            print(
                f"{workers} worker process(es): {best:.2f} s wall, {total / best:.3g} samples/s, "
                f"speed-up {best_single / best:.2f}x; records' own time on the workers "
                f"{busy:.2f} s ({busy_cpu:.2f} s CPU); "
                f"scheduler overhead {1e3 * overhead:.0f} ms per record; "
                f"network per record: task {args_size} B out, row {row_bytes:.0f} B back "
                f"(the record's file: {file_size} B, read by the worker)"
            )
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
