"""What the first lines of a text data file say: delimiter, header and column names.

The delimiter is detected among tab, ``;``, ``,``, ``|`` and runs of whitespace (the first
one that splits every sampled line into the same number (> 1) of fields). The first
non-comment line is a header when one of its fields is not a number; otherwise the columns
are named ``col0, col1, ...`` (or after a ``numpy.savetxt`` style ``#`` header line with
the right number of names); a units row under the header (every field text, e.g.
``s,m,m,V``) is skipped, and so are ``skip_rows`` lines at the top (a metadata line). Lines
starting with ``#`` and blank lines are skipped;
``"quoted"`` fields, Windows line endings, a UTF-8 byte order mark and gzip compression
(``.csv.gz``) are understood.
"""

from __future__ import annotations

import csv
import gzip
import io
import re
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import IO

from clpc.data import DataError
from clpc.io.budget import LINE_ENV, CountedReader, check_columns, limit, line_too_long
from clpc.io.errors import is_number, show

__all__ = [
    "READ_ERRORS",
    "TextFormat",
    "decode_error",
    "is_content",
    "open_binary",
    "open_text",
    "read_error",
    "sniff",
    "split_fields",
]

_CANDIDATES = ("\t", ";", ",", "|")
_SNIFF_LINES = 32
_WS_FIELD = re.compile(r'"((?:[^"]|"")*)"|(\S+)')


@dataclass(frozen=True)
class TextFormat:
    """The layout of a text data file, found by :func:`sniff`.

    Attributes
    ----------
    delimiter : str or None
        The field separator; None for runs of whitespace.
    names : list of str
        Column names (from the header, or ``col0, col1, ...``).
    header_line : int or None
        1-based line of the header, None when the file has none.
    data_line : int
        1-based physical line where data reading starts (after a units row, if any).
    """

    delimiter: str | None
    names: list[str]
    header_line: int | None
    data_line: int

    @property
    def n_cols(self) -> int:
        """Number of fields in every data line."""
        return len(self.names)

    def describe_delimiter(self) -> str:
        """The delimiter for a message: ``"','"`` or ``"whitespace"``."""
        return "whitespace" if self.delimiter is None else repr(self.delimiter)


def open_binary(path: Path) -> IO[bytes]:
    """Open a data file's bytes; a ``.gz`` is decompressed as a stream within the read limit.

    Past ``CLPC_MAX_READ_BYTES`` (:mod:`clpc.io.budget`) a read raises a ``DataError``.
    """
    if path.name.lower().endswith(".gz"):
        return io.BufferedReader(CountedReader(gzip.open(path, "rb"), show(path)), 1 << 16)
    return open(path, "rb")


def open_text(path: Path) -> IO[str]:
    """Open a text data file (gzip when it ends in ``.gz``; a UTF-8 BOM is dropped)."""
    return io.TextIOWrapper(open_binary(path), encoding="utf-8-sig", newline=None)


def is_content(line: str) -> bool:
    """Whether ``line`` holds data (not blank, not a ``#`` comment)."""
    s = line.strip()
    return bool(s) and not s.startswith("#")


def split_fields(line: str, delimiter: str | None, *, strip_comment: bool = False) -> list[str]:
    """Fields of one line (quotes removed, surrounding whitespace stripped)."""
    line = line.rstrip("\r\n")
    if strip_comment and "#" in line and '"' not in line:
        line = line[: line.index("#")]
    if delimiter is None:
        return [
            bare if bare else quoted.replace('""', '"') for quoted, bare in _WS_FIELD.findall(line)
        ]
    row = next(csv.reader([line], delimiter=delimiter), [])
    return [f.strip() for f in row]


def decode_error(path: Path, exc: UnicodeDecodeError) -> DataError:
    """The error for a file that is not UTF-8 text."""
    return DataError(
        f"{show(path)} is not UTF-8 text (byte {exc.start} of a block: {exc.reason}); "
        "re-save it as UTF-8 CSV, or check that it is really a text file."
    )


#: what reading a text file can raise besides OSError: bad UTF-8, a truncated or corrupt gzip
READ_ERRORS = (UnicodeDecodeError, EOFError, gzip.BadGzipFile, zlib.error)


def read_error(path: Path, exc: Exception) -> DataError:
    """The one-line error naming ``path`` for an exception of :data:`READ_ERRORS`."""
    if isinstance(exc, UnicodeDecodeError):
        return decode_error(path, exc)
    if isinstance(exc, EOFError):
        return DataError(
            f"{show(path)} ends in the middle of its gzip stream (the file is truncated: "
            "an interrupted download or copy?); copy it again or decompress what is there."
        )
    return DataError(
        f"{show(path)} is not a valid gzip file ({exc}); a name ending in .gz must hold "
        "gzip-compressed text: rename it without .gz if it is plain text."
    )


