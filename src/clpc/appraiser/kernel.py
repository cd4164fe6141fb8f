"""The CLPC kernel: its calls over a record's updates, and the names of its modules.

The kernel is plain ``numba.njit(cache=True)`` functions; with ``NUMBA_DISABLE_JIT=1``
numba leaves them uncompiled and they run as plain Python (slow; for debugging and
coverage). Its data types are :mod:`clpc.appraiser.kernel_types`, a window's pieces
:mod:`clpc.appraiser.blocks`, the per-window solve (windows, blocks and the exact merge)
:mod:`clpc.appraiser.window_solve`, the FSM output :mod:`clpc.appraiser.window_output`,
a record's plan and settings :mod:`clpc.appraiser.kernel_setup`; this module re-exports
their names. Here: the Python side that allocates the output arrays of a call
(:func:`outputs`, :func:`trace_outputs`) and cuts the updates into batches
(:func:`solve_updates`: solved on threads with ``n_jobs``; the FSM output then runs in
time order).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from clpc.appraiser.blocks import BlockCache, new_cache
from clpc.appraiser.kernel_setup import (
    KernelSetup,
    block_rows,
    cache_blocks,
    record_setup,
    settings_for,
    window_plan,
)
from clpc.appraiser.kernel_types import (
    FsmOutput,
    FsmSettings,
    FsmState,
    Solved,
    WindowPlan,
    Work,
    new_work,
)
from clpc.appraiser.window_output import fsm_output, update_windows
from clpc.appraiser.window_solve import solve_one, solve_windows

__all__ = [
    "WINDOWS_PER_BATCH",
    "BlockCache",
    "FsmOutput",
    "FsmSettings",
    "FsmState",
    "KernelSetup",
    "Plain",
    "Solved",
    "WindowPlan",
    "Work",
    "batches",
    "block_rows",
    "cache_blocks",
    "fsm_output",
    "new_cache",
    "new_work",
    "outputs",
    "record_setup",
    "settings_for",
    "solve_one",
    "solve_updates",
    "solve_windows",
    "trace_outputs",
    "update_windows",
    "window_plan",
]

#: windows solved per kernel call (bounds the temporaries of one call)
WINDOWS_PER_BATCH = 2048


#: a kernel call's outputs as plain tuples, in the fields' order of Solved and FsmOutput
Plain = tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]]


def outputs(count: int, setup: KernelSetup) -> Plain:
    """Uninitialised output arrays of ``count`` updates, as plain tuples (see :data:`Plain`).

    Fields of the same shape and type share one allocation.
    """
    e, p = setup.plan.chan.shape
    fs = setup.fsm
    f = np.empty((3, count, e, p))
    g = np.empty((10, count, e))
    i = np.empty((2, count, e), np.int64)
    b = np.empty((7, count, e), np.bool_)
    solved = (f[0], f[1], g[0], g[1], g[2], g[3], i[0], i[1], b[0], b[1])
    den = np.empty((count, e, fs.na + 1))
    num = np.empty((count, e, setup.n_inputs, fs.nk + fs.nb + 1))
    out = (f[2], g[4], b[2], b[3], b[4], b[5], np.empty(count, np.bool_), den, num, b[6])
    return (*solved, np.empty(count, np.int64)), (*out, g[5], g[6], g[7], g[8], g[9])


def batches(j_first: int, j_last: int, n_jobs: int) -> list[tuple[int, int]]:
    """``(j0, count)`` pairs covering updates ``j_first .. j_last`` (equal thread shares)."""
    n_new = j_last - j_first + 1
    n_batches = -(-n_new // WINDOWS_PER_BATCH)
    if n_jobs > 1:
        n_batches = -(-n_batches // n_jobs) * n_jobs
    size = -(-n_new // n_batches)
    return [(j0, min(size, j_last + 1 - j0)) for j0 in range(j_first, j_last + 1, size)]


def solve_updates(
    setup: KernelSetup,
    samples: tuple[np.ndarray, int],
    updates: tuple[int, int],
    state: tuple[FsmState, BlockCache],
    dest: Plain,
    threads: tuple[int, Callable[..., Any]] = (1, map),
) -> None:
    """Solve updates ``updates = (j_first, j_last)`` and run the FSM output over them.

    Parameters
    ----------
    setup : KernelSetup
    samples : (buffer, first_row)
        Buffered samples (n, channels) and the absolute lag row of ``buffer[0]`` minus
        ``max_lag`` (see :func:`solve_windows`).
    updates : (j_first, j_last)
    state : (FsmState, BlockCache)
        The carried FSM state and the record's block cache, updated in place (the threads
        use no cache: their batches run at once).
    dest : Plain
        Where the outputs go, one row per update (e.g. :func:`outputs`, or
        :func:`trace_outputs` to write straight into a trace); each batch writes its rows.
    threads : (n_jobs, map)
        Thread count and ``map`` or a thread pool's ``map`` (batches are independent).
    """
    buf, first_row = samples
    n_jobs, mapper = threads
    fsm, cache = state
    j_first = updates[0]
    parts = batches(j_first, updates[1], n_jobs)
    views = [_rows(dest, j0 - j_first, j0 - j_first + c) for j0, c in parts]
    if n_jobs == 1 or len(parts) == 1:  # solve and output in one kernel call per batch
        plain_state, plain_cache = tuple(fsm), tuple(cache)
        for batch, (solved, out) in zip(parts, views, strict=True):
            update_windows(
                buf, first_row, batch, setup.plain, plain_state, (solved, out), plain_cache
            )
        return
    off = new_cache(setup.plan.chan.shape, 0)

    def solve_batch(k: int) -> int:
        solved = Solved(*views[k][0])
        solve_windows(buf, first_row, parts[k], setup.plan, setup.settings, solved, off)
        return k

    # windows are independent: threads; the FSM output runs in time order, each batch's as
    # soon as it is solved (while the threads solve the next ones)
    for k in mapper(solve_batch, range(len(parts))):
        fsm_output(Solved(*views[k][0]), setup.fsm, fsm, FsmOutput(*views[k][1]))


def trace_outputs(arrays: dict[str, np.ndarray], rows: np.ndarray, not_enough: np.ndarray) -> Plain:
    """The kernel's outputs as the arrays of a trace (see :data:`Plain`): no copies.

    ``arrays`` holds the per-equation arrays of :data:`clpc.appraiser.trace.PER_EQUATION`,
    ``rows`` and ``not_enough`` the rows and flags (all with the same number of rows);
    the solved ``c`` (not in a trace) gets a scratch array.
    """
    scratch = np.empty(arrays["c"].shape)
    solved = tuple(
        scratch if key is None else rows if key == "n_rows" else arrays[key] for key in _SOLVED_KEYS
    )
    out = tuple(not_enough if key == "not_enough" else arrays[key] for key in _FSM_KEYS)
    return solved, out


def _rows(plain: Plain, lo: int, hi: int) -> Plain:
    """Rows ``lo .. hi - 1`` of every output (views, C-contiguous)."""
    return tuple(a[lo:hi] for a in plain[0]), tuple(a[lo:hi] for a in plain[1])


#: trace keys of the fields of Solved (None: not in the trace) and of FsmOutput
_SOLVED_KEYS = (
    "theta_estimate",
    "eigenvalues",
    None,
    "noise_variance",
    "separation",
    "a0_weight",
    "n_null",
    "n_input_relations",
    "degenerate",
    "excited",
    "n_rows",
)
_FSM_KEYS = tuple(FsmOutput._fields)
