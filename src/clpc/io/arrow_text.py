"""The fast path for text data files: pyarrow's CSV reader, when pyarrow is installed.

pyarrow parses a delimited file in C++ (several times faster than ``numpy.loadtxt``); the
values are the same correctly rounded float64 numbers. The fast path only answers for files
it can vouch for: a one-character delimiter, two columns or more, no compression, no blank
line (read as a row here, so that the line numbers stay exact), every selected cell a finite
number in the one number syntax of :func:`clpc.io.errors.parse_number` (``allow_missing``:
empty cells too).
Anything else - a comment line, a ragged row, a text cell, an empty cell, NaN - stops it,
and :class:`~clpc.io.text_reader.TextReader` re-reads the file with the plain reader, which
either handles the line (comments) or raises its one-line message naming the line, the
column and the text. Without pyarrow the plain reader is used throughout.
"""

from __future__ import annotations

import importlib.util
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from clpc.io.text_format import TextFormat

__all__ = ["FallBack", "arrow_available", "arrow_batches", "fast_path_applies"]

#: bytes per block of pyarrow's streaming reader
BLOCK_BYTES = 1 << 22
#: files up to this size are parsed whole (multi-threaded); larger ones block by block
WHOLE_BYTES = 64 << 20


class FallBack(Exception):
    """The fast path cannot vouch for a block; the plain reader takes over from there."""


def arrow_available() -> bool:
    """Whether pyarrow can be imported and the fast path is not switched off.

    ``CLPC_FAST_IO=0`` in the environment switches it off (the plain reader and writer
    everywhere: what the benchmarks compare against).
    """
    if os.environ.get("CLPC_FAST_IO", "1") == "0":
        return False
    return importlib.util.find_spec("pyarrow") is not None


def fast_path_applies(path: Path, fmt: TextFormat) -> bool:
    """Whether the fast path may read ``path`` (pyarrow present, a plain delimited file)."""
    return fmt.delimiter is not None and not path.name.lower().endswith(".gz") and arrow_available()


def _whole(
    csv: Any, path: Path, fmt: TextFormat, options: tuple[Any, ...], allow_missing: bool
) -> tuple[np.ndarray, np.ndarray]:
    """The whole file parsed at once (several threads)."""
    table = csv.read_csv(
        str(path), read_options=options[0], parse_options=options[1], convert_options=options[2]
    ).combine_chunks()
    n = table.num_rows
    values = np.empty((n, table.num_columns))
    for i in range(table.num_columns):
        values[:, i] = _column(table, i, allow_missing)
    return values, np.arange(fmt.data_line, fmt.data_line + n, dtype=np.int64)


def _column(batch: Any, i: int, allow_missing: bool) -> np.ndarray:
    """Column ``i`` of a record batch as float64 (an empty cell: NaN with ``allow_missing``).

    :class:`FallBack` on an empty cell without ``allow_missing`` and on any NaN or inf
    written as text: pyarrow also takes spellings such as ``nan(1)`` that the number
    syntax of every clpc reader (:func:`clpc.io.errors.parse_number`) refuses, so the plain
    reader judges those cells.
    """
    col = batch.column(i)
    if hasattr(col, "chunks"):  # a table's column: one chunk after combine_chunks()
        col = col.chunk(0) if col.num_chunks == 1 else col.combine_chunks()
    nulls = col.null_count
    if nulls and not allow_missing:
        raise FallBack
    values, missing = _float64(col)
    if not np.isfinite(values if missing is None else values[~missing]).all():
        raise FallBack
    if missing is not None:
        values = np.where(missing, np.nan, values)
    return values


def _float64(arr: Any) -> tuple[np.ndarray, np.ndarray | None]:
    """A float64 pyarrow Array as numpy (a read-only view) and its null mask (``None``: no nulls).

    Read from the Array's buffers: pyarrow's ``to_numpy`` imports pandas (about 0.2 s) when
    it is installed. The values under a null are undefined (the caller replaces them).
    """
    n, off = len(arr), arr.offset
    validity, data = arr.buffers()[:2]
    if n == 0 or data is None:
        return np.zeros(n), None
    values = np.frombuffer(data, dtype=np.float64, count=n, offset=8 * off)
    if not arr.null_count or validity is None:
        return values, None
    bits = np.unpackbits(np.frombuffer(validity, dtype=np.uint8), bitorder="little")
    return values, ~bits[off : off + n].astype(bool)


def arrow_batches(
    path: Path, fmt: TextFormat, use: list[int], allow_missing: bool
) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Values ``(n, len(use))`` and 1-based line numbers of each block of the file.

    Raises
    ------
    FallBack
        A block the fast path cannot vouch for; the rows yielded before it are right.
    """
    import pyarrow as pa
    from pyarrow import csv

    names = [f"c{i}" for i in range(fmt.n_cols)]
    wanted = [names[i] for i in use]
    reader_options = csv.ReadOptions(
        skip_rows=fmt.data_line - 1, column_names=names, block_size=BLOCK_BYTES
    )
    # a blank line is a row here (one empty field: an error), so that pyarrow's rows are
    # the file's lines one for one and the line numbers stay exact
    parse = csv.ParseOptions(delimiter=fmt.delimiter, quote_char='"', ignore_empty_lines=False)
    convert = csv.ConvertOptions(
        include_columns=wanted,
        column_types=dict.fromkeys(wanted, pa.float64()),
        null_values=[""],  # only an empty cell is missing, as for the plain reader
        strings_can_be_null=False,
    )
    line = fmt.data_line
    try:
        if path.stat().st_size <= WHOLE_BYTES:
            yield _whole(csv, path, fmt, (reader_options, parse, convert), allow_missing)
            return
        reader = csv.open_csv(
            str(path), read_options=reader_options, parse_options=parse, convert_options=convert
        )
        for batch in reader:
            n = batch.num_rows
            if n == 0:
                continue
            values = np.column_stack([_column(batch, i, allow_missing) for i in range(len(use))])
            yield values, np.arange(line, line + n, dtype=np.int64)
            line += n
    except (pa.ArrowInvalid, pa.ArrowNotImplementedError, pa.ArrowTypeError):
        raise FallBack from None
