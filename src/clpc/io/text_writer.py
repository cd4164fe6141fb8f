"""Writing named columns to a text file (CSV/TSV, optionally gzip-compressed).

A header line, then each float in its shortest exact decimal form (``repr``), so the
readers return exactly the same float64 values.
"""

from __future__ import annotations

import gzip
import io
from collections.abc import Callable
from pathlib import Path
from typing import IO

import numpy as np

from clpc.data import DataError

__all__ = ["write_text"]

_ROWS_PER_WRITE = 100_000


def _quote(name: str, delimiter: str) -> str:
    if (
        name == ""
        or delimiter in name
        or any(ch in name for ch in '"#\r\n')
        or (delimiter == " " and any(ch.isspace() for ch in name))
        or name != name.strip()
    ):
        return '"' + name.replace('"', '""') + '"'
    return name


def write_text(path: Path, names: list[str], arr: np.ndarray, delimiter: str | None) -> None:
    """Write a header line and the rows of ``arr`` to a text file.

    Parameters
    ----------
    path : Path
        Destination; ``.tsv``/``.tab`` get tabs, other extensions commas; ``.gz`` is
        compressed.
    names : list of str
        Column names, one per column of ``arr`` (quoted when needed).
    arr : ndarray, shape (n_rows, n_columns)
        float64 values.
    delimiter : str, optional
        One separator character overriding the one of the extension.

    Raises
    ------
    DataError
        A delimiter that is not one separator character.
    """
    lower = path.name.lower().removesuffix(".gz")
    if delimiter is None:
        delimiter = "\t" if lower.endswith((".tsv", ".tab")) else ","
    if len(delimiter) != 1 or delimiter in '"#\r\n.-+0123456789eE':
        raise DataError(f"delimiter must be one separator character; got {delimiter!r}.")
    header = delimiter.join(_quote(n, delimiter) for n in names)
    row_fmt = delimiter.join(["%r"] * arr.shape[1])
    opener: Callable[..., IO[str]] = gzip.open if path.name.lower().endswith(".gz") else open
    with opener(path, "wt", encoding="utf-8", newline="") as f:
        f.write(header + "\n")
        for start in range(0, arr.shape[0], _ROWS_PER_WRITE):
            rows = arr[start : start + _ROWS_PER_WRITE].tolist()
            buf = io.StringIO()
            buf.write("\n".join([row_fmt % tuple(r) for r in rows]))
            buf.write("\n")
            f.write(buf.getvalue())
