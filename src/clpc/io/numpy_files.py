"""numpy files (``.npy``, ``.npz``) in and out.

``.npy``
    A 1-D array (one column), a 2-D array (columns ``col0..``) or a structured array (one
    column per field); read memory-mapped, so chunks of a large file stay on disk.
``.npz``
    One 1-D array per column (named by its key, in file order; 0-d entries are ignored),
    or a single 2-D array (columns ``col0..``, or named by a string array ``columns``).
"""

from __future__ import annotations

import zipfile
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from clpc.data import DataError
from clpc.io.errors import check_values, show
from clpc.io.npz_members import Member, check_load, load_member, member_rows, npz_members
from clpc.io.table import Chunks, Columns, resolve_columns

__all__ = ["npy_source", "npz_source", "write_npy", "write_npz"]

#: ``block(start, stop, columns)``: rows ``start:stop`` of the 0-based ``columns``, float64
_Block = Callable[[int, int, list[int]], np.ndarray]


def _numeric_dtype(dtype: np.dtype) -> bool:
    return bool(
        (np.issubdtype(dtype, np.number) and not np.issubdtype(dtype, np.complexfloating))
        or np.issubdtype(dtype, np.bool_)
    )


def _check_magic(path: Path, magics: tuple[bytes, ...], ext: str, writer: str) -> None:
    with open(path, "rb") as f:
        head = f.read(8)
    if not head.startswith(magics):
        raise DataError(
            f"{show(path)} is not a valid {ext} file (it does not start like one); write it "
            f"with {writer}, or rename it to match its real format."
        )


def _array_source(
    source: str,
    all_names: list[str],
    n_rows: int,
    block: _Block,
    columns: Columns,
    allow_missing: bool,
) -> tuple[list[str], Chunks]:
    sel = resolve_columns(all_names, columns, source)
    if n_rows == 0:
        raise DataError(f"data file {source} is empty (0 rows); it needs at least one row.")

    def chunks(chunk_rows: int) -> Iterator[tuple[np.ndarray, None]]:
        names = [all_names[i] for i in sel]
        for start in range(0, n_rows, chunk_rows):
            values = block(start, min(start + chunk_rows, n_rows), sel)
            check_values(values, start, names, source, allow_missing)
            yield values, None

    return [all_names[i] for i in sel], chunks


def _structured_block(arr: np.ndarray, source: str) -> tuple[list[str], _Block]:
    """Column names and reader of a 1-D structured array (one column per field)."""
    fields: Mapping[str, tuple[Any, ...]] = arr.dtype.fields or {}
    all_names = [str(n) for n in arr.dtype.names or ()]
    for name in all_names:
        sub = fields[name][0]
        if sub.shape or not _numeric_dtype(sub):
            raise DataError(
                f"{source} field {name!r} has dtype {sub}; only numeric scalar fields can be read."
            )
    if arr.ndim != 1:
        raise DataError(f"{source} holds a {arr.ndim}-D structured array; expected 1-D.")

    def block(start: int, stop: int, idx: list[int]) -> np.ndarray:
        part = arr[start:stop]
        return np.column_stack([part[all_names[i]] for i in idx]).astype(np.float64)

    return all_names, block


def _plain_block(arr: np.ndarray, source: str) -> tuple[list[str], _Block]:
    """Column names and reader of a plain 1-D or 2-D numeric array."""
    if not _numeric_dtype(arr.dtype):
        raise DataError(f"{source} holds dtype {arr.dtype}; only real numeric arrays can be read.")
    if arr.ndim not in (1, 2):
        raise DataError(
            f"{source} holds a {arr.ndim}-D array of shape {arr.shape}; expected 1-D (one "
            "column) or 2-D (n_rows, n_columns)."
        )
    view = arr[:, None] if arr.ndim == 1 else arr

    def block(start: int, stop: int, idx: list[int]) -> np.ndarray:
        return np.asarray(view[start:stop, idx], dtype=np.float64)

    return [f"col{i}" for i in range(view.shape[1])], block


def npy_source(
    path: Path, columns: Columns, allow_missing: bool, whole: bool = False
) -> tuple[list[str], Chunks]:
    """Names of the selected columns of a ``.npy`` file and a chunk generator over them.

    Parameters
    ----------
    path : Path
        An existing ``.npy`` file (read memory-mapped).
    columns, allow_missing
        As for :func:`clpc.io.read_table`.
    whole : bool
        The caller will hold every selected value at once: refuse more than
        :func:`clpc.io.npz_members.max_load_bytes` up front.

    Returns
    -------
    names : list of str
        The selected column names (``col0..`` or the fields of a structured array).
    chunks : Chunks
        ``chunks(chunk_rows)`` yields float64 values (lines None).
    """
    source = show(path)
    _check_magic(path, (b"\x93NUMPY",), ".npy", "numpy.save")
    try:
        arr = np.load(path, mmap_mode="r", allow_pickle=False)
    except ValueError as exc:
        raise DataError(
            f"{source} cannot be read as a numeric .npy array ({exc}); save a plain numeric "
            "array with numpy.save."
        ) from None
    except (OSError, EOFError) as exc:
        raise DataError(f"{source} is not a valid .npy file ({exc}).") from None
    if arr.dtype.names:
        all_names, block = _structured_block(arr, source)
    else:
        all_names, block = _plain_block(arr, source)
    if whole:
        n_sel = len(resolve_columns(all_names, columns, source))
        check_load(int(arr.shape[0]) * n_sel, source, "the selected columns")
    return _array_source(source, all_names, int(arr.shape[0]), block, columns, allow_missing)


