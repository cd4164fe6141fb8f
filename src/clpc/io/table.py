"""The :class:`Table` of named columns, and how columns are selected by name or index.

Also the types the readers share: :data:`PathLike`, :data:`ColumnKey`, :data:`Columns` and
:data:`Chunks` (how a reader hands its values over, chunk by chunk).
"""

from __future__ import annotations

import difflib
import os
from collections.abc import Callable, Iterator, Sequence
from typing import Any

import numpy as np

from clpc.data import DataError

__all__ = [
    "Chunks",
    "ColumnKey",
    "Columns",
    "PathLike",
    "Table",
    "located_table",
    "reorder_columns",
    "resolve_column",
    "resolve_columns",
]

PathLike = str | os.PathLike[str]
ColumnKey = str | int
#: a column selection: one key, a sequence of keys, or None for all columns
Columns = Sequence[ColumnKey] | ColumnKey | None
#: ``chunks(chunk_rows)`` yields ``(values, lines)``: float64 values of shape
#: (n_chunk_rows, n_columns) and, for text files, the 1-based file line of each row
#: (int64, shape (n_chunk_rows,)); ``lines`` is None for binary files.
Chunks = Callable[[int], Iterator[tuple[np.ndarray, np.ndarray | None]]]


def named_columns(names: Any, data: Any, who: tuple[str, str]) -> tuple[list[str], np.ndarray]:
    """``data`` as a 2-D float array and ``names`` as one string per column.

    ``who = (shape message, count phrase)`` starts the two messages, e.g. ``("Table data
    must be 1-D or 2-D", "Table needs")``.
    """
    arr = np.asarray(data, dtype=np.float64)
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.ndim != 2:
        raise DataError(f"{who[0]}; got shape {arr.shape}.")
    listed = [names] if isinstance(names, str) else [str(n) for n in names]
    if len(listed) != arr.shape[1]:
        raise DataError(
            f"{who[1]} one name per column: {arr.shape[1]} column(s), "
            f"{len(listed)} name(s) {listed}."
        )
    return listed, arr


class Table:
    """Named numeric columns read from a file.

    Parameters
    ----------
    names : sequence of str
        Column names, one per column of ``data``.
    data : array_like, shape (n_rows, n_columns) or (n_rows,)
        The values; stored as a float64 array of shape (n_rows, n_columns).
    source : str, optional
        Where the values came from (a file name), used in error messages.
    lines : ndarray of int64, shape (n_rows,), optional
        1-based file line of each row (text files): rows are then labelled by line. Stored
        as the first line when the rows are contiguous. None: rows are labelled
        ``row 1, row 2, ...``.

    Attributes
    ----------
    names : list of str
        Column names.
    data : ndarray, shape (n_rows, n_columns)
        float64 values (units as in the file).
    source : str
        The file the table was read from ("" when built in memory).
    """

    __slots__ = ("_first", "_lines", "_unit", "data", "names", "source")

    def __init__(
        self,
        names: Sequence[str],
        data: Any,
        source: str = "",
        lines: np.ndarray | None = None,
    ) -> None:
        listed, arr = named_columns(names, data, ("Table data must be 1-D or 2-D", "Table needs"))
        self.names: list[str] = listed
        self.data: np.ndarray = arr
        self.source: str = str(source)
        self._first = 1  # label number of row 0 when _lines is None
        self._lines: np.ndarray | None = None  # 1-based file line of each row (text files)
        self._unit = "row"
        if lines is not None:
            self._unit = "line"
            if lines.size == 0 or int(lines[-1]) - int(lines[0]) == lines.size - 1:
                self._first = int(lines[0]) if lines.size else 1
            else:
                self._lines = lines

    @property
    def n_rows(self) -> int:
        """Number of rows (samples)."""
        return int(self.data.shape[0])

    @property
    def n_columns(self) -> int:
        """Number of columns."""
        return int(self.data.shape[1])

    @property
    def shape(self) -> tuple[int, int]:
        """``(n_rows, n_columns)``."""
        return self.n_rows, self.n_columns

    def __len__(self) -> int:
        return self.n_rows

    def __repr__(self) -> str:
        src = f", source={self.source!r}" if self.source else ""
        return f"Table(n_rows={self.n_rows}, names={self.names}{src})"

    def index(self, key: ColumnKey) -> int:
        """0-based position of column ``key`` (a name or an integer index).

        Parameters
        ----------
        key : str or int
            Column name, or index (negative counts from the end).

        Returns
        -------
        int

        Raises
        ------
        DataError
            Unknown or ambiguous name, or an index out of range (lists the columns).
        """
        return resolve_column(self.names, key, self.source or "the table")

    def column(self, key: ColumnKey) -> np.ndarray:
        """The values of column ``key`` (name or index), shape (n_rows,).

        Parameters
        ----------
        key : str or int
            Column name, or index (as :meth:`index`).
        """
        return self.data[:, self.index(key)]

    def __getitem__(self, key: ColumnKey) -> np.ndarray:
        return self.column(key)

    def row_label(self, row: int) -> str:
        """Where 0-based row ``row`` is in the source: ``"line 12"`` (text) or ``"row 11"``.

        Parameters
        ----------
        row : int
            0-based row index in the table.
        """
        if self._lines is not None:
            return f"line {int(self._lines[row])}"
        return f"{self._unit} {self._first + int(row)}"


