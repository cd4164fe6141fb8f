"""Parsing the numbers of a text data file (CSV/TSV/whitespace), batch by batch.

Numbers are parsed in C by :func:`numpy.loadtxt` in batches of lines; only a batch that
fails is re-read in Python to report the exact line, column and text.
"""

from __future__ import annotations

import math
import operator
import shutil
import stat
import tempfile
import warnings
from collections.abc import Iterator
from itertools import islice, repeat
from pathlib import Path

import numpy as np

from clpc.data import DataError
from clpc.io.arrow_text import FallBack, arrow_batches, fast_path_applies
from clpc.io.errors import cell_error, first_bad, parse_number, show
from clpc.io.table import Chunks, Columns, reorder_columns, resolve_columns
from clpc.io.text_format import (
    READ_ERRORS,
    TextFormat,
    is_content,
    open_text,
    read_error,
    sniff,
    split_fields,
)

__all__ = ["TextReader", "text_source"]


class TextReader:
    """Parses batches of lines of one text file into float64 arrays.

    Parameters
    ----------
    path : Path
        The text file.
    fmt : TextFormat
        Its layout (from :func:`~clpc.io.text_format.sniff`).
    use : list of int
        The sorted unique 0-based columns to read.
    allow_missing : bool
        Keep empty cells and NaN/inf as NaN instead of raising.
    fast : bool
        Use pyarrow when it is installed (default); ``False``: the plain reader only (the
        reference of the tests and benchmarks).
    """

    def __init__(
        self, path: Path, fmt: TextFormat, use: list[int], allow_missing: bool, fast: bool = True
    ):
        self.fast = fast
        self.path = path
        self.source = show(path)
        self.fmt = fmt
        self.use = use
        self.full = use == list(range(fmt.n_cols))
        self.allow_missing = allow_missing

    def batches(self, chunk_rows: int) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """Values (n, len(use)) and 1-based line numbers (n,) of ``chunk_rows`` lines at a time.

        Through pyarrow when it is installed and the file is plain (:mod:`clpc.io.arrow_text`;
        its blocks are re-cut into ``chunk_rows`` rows), else, and from the first block the
        fast path cannot vouch for, by the plain reader.
        """
        done = 0
        if self.fast and fast_path_applies(self.path, self.fmt):
            try:
                for values, rows in rechunk(
                    arrow_batches(self.path, self.fmt, self.use, self.allow_missing), chunk_rows
                ):
                    yield values, rows
                    done += values.shape[0]
                return
            except FallBack:
                pass
        for values, rows in self.plain_batches(chunk_rows):
            if done >= values.shape[0]:
                done -= values.shape[0]
                continue
            yield values[done:], rows[done:]
            done = 0

    def plain_batches(self, chunk_rows: int) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """As :meth:`batches`, always by the plain reader (``numpy.loadtxt`` and Python)."""
        with open_text(self.path) as f:
            try:
                for _ in range(self.fmt.data_line - 1):
                    next(f, None)
                line_no = self.fmt.data_line
                while True:
                    lines = list(islice(f, chunk_rows))
                    if not lines:
                        return
                    data, rows = self.parse(lines, line_no)
                    line_no += len(lines)
                    if data.shape[0]:
                        yield data, rows
            except READ_ERRORS as exc:
                raise read_error(self.path, exc) from None

    def parse(self, lines: list[str], first_no: int) -> tuple[np.ndarray, np.ndarray]:
        """Values (n, len(use)) and 1-based line numbers (n,) of a batch of lines."""
        arr = self._fast(lines)
        rows: np.ndarray | None = None
        if arr is not None:
            if arr.shape[0] == len(lines):
                rows = np.arange(first_no, first_no + len(lines), dtype=np.int64)
            else:
                idx = [i for i, line in enumerate(lines) if is_content(line)]
                if len(idx) == arr.shape[0]:
                    rows = first_no + np.asarray(idx, dtype=np.int64)
        if arr is None or rows is None:
            return self._slow(lines, first_no)
        if not self.allow_missing:
            bad = first_bad(arr)
            if bad is not None:
                row, col = bad
                no = int(rows[row])
                fields = split_fields(lines[no - first_no], self.fmt.delimiter, strip_comment=True)
                c = self.use[col]
                text = fields[c] if c < len(fields) else str(arr[row, col])
                raise cell_error(f"line {no}", self.fmt.names[c], text, self.source)
        return arr, rows

    def _fast(self, lines: list[str]) -> np.ndarray | None:
        """numpy.loadtxt on the batch; None when anything looks unusual."""
        fmt = self.fmt
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # "input contained no data"
                if not self.full and not self._field_counts_ok(lines):
                    return None
                arr = np.loadtxt(
                    lines,
                    dtype=np.float64,
                    delimiter=fmt.delimiter,
                    comments="#",
                    quotechar='"',
                    ndmin=2,
                    usecols=None if self.full else self.use,
                )
                n_cols = fmt.n_cols if self.full else len(self.use)
                if arr.shape[0] == 0:
                    return np.empty((0, n_cols))
                if arr.shape[1] != n_cols:
                    return None
                return arr
        except ValueError:
            return None

    def _field_counts_ok(self, lines: list[str]) -> bool:
        """Every content line has ``n_cols`` fields (a cheap check: no quotes or comments)."""
        n = len(lines)
        if self.fmt.delimiter is None:
            counts = np.fromiter(map(len, map(str.split, lines)), dtype=np.int64, count=n)
            expected = self.fmt.n_cols
        else:
            if any(map(operator.contains, lines, repeat('"'))):
                return False
            counts = np.fromiter(
                map(str.count, lines, repeat(self.fmt.delimiter)), dtype=np.int64, count=n
            )
            expected = self.fmt.n_cols - 1
        bad = np.flatnonzero(counts != expected)
        return all(not is_content(lines[i]) for i in bad)

    def _slow(self, lines: list[str], first_no: int) -> tuple[np.ndarray, np.ndarray]:
        """Python parsing of a batch: exact diagnostics (line, column, text)."""
        fmt = self.fmt
        values: list[list[float]] = []
        rows: list[int] = []
        for i, line in enumerate(lines):
            if not is_content(line):
                continue
            no = first_no + i
            fields = split_fields(line, fmt.delimiter, strip_comment=True)
            if len(fields) != fmt.n_cols:
                raise self._ragged(no, len(fields))
            values.append([self._cell(fields[c], no, c) for c in self.use])
            rows.append(no)
        arr = np.array(values, dtype=np.float64).reshape(len(values), len(self.use))
        return arr, np.asarray(rows, dtype=np.int64)

    def _cell(self, text: str, no: int, c: int) -> float:
        """The value of field ``text`` in column ``c`` of line ``no`` (empty: NaN)."""
        try:
            value = parse_number(text) if text else math.nan
        except ValueError:
            raise cell_error(f"line {no}", self.fmt.names[c], text, self.source) from None
        if not self.allow_missing and not math.isfinite(value):
            raise cell_error(f"line {no}", self.fmt.names[c], text, self.source)
        return value

    def _ragged(self, no: int, got: int) -> DataError:
        fmt = self.fmt
        if fmt.header_line is not None:
            ref = f"the header (line {fmt.header_line})"
        else:
            ref = f"the first data row (line {fmt.data_line})"
        return DataError(
            f"{self.source} line {no} has {got} field(s) but {ref} has {fmt.n_cols} "
            f"(delimiter {fmt.describe_delimiter()}); fix or remove that row, or pass "
            "delimiter= if the separator was guessed wrongly."
        )


