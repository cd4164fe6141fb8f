"""Two versions of the CLPC kernel timed in one process, in turn (issue 26's A/B method).

On the shared 2-core machine the load of other jobs changes within seconds, so two versions
timed in two processes a minute apart differ by +-10 % with no change at all. Here both are
imported into one process - each ``src/clpc`` is copied to a temporary directory under its
own package name (``clpc_a``, ``clpc_b``; the copies' ``clpc`` imports renamed) - and their
``kernel.solve_windows`` + ``kernel.fsm_output`` are called in turn on the same buffer
(``clpc_table.record``), round after round; each keeps its best CPU time per window. Every
configuration is measured twice, A first then B first (the one timed first tends to gain a
few per cent), and the mean of the two is reported, with whether the two give the same
bits.

Usage::

    git archive <commit> src | tar -x -C /tmp/old
    OPENBLAS_NUM_THREADS=1 python benchmarks/clpc_ab.py /tmp/old/src src
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import shutil
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from clpc_table import WINDOW, record


def renamed_copy(src: Path, name: str, dest: Path) -> None:
    """Copy ``src/clpc`` to ``dest/name`` with its ``clpc`` imports renamed to ``name``."""
    target = dest / name
    shutil.copytree(src / "clpc", target, ignore=shutil.ignore_patterns("__pycache__"))
    for path in target.rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        text = re.sub(r"\bfrom clpc([. ])", rf"from {name}\1", text)
        text = re.sub(r"\bimport clpc\b", f"import {name} as clpc", text)
        text = re.sub(r"\"clpc\.", f'"{name}.', text)
        path.write_text(text, encoding="utf-8")


def job(name: str, samples: tuple[np.ndarray, np.ndarray], cfg: tuple[int, int]) -> Any:
    """A timed call of package ``name``'s kernel: (function, windows, solved arrays)."""
    cluster, order = cfg
    pkg = importlib.import_module(name)
    kernel = importlib.import_module(name + ".appraiser.kernel")
    u, y = samples
    appraiser = pkg.CLPC(order=order, window_size=WINDOW, cluster_size=cluster)
    appraiser.run(u[:1000], y[:1000])
    setup = appraiser._state.kernel_setup()
    buf = np.ascontiguousarray(np.column_stack([u, y]))
    count = min(4000, (len(y) - 300) // cluster - 30)
    solved = kernel.Solved(*kernel.outputs(count, setup)[0])
    out = kernel.FsmOutput(*kernel.outputs(count, setup)[1])
    p = setup.plan.chan.shape[1]

    def call() -> None:
        cache = kernel.new_cache(setup.plan.chan.shape, 0)
        kernel.solve_windows(buf, -order, (30, count), setup.plan, setup.settings, solved, cache)
        state = kernel.FsmState(np.zeros((1, p)), np.zeros(1), np.zeros(1, bool))
        kernel.fsm_output(solved, setup.fsm, state, out)

    call()  # compile
    return call, count, solved


def race(calls: dict[str, tuple[Callable[[], None], int]], rounds: int) -> dict[str, float]:
    """Best CPU seconds per window of each call, the calls timed in turn."""
    best = dict.fromkeys(calls, float("inf"))
    for _ in range(rounds):
        for name, (fn, count) in calls.items():
            for _ in range(5):
                t0 = time.process_time()
                fn()
                best[name] = min(best[name], (time.process_time() - t0) / count)
    return best


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a", help="src directory of version A (the baseline)")
    ap.add_argument("b", help="src directory of version B")
    ap.add_argument("--rounds", type=int, default=12)
    ap.add_argument("--configs", default="12:2,1:2,12:1,12:3,12:5", help="C:order,...")
    args = ap.parse_args(argv)
    tmp = Path(tempfile.mkdtemp(prefix="clpc_ab_"))
    renamed_copy(Path(args.a), "clpc_a", tmp)
    renamed_copy(Path(args.b), "clpc_b", tmp)
    sys.path.insert(0, str(tmp))
    os.environ.setdefault("NUMBA_CACHE_DIR", str(tmp / "numba"))
    u, y = record(60000)
    print("config      A us/window  B us/window  A/B   same bits  load")
    for spec in args.configs.split(","):
        cluster, order = (int(x) for x in spec.split(":"))
        jobs = {n: job(n, (u[:, 0], y), (cluster, order)) for n in ("clpc_a", "clpc_b")}
        pairs = zip(jobs["clpc_a"][2], jobs["clpc_b"][2], strict=True)
        same = all(np.array_equal(x, z) for x, z in pairs)
        calls = {n: (j[0], j[1]) for n, j in jobs.items()}
        first = race(calls, args.rounds)
        second = race(dict(reversed(list(calls.items()))), args.rounds)
        a = (first["clpc_a"] + second["clpc_a"]) / 2 * 1e6
        b = (first["clpc_b"] + second["clpc_b"]) / 2 * 1e6
        load = os.getloadavg()[0]
        cells = f"{a:10.3f}  {b:11.3f}  {a / b:5.2f}x  {same!s:9s}  {load:.2f}"
        print(f"C={cluster:<3d} N={order}  {cells}")
    shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
