"""The data readers' errors and their one-line messages about a bad cell.

Every message names the file, the place (1-based *line* of a text file, 1-based data *row*
of a binary file), the column and how to fix it. The readers of every format share these
helpers, so a missing or non-numeric cell reads the same whatever the file format.
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence

import numpy as np

from clpc.data import DataError
from clpc.data.samples import NUMBER_TEXT

__all__ = [
    "DataFileNotFoundError",
    "cell_error",
    "check_values",
    "first_bad",
    "is_number",
    "parse_number",
    "show",
]

#: what a numeric cell may hold (the one definition, shared with IOData's text input)
_NUMBER = NUMBER_TEXT


class DataFileNotFoundError(DataError, FileNotFoundError):
    """A data file does not exist (both a :class:`DataError` and a ``FileNotFoundError``)."""


def show(path: str | os.PathLike[str]) -> str:
    """``path`` quoted for a message: ``'data/run1.csv'``."""
    return f"'{os.fspath(path)}'"


def is_number(text: str) -> bool:
    """Whether ``text`` is a number for every reader (``"nan"`` and ``"inf"`` count)."""
    return _NUMBER.fullmatch(text.strip()) is not None


def parse_number(text: str) -> float:
    """The value of a numeric cell: ASCII decimal (``1``, ``-2.5e-3``, ``.5``), nan or inf.

    ``float`` alone would also take ``"1_000"``, Arabic-Indic or full-width digits; every
    reader (files, ``clpc stream``) refuses those the same way.

    Raises
    ------
    ValueError
        ``text`` is not such a number.
    """
    if _NUMBER.fullmatch(text.strip()) is None:
        raise ValueError(f"{text!r} is not a decimal number")
    return float(text)


def cell_error(where: str, column: str, text: str, source: str) -> DataError:
    """The error for one cell that is empty, not finite or not a number.

    Parameters
    ----------
    where : str
        The place in the file, e.g. ``"line 12"`` or ``"row 11"``.
    column : str
        The column name.
    text : str
        The cell as written in the file.
    source : str
        The file, as given by :func:`show`.

    Returns
    -------
    DataError
        A one-line message naming the place, the column and the fix.
    """
    text = text.strip()
    shown = text if len(text) <= 60 else f"{text[:40]}... ({len(text):,} characters)"
    if not text:
        return DataError(
            f"{source} {where}, column {column!r}: empty cell (a missing value); fill or "
            "interpolate the missing samples, or remove the row."
        )
    if is_number(text):  # nan or inf
        return DataError(
            f"{source} {where}, column {column!r}: {shown!r} is not a finite number; remove "
            "or interpolate missing samples before identification."
        )
    hint = ""
    if re.fullmatch(r"[+-]?\d+,\d+([eE][+-]?\d+)?", text):
        hint = " Decimal commas are not supported: use '.' as the decimal point."
    return DataError(
        f"{source} {where}, column {column!r}: {shown!r} is not a number; fix the cell or "
        f"leave the column out of the selection.{hint}"
    )


def first_bad(values: np.ndarray) -> tuple[int, int] | None:
    """``(row, column)`` of the first non-finite entry of a 2-D array, or None."""
    bad = ~np.isfinite(values)
    if not bad.any():
        return None
    row, col = np.argwhere(bad)[0]
    return int(row), int(col)


def check_values(
    values: np.ndarray, offset: int, names: Sequence[str], source: str, allow_missing: bool
) -> None:
    """Refuse a non-finite value in a chunk of a binary file (unless ``allow_missing``).

    Parameters
    ----------
    values : ndarray, shape (n_rows, n_columns)
        One chunk of float64 values.
    offset : int
        0-based row of the file where the chunk starts.
    names : sequence of str
        Column names, one per column of ``values``.
    source : str
        The file, as given by :func:`show`.
    allow_missing : bool
        Accept NaN/inf (nothing is checked).

    Raises
    ------
    DataError
        Names the 1-based row and the column of the first non-finite value.
    """
    if allow_missing:
        return
    bad = first_bad(values)
    if bad is not None:
        row, col = bad
        raise cell_error(
            f"row {offset + row + 1}", names[col], repr(float(values[row, col])), source
        )
