"""MATLAB files (``.mat``, versions 4 to 7.2) in and out, through :mod:`scipy.io`.

The variables are the columns: every numeric vector (``n x 1`` or ``1 x n``) is a column
named after its variable, in file order; or the file holds one ``n x k`` matrix, whose
columns are ``col0..`` or named by a cell array or char matrix ``columns`` (or ``names``).
Scalars (a sample time, a gain) and text, cell and struct variables (metadata) are left
out. :func:`scipy.io.whosmat` reads the sizes first, so a file beyond the load limit is
refused before anything is loaded; :func:`scipy.io.loadmat` then loads the selected
variables whole (MATLAB files are not stored row by row). Version 7.3 files are HDF5, which
scipy does not read: save them with ``save(..., '-v7')`` or export a CSV.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from clpc.data import DataError
from clpc.io.errors import check_values, show
from clpc.io.npz_members import check_load
from clpc.io.table import Chunks, Columns, resolve_columns

__all__ = ["mat_source", "write_mat"]

_NUMERIC = {"double", "single", "logical"} | {
    f"{s}int{b}" for s in ("", "u") for b in (8, 16, 32, 64)
}
_NAMES = ("columns", "names")
_MATLAB_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,62}")


def _layout(path: Path, source: str) -> tuple[list[str], list[str], int, bool, str | None]:
    """``(variables, column names, rows, is_matrix, names variable)`` of a ``.mat`` file."""
    import scipy.io

    try:
        info = scipy.io.whosmat(path)
    except NotImplementedError:
        raise DataError(
            f"{source} is a MATLAB v7.3 (HDF5) file, which scipy cannot read; save it with "
            "save(..., '-v7') or export the variables as CSV."
        ) from None
    except Exception as exc:  # scipy raises ValueError, TypeError, MatReadError, ...
        raise DataError(
            f"{source} is not a valid .mat file ({exc}); save the variables with MATLAB's "
            "save or scipy.io.savemat."
        ) from None
    vectors = [(n, max(s)) for n, s, c in info if c in _NUMERIC and len(s) == 2 and min(s) == 1]
    vectors = [(n, rows) for n, rows in vectors if rows > 1]
    matrices = [(n, s) for n, s, c in info if c in _NUMERIC and min(s) > 1]
    names_var = next((n for n, _, c in info if n in _NAMES and c in ("cell", "char")), None)
    for name, shape in matrices:
        if len(shape) > 2 or (matrices and vectors) or len(matrices) > 1:
            raise DataError(
                f"{source} holds {[m for m, _ in matrices] + [v for v, _ in vectors]}; a .mat "
                "table is either one 2-D matrix or numeric vectors of equal length (one per "
                f"column); {name!r} has shape {shape}."
            )
    if matrices:
        name, (rows, n_cols) = matrices[0]
        return [name], [f"col{i}" for i in range(n_cols)], rows, True, names_var
    if not vectors:
        raise DataError(
            f"data file {source} holds no numeric vector or matrix; it needs at least two rows."
        )
    first, rows = vectors[0]
    for name, n in vectors:
        if n != rows:
            raise DataError(
                f"{source} columns differ in length: {name!r} has {n} rows but {first!r} has "
                f"{rows}; save columns of equal length."
            )
    names = [n for n, _ in vectors]
    return names, names, rows, False, None


def _column_names(value: Any) -> list[str]:
    """The strings of a cell array or char matrix as loaded by :func:`scipy.io.loadmat`."""
    arr = np.asarray(value)
    if arr.dtype == object:
        return [str(np.asarray(c).ravel()[0]) if np.size(c) else "" for c in arr.ravel()]
    return [str(s).strip() for s in arr.ravel()]


def mat_source(path: Path, columns: Columns, allow_missing: bool) -> tuple[list[str], Chunks]:
    """Names of the selected columns of a ``.mat`` file and a chunk generator over them.

    Parameters
    ----------
    path : Path
        An existing ``.mat`` file (MATLAB 4 to 7.2).
    columns, allow_missing
        As for :func:`clpc.io.read_table`.

    Returns
    -------
    names : list of str
        The selected column names (variable names, or ``col0..`` of a matrix).
    chunks : Chunks
        ``chunks(chunk_rows)`` yields float64 values (lines None).

    Raises
    ------
    DataError
        A file scipy cannot read (v7.3 included), no numeric data, vectors of different
        lengths, complex values, a non-finite value (unless ``allow_missing``).
    """
    import scipy.io

    source = show(path)
    variables, all_names, n_rows, matrix, names_var = _layout(path, source)
    if matrix and names_var is not None:
        names = _column_names(scipy.io.loadmat(path, variable_names=[names_var])[names_var])
        if len(names) == len(all_names):
            all_names = names
    sel = resolve_columns(all_names, columns, source)
    check_load(n_rows * len(sel), source, "the selected columns")
    wanted = variables if matrix else [variables[i] for i in sorted(set(sel))]
    loaded = scipy.io.loadmat(path, variable_names=wanted)
    if any(np.iscomplexobj(loaded[v]) for v in wanted):
        raise DataError(f"{source} holds complex values; only real numeric arrays can be read.")
    if matrix:
        values = np.asarray(loaded[variables[0]], dtype=np.float64)[:, sel]
    else:
        values = np.column_stack(
            [np.asarray(loaded[all_names[i]], dtype=np.float64).ravel() for i in sel]
        )
    names = [all_names[i] for i in sel]

    def chunks(chunk_rows: int) -> Iterator[tuple[np.ndarray, None]]:
        for start in range(0, n_rows, chunk_rows):
            part = values[start : start + chunk_rows]
            check_values(part, start, names, source, allow_missing)
            yield part, None

    return names, chunks


def write_mat(path: Path, names: list[str], arr: np.ndarray) -> None:
    """Write each column of ``arr`` (shape (n_rows, n_columns)) as a column vector ``names[k]``.

    Raises
    ------
    DataError
        A name MATLAB does not allow (a letter, then letters, digits and ``_``, at most 63
        characters), or repeated names.
    """
    import scipy.io

    bad = [n for n in names if not _MATLAB_NAME.fullmatch(n)]
    if bad or len(set(names)) != len(names):
        raise DataError(
            f"a .mat file needs unique MATLAB variable names (a letter, then letters, digits "
            f"or '_'); got {names}."
        )
    scipy.io.savemat(path, {n: arr[:, [k]] for k, n in enumerate(names)})
