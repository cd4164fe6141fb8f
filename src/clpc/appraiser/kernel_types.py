"""The CLPC kernel's data types: the plan, the solved windows, the FSM's settings and output.

:class:`WindowPlan` (a record's plan), :class:`Solved` (the solved windows),
:class:`FsmSettings`, :class:`FsmState`, :class:`FsmOutput` (the FSM output's settings,
carried state and outputs) and :class:`Work` (:func:`new_work`: the work space of one solve).

Named tuples, so numba types them in compiled code (:mod:`clpc.appraiser.window_solve`,
:mod:`clpc.appraiser.window_output`); the compiled entries of a call take them as plain
tuples in the fields' order (:func:`clpc.appraiser.window_output.update_windows`).
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

__all__ = ["FsmOutput", "FsmSettings", "FsmState", "Solved", "WindowPlan", "Work", "new_work"]


class WindowPlan(NamedTuple):
    """Where the lag rows come from, fixed per record.

    Column ``a`` of equation ``e`` is ``samples[k - lag[e, a], chan[e, a]]`` for the row
    whose newest sample is ``samples[k]``.
    """

    chan: np.ndarray  #: (E, p) int64
    lag: np.ndarray  #: (E, p) int64
    col_channel: np.ndarray  #: (p,) int64, channel block of each column (0 = output)
    transform: np.ndarray  #: (p, p), T of a FIXED_TRANSFORM solve (else unused)
    window: int  #: W, lag rows per window
    cluster: int  #: C, lag rows between updates
    min_rows: int  #: windows with fewer rows are "not enough data": no solve runs
    block: int  #: B, rows of a block summarised once (a multiple of C; see block_rows)


class Solved(NamedTuple):
    """Per-window solutions, shapes (count, E, ...) (``n_rows``: (count,))."""

    theta: np.ndarray
    eigenvalues: np.ndarray
    c: np.ndarray
    noise_variance: np.ndarray
    separation: np.ndarray
    a0_weight: np.ndarray
    n_null: np.ndarray
    n_input_relations: np.ndarray
    degenerate: np.ndarray
    excited: np.ndarray
    n_rows: np.ndarray


class FsmSettings(NamedTuple):
    """The FSM output's settings."""

    min_rows: int
    guard: bool  #: accept only trusted windows
    trust_rows: int  #: rows a trusted window needs
    separation_tol: float
    min_a0_weight: float  #: below it a solution is an input relation, never accepted
    na: int
    nb: int
    nk: int
    paired: bool


class FsmState(NamedTuple):
    """The carried part of the FSM state (updated in place)."""

    last_theta: np.ndarray  #: (E, p)
    last_c: np.ndarray  #: (E,)
    has_model: np.ndarray  #: (E,) bool


class FsmOutput(NamedTuple):
    """What the FSM outputs per update, shapes (count, E, ...) (``not_enough``: (count,))."""

    theta: np.ndarray
    c: np.ndarray
    accepted: np.ndarray
    has_model: np.ndarray
    determined: np.ndarray
    trusted: np.ndarray
    not_enough: np.ndarray
    den: np.ndarray
    num: np.ndarray
    stable: np.ndarray
    lambda_min: np.ndarray
    lambda_max: np.ndarray
    D: np.ndarray
    eig_ratio: np.ndarray
    J: np.ndarray


class Work(NamedTuple):
    """Work space of :func:`solve_one`, allocated once per batch of windows."""

    mat: np.ndarray  #: (p, p)
    tmat: np.ndarray  #: (p, p)
    vecs: np.ndarray  #: (p, p)
    vals: np.ndarray  #: (p,)
    raw: np.ndarray  #: (p,)
    ework: np.ndarray  #: (p,)
    phi: np.ndarray  #: (p,)
    scales: np.ndarray  #: (p,)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def new_work(p: int) -> Work:
    """Work space for problems of size ``p``."""
    return Work(
        np.empty((p, p)),
        np.empty((p, p)),
        np.empty((p, p)),
        np.empty(p),
        np.empty(p),
        np.empty(p),
        np.empty(p),
        np.ones(p),
    )
