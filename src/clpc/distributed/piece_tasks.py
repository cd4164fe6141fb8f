"""What a worker does with one piece of a long record (see :mod:`clpc.distributed.pieces`).

Three tasks per piece, functions of picklable arguments:

1. :func:`solve_piece` (parallel): read the piece's raw samples (from the file, or the slice
   of a ``dask.array`` computed on a worker), check them as :meth:`clpc.CLPC.push` does,
   decimate, and solve every window of the piece with the kernel's stateless solve
   (:func:`clpc.appraiser.kernel.solve`); also each window's mean output level and the
   channels' extremes (for the whole record's range check);
2. :func:`fsm_piece` (sequential, cheap): the finite-state machine's output
   (:func:`clpc.appraiser.kernel.output`) over the piece's windows in time order, starting
   from the state the previous piece ended in; :func:`end_state` is that state (a few
   numbers), all the next piece needs;
3. :func:`finish_piece` (parallel): the piece's trace rows; or :func:`write_piece`: the rows
   written to one file of a Parquet dataset, and only what a summary and a report need
   returned.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from clpc.appraiser import kernel
from clpc.appraiser.decimation import Decimator
from clpc.appraiser.inputs import as_chunk
from clpc.appraiser.settings import Settings
from clpc.appraiser.state import AppraiserState
from clpc.appraiser.trace import Trace
from clpc.appraiser.tracefile import TraceWriter
from clpc.distributed.pieces import Layout, Piece

__all__ = [
    "RecordPlan",
    "SolvedPiece",
    "WrittenPiece",
    "end_state",
    "finish_piece",
    "fsm_piece",
    "solve_piece",
    "trace_nbytes",
    "write_piece",
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
    """

    settings: Settings
    channels: tuple[int, int]
    names: tuple[tuple[str, ...], tuple[str, ...]] | None
    record_dt: float | None
    layout: Layout
    n_raw: int

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


try:  # Dask's memory accounting sizes a returned trace by its arrays
    from dask.sizeof import sizeof
except ImportError:  # pragma: no cover - the distributed extra is installed in the tests
    pass
else:
    sizeof.register(Trace)(trace_nbytes)


class SolvedPiece(NamedTuple):
    """The solved windows of a piece, batch by batch (:func:`clpc.appraiser.kernel.batches`)."""

    piece: Piece
    batches: list[tuple[int, int]]
    solved: list[kernel.Solved]
    levels: np.ndarray  #: (count, n_out): each window's mean output (record samples)
    peaks: np.ndarray  #: (2, channels): each raw channel's maximum and minimum in the piece


def _kept(raw: np.ndarray, layout: Layout, piece: Piece) -> np.ndarray:
    """The piece's decimated samples ``kept[0] .. kept[1] - 1`` from its raw samples."""
    f = layout.factor
    out = Decimator(f)(raw) if f > 1 else raw  # raw[0] is raw sample raw_lo, a multiple of f
    skip = piece.kept[0] - piece.raw[0] // f
    return np.ascontiguousarray(out[skip : skip + piece.kept[1] - piece.kept[0]])


def _levels(y: np.ndarray, plan: RecordPlan, piece: Piece, rows: np.ndarray) -> np.ndarray:
    """Each window's mean output, as :func:`clpc.appraiser.spread.attach_levels` defines it.

    Summed within the piece (its own reference level), so the values agree with the
    single-process ones to rounding, not bit for bit.
    """
    lay, lo = plan.layout, piece.raw[0]
    index = lay.max_lag + lay.cluster * np.arange(piece.j_lo, piece.j_hi + 1) - 1
    last = np.minimum(index * lay.factor, plan.n_raw - 1)
    first = np.minimum(np.maximum((index - rows + 1) * lay.factor, 0), last)
    ref = y.mean(axis=0)
    csum = np.vstack([np.zeros((1, y.shape[1])), np.cumsum(y - ref, axis=0)])
    count = (last - first + 1)[:, None]
    return (csum[last - lo + 1] - csum[first - lo]) / count + ref


