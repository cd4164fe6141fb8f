""":func:`write_table`: named columns to a data file, in the format of its extension."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from clpc.core.atomic import atomic_path
from clpc.data import DataError
from clpc.io.formats import file_kind
from clpc.io.mat_files import write_mat
from clpc.io.numpy_files import write_npy, write_npz
from clpc.io.parquet import write_parquet
from clpc.io.table import PathLike, named_columns
from clpc.io.text_writer import write_text

__all__ = ["write_table"]


def write_table(
    path: PathLike,
    names: Sequence[str],
    array: Any,
    *,
    delimiter: str | None = None,
) -> None:
    """Write named columns to a file; the format follows the extension.

    Parameters
    ----------
    path : str or os.PathLike
        ``.csv``/``.txt``/``.dat`` (comma), ``.tsv``/``.tab`` (tab), optionally ``.gz``;
        ``.parquet``/``.pq`` (needs pyarrow); ``.npy`` (the array only: names are not
        stored, they read back as ``col0..``); ``.npz`` (one 1-D array per column); ``.mat``
        (one column vector per column, named by a MATLAB name).
    names : sequence of str
        Column names, one per column.
    array : array_like, shape (n_rows, n_columns) or (n_rows,)
        Values (converted to float64).
    delimiter : str, optional
        Text files only: override the delimiter (one character, e.g. ``";"``).

    Notes
    -----
    Text files get a header line and the shortest decimal form of each float
    (``repr``), so :func:`read_table` returns exactly the same float64 values.

    Raises
    ------
    DataError
        Unsupported extension, or names that do not match the columns.
    """
    p = Path(os.fspath(path))
    kind = file_kind(p)
    listed, arr = named_columns(
        names, array, ("write_table needs a 1-D or 2-D array", "write_table needs")
    )
    if kind == "text" and any("\n" in n or "\r" in n for n in listed):
        raise DataError(f"column names of a text file cannot contain line breaks: {listed}.")
    with atomic_path(p) as tmp:  # written whole or not at all (clpc.core.atomic)
        if kind == "text":
            write_text(tmp, listed, arr, delimiter)
        elif kind == "parquet":
            write_parquet(tmp, listed, arr)
        elif kind == "npy":
            write_npy(tmp, arr)
        elif kind == "mat":
            write_mat(tmp, listed, arr)
        else:
            write_npz(tmp, listed, arr)
