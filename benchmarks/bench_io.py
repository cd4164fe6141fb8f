"""Data in and start-up: CSV reading, `clpc track` end to end, `import clpc` and `clpc --help`.

Side by side in one run, each the best of ``--repeat`` (the two paths alternating):

* reading a 1e6 x 2 CSV with ``clpc.io.read_table``: the plain reader (``fast=False``:
  ``numpy.loadtxt`` in batches, Python for the messages) against the default path (pyarrow
  when installed); ``pandas.read_csv`` and ``pyarrow.csv.read_csv`` as outside references.
  The values must be identical.
* ``python -m clpc track`` on the same file (subprocesses): ``CLPC_FAST_IO=0`` (plain reader
  and the plain trace writer) against the default; the two ``trace.csv`` must hold the same
  numbers. The phases of one in-process run are timed too (read, appraise, write the trace,
  figures and report), to show where the time goes.
* start-up: ``python -c "import clpc"``, ``clpc --help``, and the eager import of every
  exported name (what ``import clpc`` cost before the names were loaded lazily).

    python benchmarks/bench_io.py               # 1e6 rows
    python benchmarks/bench_io.py --rows 2e5    # quick
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from bench_track import write_record  # noqa: E402  (the same synthetic record)


def best_of(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def run(cmd: list[str], env: dict[str, str] | None = None) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0


def bench_read(path: str, repeat: int) -> None:
    from clpc.io import read_table

    read_table(path)  # pyarrow's import, once
    plain, fast = [], []
    for _ in range(repeat):  # alternating
        plain.append(best_of(lambda: read_table(path, fast=False), 1))
        fast.append(best_of(lambda: read_table(path), 1))
    a, b = read_table(path, fast=False), read_table(path)
    same = np.array_equal(a.data, b.data) and a.names == b.names
    print(f"## read_table, {a.n_rows} x {a.n_columns} CSV ({os.path.getsize(path) / 1e6:.1f} MB)")
    print(f"plain reader (fast=False): {min(plain):.3f} s")
    print(f"default (pyarrow):         {min(fast):.3f} s   -> {min(plain) / min(fast):.1f}x faster")
    print(f"values identical: {same}")
    try:
        import pandas as pd

        print(f"(pandas.read_csv:          {best_of(lambda: pd.read_csv(path), repeat):.3f} s)")
        from pyarrow import csv

        print(f"(pyarrow.csv.read_csv:     {best_of(lambda: csv.read_csv(path), repeat):.3f} s)")
    except ImportError:
        pass
    assert same, "the fast path changed the values"


def bench_track(path: str, repeat: int, work: Path) -> None:
    from clpc.io import read_table

    cmd = [sys.executable, "-m", "clpc", "track", path, "-u", "u", "-y", "y", "--out"]
    env_plain = dict(os.environ, CLPC_FAST_IO="0")
    run([*cmd, str(work / "warm")])  # the compiled kernel is loaded from numba's cache
    plain, fast = [], []
    for _ in range(repeat):
        plain.append(run([*cmd, str(work / "plain")], env_plain))
        fast.append(run([*cmd, str(work / "fast")]))
    a = read_table(work / "plain" / "trace.csv")
    b = read_table(work / "fast" / "trace.csv")
    same = np.array_equal(a.data, b.data) and a.names == b.names
    print(f"\n## clpc track, end to end (subprocess, best of {repeat})")
    print(f"plain (CLPC_FAST_IO=0): {min(plain):.2f} s")
    print(f"default:                {min(fast):.2f} s   -> {min(plain) / min(fast):.2f}x faster")
    print(f"trace.csv identical numbers: {same} ({a.n_rows} updates)")
    for label, env in (("plain", "0"), ("default", "1")):
        print(f"phases ({label}): {phases(path, work / f'phases-{label}', env)}")
    assert same, "the fast path changed the trace"


def phases(path: str, out: Path, fast_io: str) -> str:
    """One in-process track, timed by phase (a subprocess, so the environment switch holds)."""
    code = f"""
import os, time
os.environ["CLPC_FAST_IO"] = {fast_io!r}
t0 = time.perf_counter()
from clpc.io import iter_table_chunks
from clpc.appraiser import CLPC
from clpc.appraiser.tracefile import ThinnedTrace, TraceWriter
from clpc.report import write_track_report
t1 = time.perf_counter()
chunks = list(iter_table_chunks({path!r}, 100_000, columns=["u", "y"]))
t2 = time.perf_counter()
a = CLPC(order=2, window_size=201, cluster_size=12)
parts = [a.push(v[:, :1], v[:, 1:]) for _, v in chunks]
t3 = time.perf_counter()
kept = ThinnedTrace()
with TraceWriter({str(out / "trace.csv")!r}) as w:
    for p in parts:
        w.write(p)
        kept.add(p)
t4 = time.perf_counter()
write_track_report({str(out)!r}, kept.trace())
t5 = time.perf_counter()
print(f"imports {{t1-t0:.2f}} s, read {{t2-t1:.2f}} s, appraise {{t3-t2:.2f}} s, "
      f"write trace {{t4-t3:.2f}} s, figures+report {{t5-t4:.2f}} s")
"""
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return res.stdout.strip()


def bench_startup(repeat: int) -> None:
    py = sys.executable
    eager = "import clpc\nfor n in clpc.__all__: getattr(clpc, n)"
    rows = [
        ("python -c pass", [py, "-c", "pass"]),
        ("import clpc", [py, "-c", "import clpc"]),
        ("clpc --help", [py, "-m", "clpc", "--help"]),
        ("import clpc + every exported name (the former eager import)", [py, "-c", eager]),
    ]
    print(f"\n## start-up (best of {repeat}, wall)")
    for label, cmd in rows:
        run(cmd)
        print(f"{label}: {min(run(cmd) for _ in range(repeat)):.3f} s")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rows", type=float, default=1e6)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    import clpc

    print(f"# clpc I/O and start-up benchmark ({time.strftime('%Y-%m-%d %H:%M')})")
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} logical cores, Python "
        f"{platform.python_version()}, numpy {np.__version__}; clpc from {clpc.__file__}"
    )
    print(f"load average at start: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    with tempfile.TemporaryDirectory(prefix="clpc-bench-io-") as tmp:
        work = Path(tmp)
        path = str(work / "record.csv")
        write_record(path, int(args.rows))
        bench_read(path, args.repeat)
        bench_track(path, args.repeat, work)
    bench_startup(5 * args.repeat)


if __name__ == "__main__":
    main()