def _npz_layout(path: Path, source: str) -> tuple[list[str] | None, list[Member], list[Member]]:
    """The column names (a string array ``columns``/``names``), 1-D and 2-D members."""
    _check_magic(path, (b"PK\x03\x04", b"PK\x05\x06"), ".npz", "numpy.savez")
    names_arr: list[str] | None = None
    one_d: list[Member] = []
    two_d: list[Member] = []
    for m in npz_members(path, source):
        if len(m.shape) == 0:
            continue
        if m.key in ("columns", "names") and len(m.shape) == 1 and m.dtype.kind in "US":
            names_arr = [str(v) for v in load_member(path, m, source)]
            continue
        if not _numeric_dtype(m.dtype):
            raise DataError(
                f"{source} array {m.key!r} has dtype {m.dtype}; only real numeric arrays "
                "can be read."
            )
        if len(m.shape) > 2:
            raise DataError(
                f"{source} array {m.key!r} is {len(m.shape)}-D (shape {m.shape}); expected "
                "1-D columns or one 2-D table."
            )
        (one_d if len(m.shape) == 1 else two_d).append(m)
    return names_arr, one_d, two_d


def npz_source(
    path: Path, columns: Columns, allow_missing: bool, whole: bool = False
) -> tuple[list[str], Chunks]:
    """Names of the selected columns of a ``.npz`` file and a chunk generator over them.

    Only the array headers are read first; the rows are decompressed a chunk at a time
    (a 2-D array stored in Fortran order is loaded whole, within the load limit).

    Parameters
    ----------
    path : Path
        An existing ``.npz`` file.
    columns, allow_missing
        As for :func:`clpc.io.read_table`.
    whole : bool
        The caller will hold every selected value at once (:func:`clpc.io.read_table`):
        refuse more than :func:`clpc.io.npz_members.max_load_bytes` up front.

    Returns
    -------
    names : list of str
        The selected column names.
    chunks : Chunks
        ``chunks(chunk_rows)`` yields float64 values (lines None).
    """
    source = show(path)
    names_arr, one_d, two_d = _npz_layout(path, source)
    if two_d and (one_d or len(two_d) > 1):
        raise DataError(
            f"{source} mixes arrays {[m.key for m in two_d + one_d]}; a .npz table is either "
            "one 2-D array or 1-D arrays of equal length (one per column)."
        )
    if two_d:
        n_rows, n_cols = two_d[0].shape
        all_names = (
            names_arr
            if names_arr is not None and len(names_arr) == n_cols
            else [f"col{i}" for i in range(n_cols)]
        )
    elif one_d:
        first = one_d[0]
        for m in one_d:
            if m.shape[0] != first.shape[0]:
                raise DataError(
                    f"{source} columns differ in length: {m.key!r} has {m.shape[0]} rows but "
                    f"{first.key!r} has {first.shape[0]}; save columns of equal length."
                )
        all_names = [m.key for m in one_d]
        n_rows = first.shape[0]
    else:
        raise DataError(f"data file {source} is empty (no arrays); it needs at least one row.")
    sel = resolve_columns(all_names, columns, source)
    if whole:
        check_load(n_rows * len(sel), source, "the selected columns")
    if n_rows == 0:
        raise DataError(f"data file {source} is empty (0 rows); it needs at least one row.")
    names = [all_names[i] for i in sel]

    def chunks(chunk_rows: int) -> Iterator[tuple[np.ndarray, None]]:
        start = 0
        for values in _npz_blocks(path, source, one_d, two_d, sel, chunk_rows):
            check_values(values, start, names, source, allow_missing)
            start += values.shape[0]
            yield values, None

    return names, chunks


def _npz_blocks(
    path: Path,
    source: str,
    one_d: list[Member],
    two_d: list[Member],
    sel: list[int],
    chunk_rows: int,
) -> Iterator[np.ndarray]:
    """float64 blocks (rows, len(sel)) of the selected columns."""
    if two_d and two_d[0].fortran:
        table = load_member(path, two_d[0], source)
        for start in range(0, table.shape[0], chunk_rows):
            yield np.asarray(table[start : start + chunk_rows, sel], dtype=np.float64)
        return
    if two_d:
        for (block,) in member_rows(path, two_d, chunk_rows, source):
            yield np.asarray(block[:, sel], dtype=np.float64)
        return
    use = sorted(set(sel))
    members = [one_d[i] for i in use]
    take = [use.index(i) for i in sel]
    for blocks in member_rows(path, members, chunk_rows, source):
        yield np.column_stack([blocks[k] for k in take]).astype(np.float64)


def write_npy(path: Path, arr: np.ndarray) -> None:
    """Write a float64 array of shape (n_rows, n_columns) to ``.npy`` (no column names)."""
    np.save(path, arr, allow_pickle=False)


def write_npz(path: Path, names: list[str], arr: np.ndarray) -> None:
    """Write each column of ``arr`` (shape (n_rows, n_columns)) as a 1-D array named by ``names``.

    Raises
    ------
    DataError
        Repeated column names.
    """
    if len(set(names)) != len(names):
        raise DataError(f"a .npz file needs unique column names; got {names}.")
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_STORED, allowZip64=True) as zf:
        for k, name in enumerate(names):
            with zf.open(name + ".npy", "w", force_zip64=True) as fh:
                np.lib.format.write_array(fh, np.ascontiguousarray(arr[:, k]))
