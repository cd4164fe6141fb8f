"""What a worker does with one piece of a long record (see :mod:`clpc.distributed.pieces`).

Two steps per piece, functions of picklable arguments:

1. :func:`solve_piece`: read the piece's raw samples (from the file, or the slice of a
   ``dask.array`` computed on a worker), check them as :meth:`clpc.CLPC.push` does,
   decimate, and solve every window and run the finite-state machine's output over them
   from "no model yet", in one pass of the kernel (:func:`clpc.appraiser.kernel.solve_updates`,
   as :meth:`clpc.CLPC.run` runs it) straight into the piece's trace rows (its own arrays,
   or the rows of the record's trace in shared memory, :mod:`.shared_rows`). That output
   is already the record's from each equation's first accepted update of the piece on: an
   accepted update replaces the whole carried state (the held theta, c and the has-a-model
   flag), so nothing before it is seen after it. :func:`piece_info` is the few numbers the
   client needs (:class:`PieceInfo`): the channels' extremes, the state the piece ends in,
   which equations accepted an update in it and where first;
2. :func:`settle`, given the state the record's FSM is in when the piece starts
   (:func:`next_state` of the pieces before, computed on the client), runs the FSM again
   over the piece's first updates, up to each equation's first accepted one (usually a
   handful), from that state, in place: on the worker that holds the piece
   (:func:`finish_piece`, the rows then returned, or :func:`.part_file.write_piece`), or on
   the client in its map of the shared trace.

No step waits for another piece's, and only the FSM state (a few numbers per output) goes
from the client to a worker.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from clpc.appraiser import kernel
from clpc.appraiser.decimation import Decimator
from clpc.appraiser.inputs import as_chunk
from clpc.appraiser.levels import window_levels
from clpc.appraiser.settings import Settings
from clpc.appraiser.state import AppraiserState
from clpc.appraiser.trace import Trace
from clpc.distributed.pieces import Layout, Piece
from clpc.distributed.shared_rows import SharedRows

__all__ = [
    "PieceInfo",
    "RecordPlan",
    "SolvedPiece",
    "finish_piece",
    "next_state",
    "piece_info",
    "settle",
    "solve_piece",
    "trace_nbytes",
]

#: the carried FSM state: last accepted theta (E, p), its c (E,), has-a-model flags (E,)
FsmTuple = tuple[np.ndarray, np.ndarray, np.ndarray]


@dataclass(frozen=True)
class RecordPlan:
    """What every task of a record needs to know about it (small, picklable).

    Parameters
    ----------
    settings : Settings
        The appraiser's settings.
    channels : (int, int)
        Inputs and outputs.
    names : ((str, ...), (str, ...)) or None
        Channel names (``None``: ``u``/``y`` defaults).
    record_dt : float or None
        The data's sample time [s] when the appraiser works at it (no decimation).
    layout : Layout
        Window sizes, largest lag and decimation factor.
    n_raw : int
        Raw samples of the record.
    levels : bool
        Compute each window's mean output level (``meta["window_level"]`` of
        :meth:`clpc.CLPC.run`); the summary of ``clpc track`` does not read it.
    """

    settings: Settings
    channels: tuple[int, int]
    names: tuple[tuple[str, ...], tuple[str, ...]] | None
    record_dt: float | None
    layout: Layout
    n_raw: int
    levels: bool = True

    def state(self) -> AppraiserState:
        """A fresh appraiser state of the record (channels known; owns the kernel setup)."""
        st = AppraiserState(self.settings)
        st.set_decimator(Decimator(self.layout.factor))
        st.init_channels(self.channels[0], self.channels[1], self.names)
        st.record_dt = self.record_dt
        return st

    def initial(self) -> FsmTuple:
        """The FSM state at the record's start: no model."""
        p = self.state().n_params()
        n_out = self.channels[1]
        return np.zeros((n_out, p)), np.zeros(n_out), np.zeros(n_out, dtype=bool)


def trace_nbytes(trace: Trace) -> int:
    """Bytes of a trace's arrays (what Dask counts for a task that returns one)."""
    plain = (trace.index, trace.time, trace.rows, trace.not_enough_data)
    return sum(a.nbytes for a in plain) + sum(a.nbytes for a in trace.arrays.values())


