"""Reading a data file: :func:`read_table` (whole) and :func:`iter_table_chunks` (piece by piece).

>>> from clpc.io import read_table                                    # doctest: +SKIP
>>> table = read_table("run1.csv", columns=["t", "u", "y"])           # doctest: +SKIP

The reader is chosen by the file's extension (:mod:`clpc.io.formats`): text
(:mod:`clpc.io.text_reader`), Parquet (:mod:`clpc.io.parquet`), ``.npy``/``.npz``
(:mod:`clpc.io.numpy_files`), MATLAB ``.mat`` (:mod:`clpc.io.mat_files`). Every reader
returns float64 numbers and checks them once; a bad file gives a one-line
:class:`clpc.data.DataError` (:mod:`clpc.io.errors`).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from clpc.core.checks import check_int
from clpc.data import DataError
from clpc.io.errors import show
from clpc.io.formats import check_file, file_kind
from clpc.io.mat_files import mat_source
from clpc.io.npz_members import check_load
from clpc.io.numpy_files import npy_source, npz_source
from clpc.io.parquet import parquet_source
from clpc.io.table import Chunks, Columns, PathLike, Table, located_table
from clpc.io.text_reader import text_source

__all__ = ["iter_table_chunks", "read_table", "table_columns"]

_READ_CHUNK = 200_000


class _Source(NamedTuple):
    """An opened data file: its path, the selected column names and their chunks."""

    path: Path
    names: list[str]
    chunks: Chunks


def _open_source(
    path: PathLike,
    columns: Columns,
    delimiter: str | None,
    header: bool | None,
    allow_missing: bool,
    skip_rows: int = 0,
    whole: bool = False,
) -> _Source:
    """Check the file, resolve the columns and pick the reader of the file's format.

    ``whole``: every value will be held at once (:func:`read_table`); numpy files larger
    than the load limit are refused before anything is loaded.
    """
    p = check_file(path)
    kind = file_kind(p)
    skip = _check_skip_rows(skip_rows)
    if skip and kind != "text":
        raise DataError(f"skip_rows applies to text files only; {show(p)} is a {kind} file.")
    if kind == "text":
        names, chunks = text_source(p, columns, delimiter, header, allow_missing, skip, whole)
    elif kind == "parquet":
        names, chunks = parquet_source(p, columns, allow_missing)
    elif kind == "npy":
        names, chunks = npy_source(p, columns, allow_missing, whole)
    elif kind == "mat":
        names, chunks = mat_source(p, columns, allow_missing)
    else:
        names, chunks = npz_source(p, columns, allow_missing, whole)
    return _Source(p, names, chunks)


def _check_skip_rows(skip_rows: Any) -> int:
    try:
        return check_int(skip_rows, "skip_rows", low=0)
    except ValueError as exc:
        raise DataError(str(exc)) from None


def _no_rows(path: Path) -> DataError:
    return DataError(
        f"data file {show(path)} has a header but no data rows; it needs at least one row."
    )


def _join(parts: list[np.ndarray]) -> np.ndarray:
    return parts[0] if len(parts) == 1 else np.concatenate(parts)


def read_table(
    path: PathLike,
    *,
    columns: Columns = None,
    delimiter: str | None = None,
    header: bool | None = None,
    allow_missing: bool = False,
    skip_rows: int = 0,
) -> Table:
    """Read a whole data file into a :class:`Table`.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.csv``/``.tsv``/``.tab``/``.txt``/``.dat`` text file (optionally ``.gz``), a
        ``.parquet``/``.pq``, ``.npy``, ``.npz`` or MATLAB ``.mat`` file (numeric vectors
        as columns, or one matrix; :mod:`clpc.io.mat_files`).
    columns : sequence of (str or int), str or int, optional
        Columns to read, by name or 0-based index, in the order wanted (default: all).
        Unselected columns may hold anything (e.g. text); they are not converted.
    delimiter : str, optional
        Text files only: ``","``, ``";"``, ``"tab"`` (a tab character), ``"|"``, any
        one character, or ``"whitespace"`` (``" "``). Default: detected.
    header : bool, optional
        Text files only: whether the first non-comment line holds column names.
        Default: detected (a header has at least one non-numeric field).
    allow_missing : bool
        Keep empty cells, nulls and NaN/inf as NaN instead of raising (default False:
        identification needs finite samples).
    skip_rows : int
        Text files only: physical lines to pass over at the top (e.g. a metadata line).
        A units row right under the header (``s,m,m,V``) is skipped without asking.

    Returns
    -------
    Table
        ``names`` (list of str, the selected columns) and ``data`` (float64, shape
        (n_rows, n_selected_columns)).

    Raises
    ------
    DataFileNotFoundError
        The file does not exist (a :class:`DataError` and a ``FileNotFoundError``).
    DataError
        Unsupported extension, empty file, unknown column, ragged row, non-numeric or
        missing cell (the message names the line/row, the column and the text).
    """
    src = _open_source(path, columns, delimiter, header, allow_missing, skip_rows, whole=True)
    parts: list[np.ndarray] = []
    lines: list[np.ndarray] = []
    held = 0
    for values, where in src.chunks(_READ_CHUNK):
        held += values.size
        check_load(held, show(src.path), "the selected columns")
        parts.append(values)
        if where is not None:
            lines.append(where)
    if not parts:
        raise _no_rows(src.path)
    data = np.ascontiguousarray(_join(parts))
    return located_table(src.names, data, str(os.fspath(src.path)), _join(lines) if lines else None)


def _check_chunk_rows(chunk_rows: Any) -> int:
    try:
        return check_int(chunk_rows, "chunk_rows", low=1)
    except ValueError as exc:
        raise DataError(str(exc)) from None


def iter_table_chunks(
    path: PathLike,
    chunk_rows: int = 100_000,
    *,
    columns: Columns = None,
    delimiter: str | None = None,
    header: bool | None = None,
    allow_missing: bool = False,
    skip_rows: int = 0,
) -> Iterator[tuple[list[str], np.ndarray]]:
    """Read a data file piece by piece, without holding it all in memory.

    The file is opened and its columns are resolved at the call (so a missing file or an
    unknown column raises at once); the values are parsed as the iterator advances.

    Parameters
    ----------
    path : str or os.PathLike
        As for :func:`read_table`.
    chunk_rows : int
        Rows per chunk (>= 1): every chunk has exactly ``chunk_rows`` rows (the last one
        fewer), whatever the format and however many blank or comment lines. Text, Parquet,
        ``.npy`` and ``.npz`` files are read piece by piece (``.npy`` memory-mapped, ``.npz``
        members decompressed a chunk at a time); a 2-D ``.npz`` array in Fortran order and
        the selected variables of a ``.mat`` file are loaded whole (within the load limit).
    columns, delimiter, header, allow_missing, skip_rows
        As for :func:`read_table`.

    Yields
    ------
    names : list of str
        The selected column names (the same list every time).
    values : ndarray, shape (n_chunk_rows, n_selected_columns)
        float64 values; concatenating all chunks gives ``read_table(...).data``.

    Raises
    ------
    DataError
        As :func:`read_table`; errors in later rows surface when that chunk is reached.
    """
    chunk_rows = _check_chunk_rows(chunk_rows)
    src = _open_source(path, columns, delimiter, header, allow_missing, skip_rows)

    def generate() -> Iterator[tuple[list[str], np.ndarray]]:
        empty = True
        for values, _where in src.chunks(chunk_rows):
            empty = False
            yield src.names, values
        if empty:
            raise _no_rows(src.path)

    return generate()


def table_columns(path: PathLike, skip_rows: int = 0) -> list[str]:
    """The names of every column of a regular data file, reading no data (``[]`` if unknown).

    Parameters
    ----------
    path : str or path-like
        A data file of any format :func:`read_table` reads; a pipe or FIFO gives ``[]``
        (it cannot be read twice).
    skip_rows : int
        Lines passed over at the top of a text file.

    Returns
    -------
    list of str
        Column names (text files without a header: ``col0, col1, ...``); ``[]`` when the
        file cannot be opened or read (the reader proper reports that).
    """
    try:
        if not Path(path).is_file():
            return []
        return list(_open_source(path, None, None, None, True, skip_rows).names)
    except (DataError, OSError, ValueError):
        return []