def solve_piece(raw: Any, plan: RecordPlan, piece: Piece) -> SolvedPiece:
    """Read (or take), check and decimate a piece's samples; solve its windows.

    Parameters
    ----------
    raw : (ndarray, ndarray) or source
        The raw samples ``piece.raw``: inputs (n, n_inputs) and outputs (n, n_outputs), or a
        source with a ``read(lo, hi)`` method (:mod:`clpc.distributed.sources`), read here.
    plan : RecordPlan
    piece : Piece

    Raises
    ------
    clpc.DataError
        A sample that is not finite (the message gives its index in the record).
    """
    if isinstance(raw, tuple):
        u, y = as_chunk(raw[0], raw[1], piece.raw[0])
    else:
        both = raw.read(*piece.raw)
        n_in = plan.channels[0]
        u, y = as_chunk(both[:, :n_in], both[:, n_in:], piece.raw[0])
    both = np.hstack([u, y])
    samples = _kept(both, plan.layout, piece)
    setup = plan.state().kernel_setup()
    first_row = piece.kept[0] - plan.layout.max_lag
    batches = kernel.batches(piece.j_lo, piece.j_hi, 1)
    solved = [kernel.solve(samples, first_row, b, setup) for b in batches]
    rows = np.concatenate([s.n_rows for s in solved])
    peaks = np.stack([both.max(axis=0), both.min(axis=0)])
    return SolvedPiece(piece, batches, solved, _levels(y, plan, piece, rows), peaks)


def fsm_piece(solved: SolvedPiece, plan: RecordPlan, state: FsmTuple) -> list[kernel.FsmOutput]:
    """The FSM output over a piece's windows, from ``state`` (the previous piece's end)."""
    setup = plan.state().kernel_setup()
    carried = kernel.FsmState(*(np.array(a, copy=True) for a in state))
    return [kernel.output(s, setup, carried) for s in solved.solved]


def end_state(outputs: list[kernel.FsmOutput]) -> FsmTuple:
    """The FSM state after a piece: the held output of its last update."""
    last = outputs[-1]
    return last.theta[-1].copy(), last.c[-1].copy(), last.has_model[-1].copy()


def _arrays(sol: kernel.Solved, fsm: kernel.FsmOutput) -> dict[str, np.ndarray]:
    """A trace part's per-update arrays: the FSM's output and the windows' own solution."""
    arrays: dict[str, np.ndarray] = dict(fsm._asdict())
    for key, value in sol._asdict().items():
        if key not in ("theta", "c"):
            arrays[key] = value
    arrays["theta_estimate"] = sol.theta
    return arrays


def piece_trace(solved: SolvedPiece, outputs: list[kernel.FsmOutput], plan: RecordPlan) -> Trace:
    """The trace rows of a piece (``meta["window_level"]``: its windows' levels)."""
    st = plan.state()
    labels = st.trace_labels()
    lay = plan.layout
    parts = []
    for (j0, count), sol, out in zip(solved.batches, solved.solved, outputs, strict=True):
        arrays = _arrays(sol, out)
        index = lay.max_lag + lay.cluster * np.arange(j0, j0 + count) - 1
        parts.append(labels.trace(index, arrays.pop("n_rows"), arrays))
    trace = parts[0] if len(parts) == 1 else Trace.concat(parts)
    trace.meta["window_level"] = solved.levels
    return trace


def finish_piece(solved: SolvedPiece, outputs: list[kernel.FsmOutput], plan: RecordPlan) -> Trace:
    """The piece's trace rows (what :meth:`clpc.CLPC.run` returns for these updates)."""
    return piece_trace(solved, outputs, plan)


class WrittenPiece(NamedTuple):
    """What a worker sends back of a piece whose rows it wrote (small)."""

    summary: Trace  #: every update, the arrays a summary reads only
    figures: Trace  #: every ``stride``-th update of the record (all arrays)
    last: Trace  #: the piece's last updates (all arrays)


def write_piece(
    solved: SolvedPiece,
    outputs: list[kernel.FsmOutput],
    plan: RecordPlan,
    folder: str,
    keep: tuple[str, ...],
    thin: tuple[int, int],
) -> WrittenPiece:
    """Write the piece's rows to ``folder/part-NNNNNN.parquet``; return what a report needs.

    Parameters
    ----------
    solved, outputs, plan
        The piece's solved windows, FSM output and record plan.
    folder : str
        The dataset's folder (the file is named by the piece's number).
    keep : tuple of str
        The per-update arrays of :attr:`WrittenPiece.summary`.
    thin : (int, int)
        ``(stride, last)``: the figures take the updates ``j`` with ``(j - 1) % stride ==
        0`` (as :class:`clpc.appraiser.thinned.ThinnedTrace` keeps them); ``last`` updates
        are returned from the piece's end.
    """
    trace = piece_trace(solved, outputs, plan)
    path = Path(folder) / f"part-{solved.piece.number:06d}.parquet"
    path.parent.mkdir(parents=True, exist_ok=True)
    with TraceWriter(path) as writer:
        writer.write(trace)
    stride, last = thin
    numbers = np.arange(solved.piece.j_lo - 1, solved.piece.j_hi)
    arrays = {k: v for k, v in trace.arrays.items() if k in keep}
    return WrittenPiece(
        dataclasses.replace(trace, arrays=arrays),
        trace.take(np.flatnonzero(numbers % stride == 0)),
        trace.take(np.arange(max(len(trace) - last, 0), len(trace))),
    )
