"""One piece's trace rows as one Parquet file of a long record's dataset.

The columns and types of :class:`clpc.appraiser.tracefile.TraceWriter`'s Parquet trace
(:func:`clpc.appraiser.tracefile.trace_column_list`: ``int64`` counts and flags, ``float64``
numbers), written without dictionary encoding: the trace's numbers are nearly all distinct,
so pyarrow's dictionary pass costs about four fifths of the writing time (measured: 188 ms
against 39 ms for 87,381 rows of 34 columns) and gives a larger file.

A piece is written by the worker that holds its rows (:func:`write_piece`, which settles
them first), or, when the rows lie in the record's trace in shared memory and the client
has settled them there, by any worker of that machine from its own map of the file
(:func:`write_shared_piece`). Both write the same file from the same rows.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import NamedTuple

import numpy as np

from clpc.appraiser.trace import Trace
from clpc.appraiser.tracefile import trace_column_list
from clpc.core.atomic import atomic_path
from clpc.data import DataError
from clpc.distributed.piece_tasks import FsmTuple, RecordPlan, SolvedPiece, settle
from clpc.distributed.pieces import Piece
from clpc.distributed.shared_rows import SharedRows

__all__ = [
    "WrittenPiece",
    "part_path",
    "write_part",
    "write_piece",
    "write_shared_piece",
    "written",
]


def write_part(trace: Trace, path: Path) -> None:
    """Write ``trace`` to the Parquet file ``path`` (whole or not at all; folder created).

    Parameters
    ----------
    trace : Trace
        Consecutive updates of a record.
    path : Path
        The file (replaced if it exists: a retried task writes the same rows again).
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    names, cols = trace_column_list(trace)
    arrays = []
    for col in cols:
        integer = np.issubdtype(col.dtype, np.integer) or np.issubdtype(col.dtype, np.bool_)
        values = np.ascontiguousarray(col, dtype=np.int64 if integer else np.float64)
        kind = pa.int64() if integer else pa.float64()
        arrays.append(pa.Array.from_buffers(kind, values.size, [None, pa.py_buffer(values)]))
    table = pa.Table.from_arrays(arrays, names=names)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp, use_dictionary=False)


class WrittenPiece(NamedTuple):
    """What a worker sends back of a piece whose rows it wrote (small)."""

    summary: Trace  #: every update, the arrays a summary reads only
    figures: Trace  #: every ``stride``-th update of the record (all arrays)
    last: Trace  #: the piece's last updates (all arrays)


def write_piece(
    solved: SolvedPiece,
    plan: RecordPlan,
    state: FsmTuple,
    folder: str,
    keep: tuple[str, ...],
    thin: tuple[int, int],
) -> WrittenPiece:
    """Write the piece's rows to ``folder/part-NNNNNN.parquet``; return what a report needs.

    Parameters
    ----------
    solved, plan, state
        The piece's solved windows, the record plan and the FSM state before the piece.
    folder : str
        The dataset's folder (the file is named by the piece's number).
    keep : tuple of str
        The per-update arrays of :attr:`WrittenPiece.summary`.
    thin : (int, int)
        ``(stride, last)``: the figures take the updates ``j`` with ``(j - 1) % stride ==
        0`` (as :class:`clpc.appraiser.thinned.ThinnedTrace` keeps them); ``last`` updates
        are returned from the piece's end.
    """
    settle(solved, plan, state)
    write_part(solved.trace, part_path(folder, solved.piece))
    return written(solved.trace, solved.piece, keep, thin)


def part_path(folder: str, piece: Piece) -> Path:
    """The dataset's file of ``piece``: ``folder/part-NNNNNN.parquet`` (its number)."""
    return Path(folder) / f"part-{piece.number:06d}.parquet"


def written(
    trace: Trace, piece: Piece, keep: tuple[str, ...], thin: tuple[int, int]
) -> WrittenPiece:
    """What a report needs of a piece's settled rows ``trace`` (see :func:`write_piece`).

    ``summary`` shares the memory of ``trace`` (its arrays ``keep``); ``figures`` and
    ``last`` are copies (they outlive the piece's rows).
    """
    stride, last = thin
    numbers = np.arange(piece.j_lo - 1, piece.j_hi)
    arrays = {k: v for k, v in trace.arrays.items() if k in keep}
    return WrittenPiece(
        dataclasses.replace(trace, arrays=arrays),
        trace.take(np.flatnonzero(numbers % stride == 0)),
        trace.take(np.arange(max(len(trace) - last, 0), len(trace))),
    )


def write_shared_piece(shared: SharedRows, plan: RecordPlan, piece: Piece, folder: str) -> int:
    """Write a piece's rows, settled by the client in the shared trace, as its dataset file.

    Run on a worker of the client's machine (it maps the file for reading). Returns the
    rows written.

    Raises
    ------
    clpc.DataError
        This worker does not see the shared file (a worker of another machine was given
        the task because the worker that solved the piece is gone).
    """
    mapped = shared.read(plan.state().empty_trace())
    if mapped is None:
        raise DataError(
            f"{shared.path}: this worker does not see the record's shared trace, so it cannot "
            f"write piece {piece.number}; run the workers of one machine only, or give the "
            "record to a cluster whose workers all see the client's /dev/shm."
        )
    rows = mapped.trace.view(piece.j_lo - 1, piece.j_hi)
    write_part(rows, part_path(folder, piece))
    return len(rows)