def _detect_delimiter(lines: list[str]) -> str | None:
    for subset in (lines, lines[1:]):
        if not subset:
            continue
        for delim in (*_CANDIDATES, None):
            counts = {len(split_fields(line, delim)) for line in subset}
            if len(counts) == 1 and counts.pop() > 1:
                return delim
    data = lines[1] if len(lines) > 1 else lines[0]
    best = max(_CANDIDATES, key=data.count)
    if data.count(best):
        return best
    if len(data.split()) > 1:
        return None
    return ","  # a single column


def _choose_delimiter(delimiter: str | None, lines: list[str]) -> str | None:
    """The delimiter asked for (None: detected from ``lines``); None means whitespace."""
    if delimiter is None:
        return _detect_delimiter(lines)
    if not isinstance(delimiter, str):
        raise DataError(f"delimiter must be a string; got {delimiter!r}.")
    if delimiter in (" ", "whitespace", "\\s+"):
        return None
    if delimiter in ("tab", "\\t"):
        return "\t"
    if len(delimiter) != 1 or delimiter in '"#\r\n':
        raise DataError(
            f"delimiter must be one character (e.g. ',', ';', '\\t', '|') or 'whitespace'; "
            f"got {delimiter!r}."
        )
    return delimiter


def _first_lines(path: Path, skip_rows: int = 0) -> tuple[list[str], list[tuple[int, str]]]:
    """The comment lines before the data and up to 32 ``(line number, line)`` of data.

    The first ``skip_rows`` physical lines (e.g. a metadata line) are passed over.
    """
    comments: list[str] = []
    content: list[tuple[int, str]] = []
    longest = limit(LINE_ENV)
    with open_text(path) as f:
        try:
            for no, line in enumerate(iter(lambda: f.readline(longest + 1), ""), 1):
                if len(line) > longest:
                    raise line_too_long(show(path), no)
                if no <= skip_rows:
                    continue
                if is_content(line):
                    content.append((no, line))
                    if len(content) >= _SNIFF_LINES:
                        break
                elif not content and line.strip():
                    comments.append(line)
                if content and no > content[0][0] + 8 * _SNIFF_LINES:
                    break
        except READ_ERRORS as exc:
            raise read_error(path, exc) from None
    if not content:
        what = "only comment lines" if comments else "no lines with data"
        raise DataError(f"data file {show(path)} is empty ({what}); it needs at least one row.")
    return comments, content


def sniff(path: Path, delimiter: str | None, header: bool | None, skip_rows: int = 0) -> TextFormat:
    """Read the first lines of a text data file and find its layout.

    Parameters
    ----------
    path : Path
        The text file (optionally gzip-compressed).
    delimiter : str, optional
        As for :func:`clpc.io.read_table`; None: detected.
    header : bool, optional
        Whether the first non-comment line holds column names; None: detected.
    skip_rows : int
        Physical lines to pass over first (a metadata line, a title).

    Returns
    -------
    TextFormat
        Delimiter, column names and where the data starts. A line right under the header
        whose every field is text (a units row such as ``s,m,m,V``) is skipped.

    Raises
    ------
    DataError
        An empty file, a file that is not UTF-8 text, an invalid ``delimiter``, or a
        file beyond a limit of :mod:`clpc.io.budget` (decompressed size, line length,
        number of columns).
    """
    comments, content = _first_lines(path, skip_rows)
    try:
        fmt = _layout(comments, content, delimiter, header)
        check_columns(fmt.n_cols, show(path))
        return fmt
    except csv.Error as exc:  # e.g. a field over the csv module's limit (131,072 characters)
        raise DataError(
            f"{show(path)} cannot be split into fields near line {content[0][0]} ({exc}); "
            "check that it is a delimited text file, or pass delimiter=."
        ) from None


def _layout(
    comments: list[str], content: list[tuple[int, str]], delimiter: str | None, header: bool | None
) -> TextFormat:
    """The :class:`TextFormat` of the first comment and content lines of a file."""
    lines = [line for _, line in content]
    delim = _choose_delimiter(delimiter, lines)
    first = split_fields(lines[0], delim)
    if header is None:
        has_header = any(f and not is_number(f) for f in first)
    else:
        has_header = bool(header)
    if has_header:
        names = [f or f"col{i}" for i, f in enumerate(first)]
        if len(content) > 1:
            second = split_fields(lines[1], delim)
            if len(second) == len(first) and all(f and not is_number(f) for f in second):
                return TextFormat(delim, names, content[0][0], content[1][0] + 1)
        return TextFormat(delim, names, content[0][0], content[0][0] + 1)
    names = [f"col{i}" for i in range(len(first))]
    if comments and header is None:  # numpy.savetxt writes its header as "# a,b,c"
        candidate = split_fields(comments[-1].strip().lstrip("#"), delim)
        if len(candidate) == len(first) and all(c and not is_number(c) for c in candidate):
            names = candidate
    return TextFormat(delim, names, None, content[0][0])