def text_source(
    path: Path,
    columns: Columns,
    delimiter: str | None,
    header: bool | None,
    allow_missing: bool,
    skip_rows: int = 0,
    fast: bool = True,
) -> tuple[list[str], Chunks]:
    """Names of the selected columns of a text file and a chunk generator over them.

    Parameters
    ----------
    path : Path
        An existing text data file.
    columns, delimiter, header, allow_missing, skip_rows
        As for :func:`clpc.io.read_table`.
    fast : bool
        Use pyarrow when installed (see :class:`TextReader`).

    Returns
    -------
    names : list of str
        The selected column names, in the order asked for.
    chunks : Chunks
        ``chunks(chunk_rows)`` yields values and the 1-based line number of each row.
    """
    spool, given = None, path
    if not stat.S_ISREG(path.stat().st_mode):
        spool, path = _spool(path)
    fmt = sniff(path, delimiter, header, skip_rows)
    sel = resolve_columns(fmt.names, columns, show(given))
    use = sorted(set(sel))
    reader = TextReader(path, fmt, use, allow_missing, fast)
    reader.source = show(given)
    batches = reader.batches
    if spool is not None:

        def batches(chunk_rows: int) -> Iterator[tuple[np.ndarray, np.ndarray]]:
            with spool:  # removed once read
                yield from reader.batches(chunk_rows)

    return [fmt.names[i] for i in sel], reorder_columns(batches, use, sel)


def _spool(path: Path) -> tuple[tempfile.TemporaryDirectory[str], Path]:
    """A named pipe or device copied to a temporary file, read once (nothing lost).

    The layout is sniffed from the first lines and the data read from the start again:
    a stream cannot be read twice, so it is copied to disk first (not into memory).
    """
    folder = tempfile.TemporaryDirectory(prefix="clpc-")
    copy = Path(folder.name) / path.name
    with open(path, "rb") as src, open(copy, "wb") as dst:
        shutil.copyfileobj(src, dst, 1 << 20)
    return folder, copy


def rechunk(
    blocks: Iterator[tuple[np.ndarray, np.ndarray]], chunk_rows: int
) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """The rows of ``blocks`` re-cut into pieces of exactly ``chunk_rows`` (the last fewer)."""
    values: list[np.ndarray] = []
    rows: list[np.ndarray] = []
    held = 0
    for v, r in blocks:
        values.append(v)
        rows.append(r)
        held += v.shape[0]
        if held < chunk_rows:
            continue
        all_v = values[0] if len(values) == 1 else np.concatenate(values)
        all_r = rows[0] if len(rows) == 1 else np.concatenate(rows)
        cut = held - held % chunk_rows
        for lo in range(0, cut, chunk_rows):
            yield all_v[lo : lo + chunk_rows], all_r[lo : lo + chunk_rows]
        values, rows, held = [all_v[cut:]], [all_r[cut:]], held - cut
    if held:
        yield np.concatenate(values), np.concatenate(rows)
