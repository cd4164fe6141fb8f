"""Parquet files (``.parquet``, ``.pq``) in and out, through ``pyarrow.parquet``.

Numeric and boolean columns are read as float64; timestamp and duration columns as seconds
since the first row. The file is read batch by batch (``ParquetFile.iter_batches``).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from clpc.data import DataError
from clpc.io.errors import cell_error, check_values, is_number, show
from clpc.io.table import Chunks, Columns, reorder_columns, resolve_columns

__all__ = ["parquet_source", "write_parquet"]

_PER_SECOND = {"s": 1, "ms": 10**3, "us": 10**6, "ns": 10**9}


class _ArrowColumns:
    """Converts the pyarrow columns of one file to float64 arrays (checking them)."""

    def __init__(self, pa: ModuleType, pc: ModuleType, source: str, allow_missing: bool):
        self.pa = pa
        self.pc = pc
        self.source = source
        self.allow_missing = allow_missing
        self.origin: dict[str, int] = {}  # first time stamp of each time column

    def convert(self, col: Any, name: str, offset: int) -> np.ndarray:
        """Column ``name`` of a batch starting at 0-based row ``offset``, as float64."""
        pa, typ = self.pa, col.type
        if col.null_count and not self.allow_missing:
            first = int(self.pc.index(self.pc.is_null(col), True).as_py())
            raise cell_error(f"row {offset + first + 1}", name, "", self.source)
        if pa.types.is_timestamp(typ) or pa.types.is_duration(typ):
            ints = col.cast(pa.int64()).to_numpy(zero_copy_only=False)
            t0 = self.origin.setdefault(name, int(ints[0]))
            return np.asarray((ints - t0) / _PER_SECOND[typ.unit])
        if (
            pa.types.is_integer(typ)
            or pa.types.is_floating(typ)
            or pa.types.is_boolean(typ)
            or pa.types.is_decimal(typ)
        ):
            return np.asarray(col.cast(pa.float64()).to_numpy(zero_copy_only=False))
        if pa.types.is_string(typ) or pa.types.is_large_string(typ):
            try:
                return np.asarray(col.cast(pa.float64()).to_numpy(zero_copy_only=False))
            except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
                for k, text in enumerate(col.to_pylist()):
                    if text is not None and not is_number(text):
                        raise cell_error(f"row {offset + k + 1}", name, text, self.source) from None
                raise
        raise DataError(
            f"{self.source} column {name!r} has type {typ}, which is not numeric; convert it "
            "to numbers (or leave it out of the selection)."
        )


def parquet_source(path: Path, columns: Columns, allow_missing: bool) -> tuple[list[str], Chunks]:
    """Names of the selected columns of a Parquet file and a chunk generator over them.

    Parameters
    ----------
    path : Path
        An existing Parquet file.
    columns, allow_missing
        As for :func:`clpc.io.read_table`.

    Returns
    -------
    names : list of str
        The selected column names, in the order asked for.
    chunks : Chunks
        ``chunks(chunk_rows)`` yields float64 values (lines None).

    Raises
    ------
    DataError
        An unreadable or empty file, a non-numeric column, a missing or bad cell.
    """
    import pyarrow as pa
    import pyarrow.compute as pc
    import pyarrow.parquet as pq

    source = show(path)
    try:
        pf = pq.ParquetFile(path)
    except (pa.ArrowInvalid, OSError) as exc:
        raise DataError(
            f"{source} is not a readable Parquet file ({str(exc).splitlines()[0]}); "
            "check that the file is complete and really Parquet."
        ) from None
    all_names = [str(n) for n in pf.schema_arrow.names]
    sel = resolve_columns(all_names, columns, source)
    use = sorted(set(sel))
    use_names = [all_names[i] for i in use]
    if pf.metadata.num_rows == 0:
        raise DataError(f"data file {source} is empty (0 rows); it needs at least one row.")

    def chunks(chunk_rows: int) -> Iterator[tuple[np.ndarray, None]]:
        offset = 0
        arrow = _ArrowColumns(pa, pc, source, allow_missing)
        for batch in pf.iter_batches(batch_size=chunk_rows, columns=use_names):
            cols = [
                arrow.convert(batch.column(k), use_names[k], offset) for k in range(len(use_names))
            ]
            values = np.column_stack(cols).astype(np.float64, copy=False)
            check_values(values, offset, use_names, source, allow_missing)
            yield values, None
            offset += values.shape[0]

    return [all_names[i] for i in sel], reorder_columns(chunks, use, sel)


def write_parquet(path: Path, names: list[str], arr: np.ndarray) -> None:
    """Write named float64 columns to a Parquet file.

    Parameters
    ----------
    path : Path
        Destination (overwritten).
    names : list of str
        Column names, one per column of ``arr``.
    arr : ndarray, shape (n_rows, n_columns)
        float64 values.

    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_arrays([pa.array(arr[:, k]) for k in range(arr.shape[1])], names)
    pq.write_table(table, path)
