"""One piece's trace rows as one Parquet file of a long record's dataset.

The columns and types of :class:`clpc.appraiser.tracefile.TraceWriter`'s Parquet trace
(:func:`clpc.appraiser.tracefile.trace_column_list`: ``int64`` counts and flags, ``float64``
numbers), written without dictionary encoding: the trace's numbers are nearly all distinct,
so pyarrow's dictionary pass costs about four fifths of the writing time (measured: 188 ms
against 39 ms for 87,381 rows of 34 columns) and gives a larger file.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from clpc.appraiser.trace import Trace
from clpc.appraiser.tracefile import trace_column_list
from clpc.core.atomic import atomic_path

__all__ = ["write_part"]


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