class SolvedPiece(NamedTuple):
    """A solved piece: its trace rows, written by the kernel as :meth:`clpc.CLPC.run` writes.

    ``trace`` holds the FSM output from "no model yet" until :func:`settle` makes the first
    updates the record's (in place; settling again gives the same).
    """

    piece: Piece
    trace: Trace  #: the piece's rows (``index``, ``time``, every array; levels in ``meta``)
    solved_c: np.ndarray  #: (count, E): each window's own ``c`` (not a trace column)
    first_accepted: np.ndarray  #: (E,) int64: each equation's first accepted update (-1: none)
    peaks: np.ndarray  #: (2, channels): each raw channel's maximum and minimum in the piece
    shared: bool  #: ``trace`` and ``solved_c`` are views of the record's shared trace


try:  # Dask's memory accounting sizes a returned trace or solved piece by its arrays
    from dask.sizeof import sizeof
except ImportError:  # pragma: no cover - the distributed extra is installed in the tests
    pass
else:
    sizeof.register(Trace)(trace_nbytes)

    @sizeof.register(SolvedPiece)
    def _solved_nbytes(solved: SolvedPiece) -> int:
        return trace_nbytes(solved.trace) + solved.solved_c.nbytes


class PieceInfo(NamedTuple):
    """What the client learns of a solved piece (a few numbers)."""

    peaks: np.ndarray  #: (2, channels): each raw channel's maximum and minimum
    end: FsmTuple  #: the FSM state after the piece, for the equations that accepted in it
    accepted: np.ndarray  #: (E,) bool: the equation accepted an update in the piece
    first: np.ndarray  #: (E,) int64: each equation's first accepted update (-1: none)
    shared: bool  #: the rows are in the record's shared trace (SolvedPiece.shared)


def _kept(raw: np.ndarray, layout: Layout, piece: Piece) -> np.ndarray:
    """The piece's decimated samples ``kept[0] .. kept[1] - 1`` from its raw samples."""
    f = layout.factor
    out = Decimator(f)(raw) if f > 1 else raw  # raw[0] is raw sample raw_lo, a multiple of f
    skip = piece.kept[0] - piece.raw[0] // f
    return np.ascontiguousarray(out[skip : skip + piece.kept[1] - piece.kept[0]])


def _levels(y: np.ndarray, plan: RecordPlan, piece: Piece, trace: Trace) -> np.ndarray:
    """Each window's mean output, as :func:`clpc.appraiser.levels.attach_levels` defines it.

    Summed within the piece (about its own mean), so the values agree with the
    single-process ones to rounding, not bit for bit.
    """
    span = (piece.raw[0], plan.n_raw)
    return window_levels(y, trace.index, trace.rows, plan.layout.factor, span)


def _peaks(columns: list[np.ndarray]) -> np.ndarray:
    """(2, channels): each column's maximum and minimum."""
    return np.array([[c.max() for c in columns], [c.min() for c in columns]])


