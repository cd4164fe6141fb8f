"""The machine's own speed-up of two plain processes on a long record's pieces: a control.

``bench_distributed_long.py`` compares ``run_long`` on 2 Dask workers with ``CLPC.run`` in
one process. On a virtual machine the speed-up two processes get at all moves from minute
to minute (the same pieces, no Dask, gave 1.48x, 1.85x and 1.74x within ten minutes on
2026-11-27), so a single ratio mixes Dask's cost with the machine's minute. This control
measures the machine alone, in the same invocation: the record's pieces as ``run_long``
cuts them for 2 workers (:func:`clpc.distributed.schedule.default_piece_samples`),
solved by :func:`clpc.distributed.piece_tasks.solve_piece`

1. one after the other in this process, then
2. by a pool of ``processes`` forked processes (``multiprocessing``: a measuring tool
   here, never part of the package, which runs on Dask), each piece's trace dropped where
   it was solved (``run_long`` keeps it in shared memory).

Both read the ``.npy`` file themselves, as the workers do. Run by
``bench_distributed_long.py`` in a fresh process before each round; alone::

    python benchmarks/machine_control.py RECORD.npy
"""

from __future__ import annotations

import json
import multiprocessing
import sys
import time
from typing import Any

from clpc import CLPC
from clpc.distributed.long_record import plan_record
from clpc.distributed.piece_tasks import solve_piece
from clpc.distributed.schedule import default_piece_samples
from clpc.distributed.sources import NpySource

#: the record, its plan and pieces, set before the pool forks (the children inherit them)
_JOB: dict[str, Any] = {}


def _prepare(path: str, workers: int) -> int:
    """Plan the record of ``path`` (``[u, y]`` columns) in pieces as ``run_long`` would."""
    source = NpySource(path, (0,), (1,))
    n_raw = source.length()
    plan = plan_record(CLPC(), (1, 1), n_raw)
    pieces = plan.layout.pieces(n_raw, default_piece_samples(plan, workers))
    # as run_pieces does: the last piece reads to the end of the record
    pieces[-1] = pieces[-1]._replace(raw=(pieces[-1].raw[0], n_raw))
    _JOB.update(source=source, plan=plan, pieces=pieces)
    return len(pieces)


def _solve(k: int) -> float:
    """Solve piece ``k`` and drop it; its CPU seconds."""
    c0 = time.process_time()
    solve_piece(_JOB["source"], _JOB["plan"], _JOB["pieces"][k])
    return time.process_time() - c0


def control(path: str, processes: int = 2) -> dict[str, float]:
    """Wall seconds of the pieces one after the other and on ``processes`` processes.

    Returns ``{"sequential", "parallel", "ratio", "pieces"}``.
    """
    count = _prepare(path, processes)
    _solve(0)  # the compiled kernel loaded (the forked processes inherit it)
    t0 = time.perf_counter()
    for k in range(count):
        _solve(k)
    sequential = time.perf_counter() - t0
    with multiprocessing.get_context("fork").Pool(processes) as pool:
        pool.map(abs, range(processes))  # the processes started before the timing
        t0 = time.perf_counter()
        list(pool.imap_unordered(_solve, range(count)))  # a piece to whichever is free
        parallel = time.perf_counter() - t0
    return {
        "sequential": sequential,
        "parallel": parallel,
        "ratio": sequential / parallel,
        "pieces": count,
    }


if __name__ == "__main__":
    print(json.dumps(control(sys.argv[1])))
