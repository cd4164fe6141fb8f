"""`clpc track` over a long CSV file: throughput and peak memory (issue: command line).

Writes a synthetic record (a rich input through a 2nd-order system plus noise) of ``--rows``
rows to a temporary CSV file, then runs ``python -m clpc track`` on it in a subprocess and
reports wall time, rows/s and the subprocess's peak resident memory (``ru_maxrss``). The file is
read in chunks and fed to the appraiser chunk by chunk, so the peak should not grow with the
number of rows: the run at ``--rows`` is compared with one at a tenth of it.

    python benchmarks/bench_track.py            # 1e7 rows (about a minute)
    python benchmarks/bench_track.py --rows 1e6 # quick
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy import signal


def write_record(path: str, n: int, seed: int = 0) -> None:
    rng = np.random.default_rng(seed)
    with open(path, "w") as fh:
        fh.write("u,y\n")
        zi = np.zeros(2)
        for lo in range(0, n, 1_000_000):
            m = min(1_000_000, n - lo)
            u = rng.standard_normal(m)
            y, zi = signal.lfilter([0.2, 0.5, 0.1], [1.0, -1.5, 0.7], u, zi=zi)
            y = y + 0.01 * rng.standard_normal(m)
            np.savetxt(fh, np.column_stack([u, y]), fmt="%.6g", delimiter=",")


def run_track(path: str, out: str) -> tuple[float, float]:
    """Wall seconds and peak RSS [MiB] of one `clpc track` subprocess."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    t0 = time.perf_counter()
    cmd = [
        sys.executable,
        "-m",
        "clpc",
        "track",
        path,
        "-u",
        "u",
        "-y",
        "y",
        "--order",
        "2",
        "--window-size",
        "201",
        "--cluster-size",
        "12",
        "--out",
        out,
        "--no-progress",
    ]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return wall, max(peak, before) / 1024.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=float, default=1e7)
    args = parser.parse_args()
    n = int(args.rows)
    print(f"clpc track benchmark, {os.cpu_count()} cores; N=2, W=201, C=12")
    print(f"{'rows':>10} {'file MB':>8} {'wall s':>8} {'rows/s':>10} {'peak RSS MiB':>13}")
    with tempfile.TemporaryDirectory() as tmp:
        for rows in (n // 10, n):
            path = os.path.join(tmp, f"rec{rows}.csv")
            write_record(path, rows)
            size = os.path.getsize(path) / 1e6
            # each size in its own child: ru_maxrss of children is the max over all of them,
            # so run the smaller first
            wall, peak = run_track(path, os.path.join(tmp, f"out{rows}"))
            print(f"{rows:>10d} {size:>8.0f} {wall:>8.1f} {rows / wall:>10.3g} {peak:>13.0f}")
            os.remove(path)
    print("target: peak memory bounded (the larger run within ~100 MB of the smaller)")


if __name__ == "__main__":
    main()