def solve_piece(
    raw: Any, plan: RecordPlan, piece: Piece, shared: SharedRows | None = None
) -> SolvedPiece:
    """Read (or take), check and decimate a piece's samples; solve its windows; run the FSM.

    The kernel writes straight into the piece's trace arrays, batch by batch with its block
    cache, as :meth:`clpc.CLPC.run` does (:func:`clpc.appraiser.kernel.solve_updates`): the
    same operations, so the same numbers bit for bit, and no copy of the rows.

    Parameters
    ----------
    raw : (ndarray, ndarray) or source
        The raw samples ``piece.raw``: inputs (n, n_inputs) and outputs (n, n_outputs), or a
        source with a ``read(lo, hi)`` method (:mod:`clpc.distributed.sources`), read here.
    plan : RecordPlan
    piece : Piece
    shared : SharedRows, optional
        The record's trace in shared memory (with two extra arrays: each window's own
        ``c`` and level): when this process sees it, the kernel writes the piece's rows
        there (else into the piece's own arrays), and the client settles them itself.

    Raises
    ------
    clpc.DataError
        A sample that is not finite (the message gives its index in the record).
    """
    if isinstance(raw, tuple):
        u, y = as_chunk(raw[0], raw[1], piece.raw[0])
        both = np.hstack([u, y])
    else:  # float64 [inputs | outputs] as read: checked column by column, not copied
        both = raw.read(*piece.raw)
        n_in = plan.channels[0]
        u, y = as_chunk(both[:, :n_in], both[:, n_in:], piece.raw[0])
    samples = _kept(both, plan.layout, piece)
    st = plan.state()
    setup = st.kernel_setup()
    lo, hi = piece.j_lo - 1, piece.j_hi
    mapped = shared.open(st.empty_trace(), (lo, hi)) if shared is not None else None
    if mapped is None:
        trace = Trace.allocate(st.empty_trace(), piece.updates)
        dest = kernel.trace_outputs(trace.arrays, trace.rows, trace.not_enough_data)
    else:  # rows of the shared trace; the windows' own c in its first extra array
        view = mapped.trace.view(lo, hi)
        trace = dataclasses.replace(view, meta=dict(view.meta))
        windows, out = kernel.trace_outputs(trace.arrays, trace.rows, trace.not_enough_data)
        dest = (tuple(kernel.Solved(*windows)._replace(c=mapped.extra[0][lo:hi])), out)
    cache = kernel.new_cache(setup.plan.chan.shape, kernel.cache_blocks(setup.plan))
    first_row = piece.kept[0] - plan.layout.max_lag
    fsm = kernel.FsmState(*plan.initial())
    kernel.solve_updates(setup, (samples, first_row), (piece.j_lo, piece.j_hi), (fsm, cache), dest)
    lay = plan.layout
    trace.index[:] = lay.max_lag + lay.cluster * np.arange(piece.j_lo, piece.j_hi + 1) - 1
    trace.time[:] = trace.index * trace.sample_time
    accepted = trace.arrays["accepted"]
    first = np.where(accepted.any(axis=0), accepted.argmax(axis=0), -1)
    if plan.levels:
        trace.meta["window_level"] = _levels(y, plan, piece, trace)
        if mapped is not None:  # the second extra array
            mapped.extra[1][lo:hi] = trace.meta["window_level"]
    peaks = _peaks([u[:, k] for k in range(u.shape[1])] + [y[:, k] for k in range(y.shape[1])])
    return SolvedPiece(piece, trace, kernel.Solved(*dest[0]).c, first, peaks, mapped is not None)


def piece_info(solved: SolvedPiece) -> PieceInfo:
    """The extremes and the end state of a solved piece (see :func:`next_state`)."""
    arrays = solved.trace.arrays
    end = (arrays["theta"][-1].copy(), arrays["c"][-1].copy(), arrays["has_model"][-1].copy())
    first = solved.first_accepted
    return PieceInfo(solved.peaks, end, first >= 0, first.copy(), solved.shared)


def next_state(state: FsmTuple, info: PieceInfo) -> FsmTuple:
    """The record's FSM state after a piece that started in ``state``.

    An equation that accepted an update in the piece ends in the piece's own end state;
    one that did not holds what it held before the piece.
    """
    ok = info.accepted
    theta = np.where(ok[:, None], info.end[0], state[0])
    return theta, np.where(ok, info.end[1], state[1]), np.where(ok, info.end[2], state[2])


def settle(solved: SolvedPiece, plan: RecordPlan, state: FsmTuple) -> int:
    """Make the piece's FSM output the record's, given the state the record is in before it.

    Runs the FSM from ``state`` over the updates before (and at) the last of the
    equations' first accepted updates (every update when an equation accepted none); the
    later updates' outputs do not depend on ``state``. Writes into ``solved.trace`` (in
    place) and returns the number of rows it wrote (the piece's first ones).
    """
    trace = solved.trace
    ends = np.where(solved.first_accepted >= 0, solved.first_accepted, solved.piece.updates - 1)
    todo = int(ends.max()) + 1
    setup = plan.state().kernel_setup()
    carried = kernel.FsmState(*(np.array(a, copy=True) for a in state))
    windows, out = kernel.trace_outputs(trace.arrays, trace.rows, trace.not_enough_data)
    head = kernel.Solved(*windows)._replace(c=solved.solved_c)
    kernel.fsm_output(
        kernel.Solved(*(a[:todo] for a in head)),
        setup.fsm,
        carried,
        kernel.FsmOutput(*(a[:todo] for a in out)),
    )
    return todo


def finish_piece(solved: SolvedPiece, plan: RecordPlan, state: FsmTuple) -> Trace:
    """The piece's trace rows (what :meth:`clpc.CLPC.run` returns for these updates).

    ``state``: the record's FSM state before the piece (:func:`next_state`).
    """
    settle(solved, plan, state)
    return solved.trace
