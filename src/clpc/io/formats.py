"""Which format a data file is in (by its extension), and whether the file is there."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Literal

from clpc.data import DataError
from clpc.io.errors import DataFileNotFoundError, show
from clpc.io.table import PathLike

__all__ = ["PARQUET_EXTS", "SUPPORTED", "TEXT_EXTS", "Kind", "check_file", "file_kind"]

TEXT_EXTS = (".csv", ".tsv", ".tab", ".txt", ".dat")
PARQUET_EXTS = (".parquet", ".pq")
SUPPORTED = (*TEXT_EXTS, *(e + ".gz" for e in TEXT_EXTS), *PARQUET_EXTS, ".npy", ".npz", ".mat")

Kind = Literal["text", "parquet", "npy", "npz", "mat"]


def file_kind(path: Path) -> Kind:
    """The format of ``path`` by its extension (text files may end in ``.gz``).

    Raises
    ------
    DataError
        An unsupported extension (the message lists the supported ones).
    """
    name = path.name.lower()
    if name.endswith(tuple(e + ".gz" for e in TEXT_EXTS)) or name.endswith(TEXT_EXTS):
        return "text"
    if name.endswith(PARQUET_EXTS):
        return "parquet"
    if name.endswith(".npy"):
        return "npy"
    if name.endswith(".npz"):
        return "npz"
    if name.endswith(".mat"):
        return "mat"
    ext = "".join(path.suffixes[-2:]) if path.suffix.lower() == ".gz" else path.suffix
    hint = ""
    if ext.lower() in (".xlsx", ".xls", ".ods"):
        hint = " Export the sheet as CSV first."
    elif not ext:
        hint = " Rename the file with one of these extensions."
    raise DataError(
        f"unsupported data file extension {ext or '(none)'!r} of {show(path)}; "
        f"supported: {', '.join(SUPPORTED)}.{hint}"
    )


def check_file(path: PathLike) -> Path:
    """``path`` as a :class:`~pathlib.Path`, after checking that it is an existing file.

    Raises
    ------
    DataFileNotFoundError
        The file does not exist.
    DataError
        The path is a directory.
    """
    p = Path(os.fspath(path))
    if not p.exists():
        raise DataFileNotFoundError(
            f"data file {show(p)} does not exist (resolved to '{p.resolve()}'); "
            "check the path and the working directory."
        )
    if p.is_dir():
        raise DataError(f"{show(p)} is a directory, not a data file; pass a file path.")
    return p
