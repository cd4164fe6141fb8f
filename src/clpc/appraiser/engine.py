"""The appraiser's calls into its kernel, and the kernel's inputs from the settings.

:mod:`clpc.appraiser.kernel` is compiled by numba (``numba.njit(cache=True)``); with the
environment variable ``NUMBA_DISABLE_JIT=1`` numba leaves it uncompiled and the same
functions run as plain Python (slow: for debugging and coverage).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.appraiser import kernel
from clpc.core.rules import RobustRule, SolveSettings, solve_settings, transform_mode
from clpc.lpc.solve import fixed_transform
from clpc.model.structure import Structure

__all__ = ["output", "settings_for", "solve", "update", "window_plan"]


def window_plan(
    structure: Structure,
    channels: tuple[int, int, bool],
    sizes: tuple[int, int, int],
    noise: np.ndarray | None,
) -> tuple[kernel.WindowPlan, int]:
    """Column maps of the lag rows and the transform of the solved problem.

    Parameters
    ----------
    structure : Structure
    channels : (n_inputs, n_outputs, miso)
        ``miso``: every equation uses every input (else the paper's pairing).
    sizes : (window, cluster, min_rows)
    noise : ndarray, shape (p,) or (p, p), optional
        Known noise covariance of the lag vector (weighted LPC).

    Returns
    -------
    plan : WindowPlan
    n_channels : int
        Channel blocks of a lag vector (the output, then one per input block).
    """
    n_in, n_out, miso = channels
    s = structure
    n_blocks = n_in if miso else 1
    p = s.n_params(n_blocks)
    col_channel = np.zeros(p, dtype=np.int64)
    for blk in range(n_blocks):
        col_channel[s.na + 1 + blk * (s.nb + 1) : s.na + 1 + (blk + 1) * (s.nb + 1)] = blk + 1
    # column a of equation e is buf[k - lag, chan] (buffer columns: inputs, then outputs)
    chan = np.empty((n_out, p), dtype=np.int64)
    lag = np.empty((n_out, p), dtype=np.int64)
    for e in range(n_out):
        chan[e, : s.na + 1] = n_in + e
        lag[e, : s.na + 1] = np.arange(s.na + 1)
        for i, inp in enumerate(range(n_in) if miso else [e]):
            cols = slice(s.na + 1 + i * (s.nb + 1), s.na + 1 + (i + 1) * (s.nb + 1))
            chan[e, cols] = inp
            lag[e, cols] = s.nk + np.arange(s.nb + 1)
    transform = np.eye(p) if noise is None else fixed_transform(noise, p)
    window, cluster, min_rows = sizes
    plan = kernel.WindowPlan(
        chan, lag, col_channel, np.ascontiguousarray(transform), window, cluster, min_rows
    )
    return plan, n_blocks + 1


def settings_for(
    method: tuple[str, str],
    rule: RobustRule,
    noise: np.ndarray | None,
    na: int,
    n_channels: int,
) -> SolveSettings:
    """The solve settings of an appraiser: ``method = (method, scaling)``.

    See :func:`clpc.core.rules.solve_settings` and :func:`clpc.core.rules.transform_mode`.
    """
    name, scaling = method
    mode = transform_mode(scaling, noise is not None)
    return solve_settings(rule, name == "robust", mode, na + 1, n_channels)


def update(
    samples: tuple[np.ndarray, int], windows: tuple[int, int], setup: Any, state: Any
) -> tuple[kernel.Solved, kernel.FsmOutput]:
    """Solve ``windows`` and run the FSM output over them in one kernel call.

    Parameters
    ----------
    samples : (ndarray, int)
        The buffered samples, shape (n, channels), and the absolute lag row of the first.
    windows : (int, int)
        ``(j0, count)``: updates ``j0 .. j0 + count - 1``.
    setup : KernelSetup
        The record's :class:`clpc.appraiser.updates.KernelSetup` (its ``plain`` settings go
        to :func:`clpc.appraiser.kernel.update_windows`).
    state : FsmState
        The carried :class:`clpc.appraiser.kernel.FsmState` (updated in place).

    Returns
    -------
    solved : Solved
    output : FsmOutput
    """
    solved = _solved(windows[1], setup.plan)
    out = _fsm_output(solved, setup.fsm, setup.n_inputs)
    kernel.update_windows(
        samples[0], samples[1], windows, setup.plain, tuple(state), (tuple(solved), tuple(out))
    )
    return solved, out


def solve(
    samples: np.ndarray,
    first_row: int,
    windows: tuple[int, int],
    plan: kernel.WindowPlan,
    settings: SolveSettings,
) -> kernel.Solved:
    """Solve ``windows = (j0, count)`` (see :func:`clpc.appraiser.kernel.solve_windows`)."""
    out = _solved(windows[1], plan)
    kernel.solve_windows(samples, first_row, windows, plan, settings, out)
    return out


def output(
    solved: kernel.Solved, fs: kernel.FsmSettings, state: kernel.FsmState, n_inputs: int
) -> kernel.FsmOutput:
    """The FSM output of ``solved`` (``state`` is updated in place)."""
    out = _fsm_output(solved, fs, n_inputs)
    kernel.fsm_output(solved, fs, state, out)
    return out


def _solved(count: int, plan: kernel.WindowPlan) -> kernel.Solved:
    e, p = plan.chan.shape
    f = np.empty((2, count, e, p))  # same-shape fields share one allocation (hot path)
    g = np.empty((4, count, e))
    i = np.empty((2, count, e), np.int64)
    b = np.empty((2, count, e), np.bool_)
    fields = (*f, *g, *i, *b, np.empty(count, np.int64))
    return kernel.Solved(*fields)


def _fsm_output(solved: kernel.Solved, fs: kernel.FsmSettings, n_inputs: int) -> kernel.FsmOutput:
    count, e, p = solved.theta.shape
    b = np.empty((5, count, e), np.bool_)
    g = np.empty((5, count, e))
    fields = (
        np.empty((count, e, p)),
        np.empty((count, e)),
        *b[:4],
        np.empty(count, np.bool_),
        np.empty((count, e, fs.na + 1)),
        np.empty((count, e, n_inputs, fs.nk + fs.nb + 1)),
        b[4],
        *g,
    )
    return kernel.FsmOutput(*fields)