def located_table(
    names: list[str], data: np.ndarray, source: str, lines: np.ndarray | None
) -> Table:
    """A :class:`Table` that knows where its rows are in the file.

    Parameters
    ----------
    names : list of str
        Column names.
    data : ndarray, shape (n_rows, n_columns)
        float64 values.
    source : str
        The file name.
    lines : ndarray of int64, shape (n_rows,), or None
        1-based file line of each row (text files; stored compressed when contiguous), or
        None for binary files (rows are labelled ``row 1, row 2, ...``).

    Returns
    -------
    Table
        The table; its :meth:`Table.row_label` names lines or rows.
    """
    return Table(names, data, source, lines)


def _list_names(names: Sequence[str], limit: int = 25) -> str:
    shown = list(names[:limit])
    more = f" ... and {len(names) - limit} more" if len(names) > limit else ""
    return f"{shown}{more}"


def resolve_column(names: Sequence[str], key: object, source: str) -> int:
    """0-based position of column ``key`` (a name or an integer index) in ``names``.

    Raises
    ------
    DataError
        A key that is neither str nor int, an index out of range, or an unknown or
        ambiguous name (the message lists the columns and suggests a close name).
    """
    n = len(names)
    if isinstance(key, (bool, np.bool_)):
        raise DataError(f"column keys must be names (str) or indices (int); got {key!r}.")
    if isinstance(key, (int, np.integer)):
        k = int(key)
        if -n <= k < n:
            return k % n
        raise DataError(
            f"column index {k} is out of range for {source}, which has {n} column(s) "
            f"{_list_names(names)}; use 0..{n - 1} or a name."
        )
    if not isinstance(key, str):
        raise DataError(
            f"column keys must be names (str) or indices (int); got {type(key).__name__} {key!r}."
        )
    hits = [i for i, name in enumerate(names) if name == key]
    if len(hits) == 1:
        return hits[0]
    if len(hits) > 1:
        raise DataError(
            f"column name {key!r} is ambiguous in {source}: columns {hits} share it; "
            "select the column by its 0-based index instead."
        )
    close = difflib.get_close_matches(key, list(names), n=1)
    if not close:
        close = [name for name in names if name.strip().lower() == key.strip().lower()][:1]
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    raise DataError(
        f"unknown column {key!r} in {source}; available columns: {_list_names(names)}"
        f"{hint}. Use one of these names or a 0-based column index."
    )


def resolve_columns(names: Sequence[str], columns: Columns, source: str) -> list[int]:
    """0-based positions of ``columns`` (None: all) in ``names``, in the order asked for.

    Raises
    ------
    DataError
        An empty selection, or any problem of :func:`resolve_column`.
    """
    if columns is None:
        return list(range(len(names)))
    if isinstance(columns, (str, int, np.integer)):
        columns = [columns]
    keys = list(columns)
    if not keys:
        raise DataError("columns is empty; select at least one column (or pass None for all).")
    return [resolve_column(names, key, source) for key in keys]


def reorder_columns(chunks: Chunks, use: list[int], sel: list[int]) -> Chunks:
    """Chunks of the sorted unique columns ``use`` put in the requested order ``sel``.

    Parameters
    ----------
    chunks : Chunks
        Yields values of shape (n_chunk_rows, len(use)).
    use : list of int
        The sorted unique column positions that ``chunks`` reads.
    sel : list of int
        The column positions asked for (any order, repeats allowed).

    Returns
    -------
    Chunks
        Yields values of shape (n_chunk_rows, len(sel)).
    """
    if use == sel:
        return chunks
    take = [use.index(i) for i in sel]

    def reordered(chunk_rows: int) -> Iterator[tuple[np.ndarray, np.ndarray | None]]:
        for values, where in chunks(chunk_rows):
            yield values[:, take], where

    return reordered
