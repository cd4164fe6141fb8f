"""Peak memory of ``CLPC().run`` besides the trace it returns, against the record's length.

``run`` returns one row per update (about 312 bytes; 248 MiB at 1e7 samples and C = 12) and
each window's level in ``meta["window_level"]``. What it needs besides them should not grow
with the record: it processes the record in chunks of ``chunk_samples`` and computes the
levels without arrays of the record's or of the windows' length
(:mod:`clpc.appraiser.levels`). Measured with ``tracemalloc`` (numpy's allocations; the
compiled kernel's scratch is not traced and is ``O(W p^2)``) on the record of
``clpc_table.record`` (N = 2, W = 201, C = 12), held in memory before the measurement.

    OPENBLAS_NUM_THREADS=1 python benchmarks/run_memory.py [--sizes 1e6 3e6 1e7]
"""

from __future__ import annotations

import argparse
import sys
import tracemalloc
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from clpc_table import record

from clpc import CLPC

MIB = 2**20


def trace_bytes(trace: object) -> int:
    """Bytes of the trace's rows and of its levels."""
    plain = [getattr(trace, f) for f in ("index", "time", "rows", "not_enough_data")]
    arrays = [*plain, *trace.arrays.values(), trace.meta["window_level"]]  # type: ignore[attr-defined]
    return sum(a.nbytes for a in arrays)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=float, nargs="+", default=[1e6, 3e6, 1e7])
    sizes = [int(n) for n in parser.parse_args().sizes]
    u, y = record(max(sizes))
    u = np.ascontiguousarray(u[:, 0])
    CLPC().run(u[:20_000], y[:20_000])  # the compiled kernel loaded
    print("| samples | updates | trace and levels [MiB] | peak [MiB] | besides them [MiB] |")
    print("|---|---|---|---|---|")
    for n in sizes:
        tracemalloc.start()
        trace = CLPC().run(u[:n], y[:n])
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        kept = trace_bytes(trace)
        print(
            f"| {n:.0e} | {len(trace)} | {kept / MIB:.1f} | {peak / MIB:.1f} | "
            f"{(peak - kept) / MIB:.1f} |"
        )
        del trace


if __name__ == "__main__":
    main()
