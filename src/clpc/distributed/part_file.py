"""One piece's trace rows as one Parquet file of a long record's dataset.

The columns and types of :class:`clpc.appraiser.tracefile.TraceWriter`'s Parquet trace
(:func:`clpc.appraiser.tracefile.trace_column_list`: ``int64`` counts and flags, ``float64``
numbers), written without dictionary encoding: the trace's numbers are nearly all distinct,
so pyarrow's dictionary pass costs about four fifths of the writing time (measured: 188 ms
against 39 ms for 87,381 rows of 34 columns) and gives a larger file.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import NamedTuple

import numpy as np

from clpc.appraiser.trace import Trace
from clpc.appraiser.tracefile import trace_column_list
from clpc.core.atomic import atomic_path
from clpc.distributed.piece_tasks import FsmTuple, RecordPlan, SolvedPiece, settle

__all__ = ["WrittenPiece", "write_part", "write_piece"]


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
    trace = solved.trace
    write_part(trace, Path(folder) / f"part-{solved.piece.number:06d}.parquet")
    stride, last = thin
    numbers = np.arange(solved.piece.j_lo - 1, solved.piece.j_hi)
    arrays = {k: v for k, v in trace.arrays.items() if k in keep}
    return WrittenPiece(
        dataclasses.replace(trace, arrays=arrays),
        trace.take(np.flatnonzero(numbers % stride == 0)),
        trace.take(np.arange(max(len(trace) - last, 0), len(trace))),
    )
