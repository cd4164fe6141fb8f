"""Data in and start-up: CSV reading, `clpc track` end to end, `import clpc` and `clpc --help`.

Side by side in one run, each the best of ``--repeat`` (the two paths alternating):

* reading a 1e6 x 2 CSV with ``clpc.io.read_table`` and ``iter_table_chunks`` (``pyarrow.csv``
  with the line bookkeeping for messages); ``pandas.read_csv`` and ``pyarrow.csv.read_csv`` as
  outside references. The values must equal ``numpy.loadtxt``'s.
* ``python -m clpc track`` on the same file (subprocesses, all variants alternating):
  ``CLPC_FAST_IO=0`` (plain reader and the plain trace writer) and the default, and with
  ``--baseline-src`` the package before issue 16 (commit 64b4459) as well; every
  ``trace.csv`` must hold the same numbers. The phases of one in-process run are timed too
  (read, appraise, write the trace, figures and report), to show where the time goes.
* start-up: ``python -c "import clpc"``, ``clpc --help``, and the eager import of every
  exported name (what ``import clpc`` cost before the names were loaded lazily).

    python benchmarks/bench_io.py               # 1e6 rows
    python benchmarks/bench_io.py --rows 2e5    # quick
    python benchmarks/bench_io.py --only-read   # the CSV read only
    git worktree add /tmp/clpc-old 64b4459      # the package before issue 16, then:
    python benchmarks/bench_io.py --baseline-src /tmp/clpc-old/src --skip-read --repeat 5
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
    from clpc.io import iter_table_chunks, read_table

    read_table(path)  # pyarrow's import, once
    whole = best_of(lambda: read_table(path), repeat)
    chunked = best_of(lambda: sum(v.shape[0] for _, v in iter_table_chunks(path)), repeat)
    table = read_table(path)
    same = np.array_equal(table.data, np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2))
    print(
        f"## read_table, {table.n_rows} x {table.n_columns} CSV "
        f"({os.path.getsize(path) / 1e6:.1f} MB)"
    )
    print(f"read_table (pyarrow.csv):        {whole:.3f} s")
    print(f"iter_table_chunks (100k rows):   {chunked:.3f} s")
    print(f"values identical to numpy.loadtxt: {same}")
    import pandas as pd
    from pyarrow import csv

    print(f"(pandas.read_csv:                {best_of(lambda: pd.read_csv(path), repeat):.3f} s)")
    print(f"(pyarrow.csv.read_csv:           {best_of(lambda: csv.read_csv(path), repeat):.3f} s)")
    assert same, "the reader changed the values"


def bench_track(path: str, repeat: int, work: Path, baseline_src: str | None) -> None:
    from clpc.io import read_table

    cmd = [sys.executable, "-m", "clpc", "track", path, "-u", "u", "-y", "y", "--out"]
    variants = {
        "plain": dict(os.environ, CLPC_FAST_IO="0"),
        "default": dict(os.environ),
    }
    if baseline_src:  # the package before the work on issue 16 (commit 64b4459)
        old_path = os.pathsep.join(filter(None, [baseline_src, os.environ.get("PYTHONPATH")]))
        variants = {"baseline": dict(os.environ, PYTHONPATH=old_path), **variants}
    for name, env in variants.items():  # compiled kernels loaded from numba's cache after this
        run([*cmd, str(work / f"warm-{name}")], env)
    times: dict[str, list[float]] = {name: [] for name in variants}
    for _ in range(repeat):  # alternating, so that a busy spell of the machine hits all
        for name, env in variants.items():
            times[name].append(run([*cmd, str(work / name)], env))
    best = {name: min(t) for name, t in times.items()}
    traces = {name: read_table(work / name / "trace.csv") for name in variants}
    ref = traces["default"]
    same = {
        name: np.array_equal(t.data, ref.data) and t.names == ref.names
        for name, t in traces.items()
    }
    print(f"\n## clpc track, end to end (subprocess wall time, best of {repeat}, alternating)")
    labels = {
        "baseline": f"baseline package ({baseline_src})",
        "plain": "plain path (CLPC_FAST_IO=0)",
        "default": "default",
    }
    for name, t in best.items():
        ratios = ", ".join(
            f"{name} is {best[other] / t:.2f}x as fast as {other}"
            for other in best
            if other != name
        )
        median = float(np.median(times[name]))
        print(f"{labels[name]:<45} {t:6.2f} s (median {median:.2f} s)   ({ratios})")
    every = "; ".join(f"{n}: " + " ".join(f"{x:.2f}" for x in t) for n, t in times.items())
    print(f"(every run [s]: {every})")
    print(f"trace.csv: same numbers as the default: {same} ({ref.n_rows} updates)")
    for label, env in (("plain", "0"), ("default", "1")):
        print(f"phases ({label}): {phases(path, work / f'phases-{label}', env)}")
    assert all(same.values()), "a path changed the trace"


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
    ap.add_argument(
        "--baseline-src",
        help="src folder of the package at commit 64b4459 (before issue 16), e.g. "
        "/tmp/clpc-old/src after `git worktree add /tmp/clpc-old 64b4459`; its `clpc track` "
        "is timed beside the others (PYTHONPATH of the subprocess)",
    )
    ap.add_argument("--skip-read", action="store_true", help="only `clpc track` and start-up")
    ap.add_argument("--only-read", action="store_true", help="only the CSV read")
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
        if not args.skip_read:
            bench_read(path, args.repeat)
        if args.only_read:
            return
        bench_track(path, args.repeat, work, args.baseline_src)
    bench_startup(5 * args.repeat)


if __name__ == "__main__":
    main()
