"""``CLPC.step`` of two versions timed in one process, in turn (issue 26's A/B method).

Both ``src/clpc`` trees are imported side by side under their own names (``clpc_a``,
``clpc_b``; :func:`clpc_ab.renamed_copy`), and each feeds the same Python floats (N = 2,
W = 201, the record of ``clpc_table.record``) to a fresh appraiser's ``step``, one sample a
call, round after round in turn (A first in even rounds, B first in odd ones); each keeps
its best CPU time per sample. ``--read`` also reads ``theta`` and ``D`` of every update
``step`` returns (what a monitoring loop does; a returned update's arrays are sliced on
first use). The traces of both are checked bit for bit against each other and against
``run`` on the same samples (kept from a first, untimed loop; the timed loops keep nothing,
as a monitoring loop would).

Usage::

    git archive <commit> src | tar -x -C /tmp/old
    OPENBLAS_NUM_THREADS=1 python benchmarks/step_ab.py /tmp/old/src src --clusters 12,1
"""

from __future__ import annotations

import argparse
import importlib
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from clpc_ab import renamed_copy
from clpc_table import WINDOW, record


def stepper(name: str, cluster: int, samples: tuple[list[float], list[float]], read: bool) -> Any:
    """A timed loop of package ``name``'s ``step`` over ``samples`` (a fresh appraiser)."""
    pkg = importlib.import_module(name)
    u, y = samples

    def call(keep: bool = False) -> list[Any]:
        step = pkg.CLPC(order=2, window_size=WINDOW, cluster_size=cluster).step
        parts = []
        for u_k, y_k in zip(u, y, strict=True):
            part = step(u_k, y_k)
            if read and len(part):
                part.theta, part.D  # noqa: B018 - what a caller reads
            if keep:  # the bits are compared once; the timed loops keep nothing
                parts.append(part)
        return parts

    return call


def race(calls: dict[str, Callable[[], Any]], rounds: int, n: int) -> dict[str, float]:
    """Best CPU seconds per sample of each call, the calls timed in turn."""
    best = dict.fromkeys(calls, float("inf"))
    names = list(calls)
    for k in range(rounds):
        for name in names if k % 2 == 0 else names[::-1]:
            t0 = time.process_time()
            calls[name]()
            best[name] = min(best[name], (time.process_time() - t0) / n)
    return best


def same_bits(a: Any, b: Any) -> bool:
    """Two traces equal bit for bit (every row field and array)."""
    fields = ("index", "time", "rows", "not_enough_data")
    return all(np.array_equal(getattr(a, f), getattr(b, f)) for f in fields) and all(
        np.array_equal(a.arrays[k], b.arrays[k]) for k in a.arrays
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a", help="src directory of version A (the baseline)")
    ap.add_argument("b", help="src directory of version B")
    ap.add_argument("--rounds", type=int, default=6)
    ap.add_argument("--clusters", default="12,1", help="cluster sizes C, comma-separated")
    ap.add_argument("--samples", type=int, default=24000)
    ap.add_argument("--read", action="store_true", help="read theta and D of each update")
    args = ap.parse_args(argv)
    tmp = Path(tempfile.mkdtemp(prefix="step_ab_"))
    renamed_copy(Path(args.a), "clpc_a", tmp)
    renamed_copy(Path(args.b), "clpc_b", tmp)
    sys.path.insert(0, str(tmp))
    os.environ.setdefault("NUMBA_CACHE_DIR", str(tmp / "numba"))
    u, y = record(args.samples)
    floats = (u[:, 0].tolist(), y.tolist())
    print("C    A us/sample  B us/sample  A/B    same bits (A, B, run)  load")
    for cluster in (int(c) for c in args.clusters.split(",")):
        calls = {n: stepper(n, cluster, floats, args.read) for n in ("clpc_a", "clpc_b")}
        traces = {n: fn(True) for n, fn in calls.items()}  # compiles; the bits compared below
        pkg = importlib.import_module("clpc_b")
        ref = pkg.CLPC(order=2, window_size=WINDOW, cluster_size=cluster).run(u[:, 0], y)
        joined = {n: pkg.Trace.concat(t) for n, t in traces.items()}
        same = same_bits(joined["clpc_a"], joined["clpc_b"]) and same_bits(joined["clpc_b"], ref)
        best = race(calls, args.rounds, args.samples)
        a, b = best["clpc_a"] * 1e6, best["clpc_b"] * 1e6
        load = os.getloadavg()[0]
        print(f"{cluster:<4d} {a:10.3f}  {b:11.3f}  {a / b:5.2f}x  {same!s:21s}  {load:.2f}")
    shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
