"""Reading and writing users' records: CSV/TSV/whitespace text, Parquet, ``.npy``, ``.npz``.

>>> from clpc.io import load_iodata                                   # doctest: +SKIP
>>> data = load_iodata("run1.csv", inputs="u", outputs="y", time_column="t")  # doctest: +SKIP

Every reader returns float64 numbers and checks them once; a bad file gives a one-line
:class:`clpc.data.DataError` that names the file, the place (1-based *line* of a text
file, 1-based data *row* of a binary file), the column and how to fix it.

Text files
    The delimiter is detected among tab, ``;``, ``,``, ``|`` and runs of whitespace (the
    first one that splits every sampled line into the same number (> 1) of fields). The
    first non-comment line is a header when one of its fields is not a number; otherwise
    the columns are named ``col0, col1, ...`` (or after a ``numpy.savetxt`` style ``#``
    header line with the right number of names). Lines starting with ``#`` and blank
    lines are skipped; ``"quoted"`` fields, Windows line endings, a UTF-8 byte order
    mark and gzip compression (``.csv.gz``) are understood. Numbers are parsed in C by
    :func:`numpy.loadtxt` in batches; only a batch that fails is re-read in Python to
    report the exact line, column and text.
Parquet (``.parquet``, ``.pq``)
    Needs pyarrow (or pandas with a Parquet engine): ``pip install 'clpc[frames]'``.
    Numeric and boolean columns are read as float64; timestamp and duration columns as
    seconds since the first row.
``.npy``
    A 1-D array (one column), a 2-D array (columns ``col0..``) or a structured array (one
    column per field); read memory-mapped, so chunks of a large file stay on disk.
``.npz``
    One 1-D array per column (named by its key, in file order; 0-d entries are ignored),
    or a single 2-D array (columns ``col0..``, or named by a string array ``columns``).
"""

from __future__ import annotations

import csv
import difflib
import gzip
import io
import math
import operator
import os
import re
import warnings
import zipfile
from collections.abc import Callable, Iterator, Sequence
from itertools import islice, repeat
from pathlib import Path
from typing import IO, Any

import numpy as np

from clpc.data import DataError, IOData

__all__ = [
    "DataFileNotFoundError",
    "Table",
    "iter_table_chunks",
    "load_iodata",
    "read_table",
    "write_table",
]

PathLike = str | os.PathLike[str]
ColumnKey = str | int

_TEXT_EXTS = (".csv", ".tsv", ".tab", ".txt", ".dat")
_PARQUET_EXTS = (".parquet", ".pq")
_SUPPORTED = (*_TEXT_EXTS, *(e + ".gz" for e in _TEXT_EXTS), *_PARQUET_EXTS, ".npy", ".npz")
_CANDIDATES = ("\t", ";", ",", "|")
_SNIFF_LINES = 32
_READ_CHUNK = 200_000
_FRAMES_HINT = "pip install 'clpc[frames]'"


class DataFileNotFoundError(DataError, FileNotFoundError):
    """A data file does not exist (both a :class:`DataError` and a ``FileNotFoundError``)."""


# =============================================================================== Table
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

    def __init__(self, names: Sequence[str], data: Any, source: str = "") -> None:
        arr = np.asarray(data, dtype=np.float64)
        if arr.ndim == 1:
            arr = arr[:, None]
        if arr.ndim != 2:
            raise DataError(f"Table data must be 1-D or 2-D; got shape {arr.shape}.")
        if isinstance(names, str):
            names = [names]
        names = [str(n) for n in names]
        if len(names) != arr.shape[1]:
            raise DataError(
                f"Table needs one name per column: {arr.shape[1]} column(s), "
                f"{len(names)} name(s) {names}."
            )
        self.names: list[str] = names
        self.data: np.ndarray = arr
        self.source: str = str(source)
        self._first = 1  # label number of row 0 when _lines is None
        self._lines: np.ndarray | None = None  # 1-based file line of each row (text files)
        self._unit = "row"

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

        Raises
        ------
        DataError
            Unknown or ambiguous name, or an index out of range (lists the columns).
        """
        return _resolve_one(self.names, key, self.source or "the table")

    def column(self, key: ColumnKey) -> np.ndarray:
        """The values of column ``key`` (name or index), shape (n_rows,)."""
        return self.data[:, self.index(key)]

    def __getitem__(self, key: ColumnKey) -> np.ndarray:
        return self.column(key)

    def row_label(self, row: int) -> str:
        """Where 0-based row ``row`` is in the source: ``"line 12"`` (text) or ``"row 11"``."""
        if self._lines is not None:
            return f"line {int(self._lines[row])}"
        return f"{self._unit} {self._first + int(row)}"


def _table(names: list[str], data: np.ndarray, source: str, lines: np.ndarray | None) -> Table:
    """Build a :class:`Table` with its row locator (compressed when lines are contiguous)."""
    table = Table(names, data, source)
    if lines is not None:
        table._unit = "line"
        if lines.size == 0 or int(lines[-1]) - int(lines[0]) == lines.size - 1:
            table._first = int(lines[0]) if lines.size else 1
        else:
            table._lines = lines
    return table


# ============================================================================ helpers
def _show(path: Any) -> str:
    return f"'{os.fspath(path)}'"


def _kind(path: Path) -> str:
    name = path.name.lower()
    if name.endswith(tuple(e + ".gz" for e in _TEXT_EXTS)) or name.endswith(_TEXT_EXTS):
        return "text"
    if name.endswith(_PARQUET_EXTS):
        return "parquet"
    if name.endswith(".npy"):
        return "npy"
    if name.endswith(".npz"):
        return "npz"
    ext = "".join(path.suffixes[-2:]) if path.suffix.lower() == ".gz" else path.suffix
    hint = ""
    if ext.lower() in (".xlsx", ".xls", ".ods"):
        hint = " Export the sheet as CSV first."
    elif not ext:
        hint = " Rename the file with one of these extensions."
    raise DataError(
        f"unsupported data file extension {ext or '(none)'!r} of {_show(path)}; "
        f"supported: {', '.join(_SUPPORTED)}.{hint}"
    )


def _check_file(path: PathLike) -> Path:
    p = Path(os.fspath(path))
    if not p.exists():
        raise DataFileNotFoundError(
            f"data file {_show(p)} does not exist (resolved to '{p.resolve()}'); "
            "check the path and the working directory."
        )
    if p.is_dir():
        raise DataError(f"{_show(p)} is a directory, not a data file; pass a file path.")
    return p


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _resolve_one(names: Sequence[str], key: Any, source: str) -> int:
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


def _list_names(names: Sequence[str], limit: int = 25) -> str:
    shown = list(names[:limit])
    more = f" ... and {len(names) - limit} more" if len(names) > limit else ""
    return f"{shown}{more}"


def _resolve(names: Sequence[str], columns: Any, source: str) -> list[int]:
    """0-based indices of ``columns`` (None: all) in ``names``."""
    if columns is None:
        return list(range(len(names)))
    if isinstance(columns, (str, int, np.integer)):
        columns = [columns]
    keys = list(columns)
    if not keys:
        raise DataError("columns is empty; select at least one column (or pass None for all).")
    return [_resolve_one(names, key, source) for key in keys]


def _cell_error(where: str, column: str, text: str, source: str) -> DataError:
    text = text.strip()
    if not text:
        return DataError(
            f"{source} {where}, column {column!r}: empty cell (a missing value); fill or "
            "interpolate the missing samples, or remove the row."
        )
    if _is_number(text):  # nan or inf
        return DataError(
            f"{source} {where}, column {column!r}: {text!r} is not a finite number; remove "
            "or interpolate missing samples before identification."
        )
    hint = ""
    if re.fullmatch(r"[+-]?\d+,\d+([eE][+-]?\d+)?", text):
        hint = " Decimal commas are not supported: use '.' as the decimal point."
    return DataError(
        f"{source} {where}, column {column!r}: {text!r} is not a number; fix the cell or "
        f"leave the column out of the selection.{hint}"
    )


def _first_bad(values: np.ndarray) -> tuple[int, int] | None:
    bad = ~np.isfinite(values)
    if not bad.any():
        return None
    row, col = np.argwhere(bad)[0]
    return int(row), int(col)


# ======================================================================= text files
def _open_text(path: Path) -> IO[str]:
    if path.name.lower().endswith(".gz"):
        return gzip.open(path, "rt", encoding="utf-8-sig", newline=None)
    return open(path, encoding="utf-8-sig", newline=None)


def _is_content(line: str) -> bool:
    s = line.strip()
    return bool(s) and not s.startswith("#")


_WS_FIELD = re.compile(r'"((?:[^"]|"")*)"|(\S+)')


def _split(line: str, delimiter: str | None, *, strip_comment: bool = False) -> list[str]:
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


def _detect_delimiter(lines: list[str]) -> str | None:
    for subset in (lines, lines[1:]):
        if not subset:
            continue
        for delim in (*_CANDIDATES, None):
            counts = {len(_split(line, delim)) for line in subset}
            if len(counts) == 1 and counts.pop() > 1:
                return delim
    data = lines[1] if len(lines) > 1 else lines[0]
    best = max(_CANDIDATES, key=data.count)
    if data.count(best):
        return best
    if len(data.split()) > 1:
        return None
    return ","  # a single column


class _TextFormat:
    """What the first lines of a text file say about the rest."""

    def __init__(
        self,
        delimiter: str | None,
        names: list[str],
        header_line: int | None,
        data_line: int,
    ) -> None:
        self.delimiter = delimiter
        self.names = names
        self.n_cols = len(names)
        self.header_line = header_line
        self.data_line = data_line  # 1-based physical line where data reading starts

    def describe_delimiter(self) -> str:
        return "whitespace" if self.delimiter is None else repr(self.delimiter)


def _normalise_delimiter(delimiter: str | None) -> str | bool | None:
    """``False``: detect; ``None``: whitespace; else the one-character delimiter."""
    if delimiter is None:
        return False
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


def _sniff(path: Path, delimiter: str | None, header: bool | None) -> _TextFormat:
    comments: list[str] = []
    content: list[tuple[int, str]] = []
    with _open_text(path) as f:
        try:
            for no, line in enumerate(f, 1):
                if _is_content(line):
                    content.append((no, line))
                    if len(content) >= _SNIFF_LINES:
                        break
                elif not content and line.strip():
                    comments.append(line)
                if content and no > content[0][0] + 8 * _SNIFF_LINES:
                    break
        except UnicodeDecodeError as exc:
            raise _decode_error(path, exc) from None
    if not content:
        what = "only comment lines" if comments else "no lines with data"
        raise DataError(f"data file {_show(path)} is empty ({what}); it needs at least one row.")
    lines = [line for _, line in content]
    chosen = _normalise_delimiter(delimiter)
    delim = _detect_delimiter(lines) if chosen is False else chosen
    first = _split(lines[0], delim)
    if header is None:
        has_header = any(f and not _is_number(f) for f in first)
    else:
        has_header = bool(header)
    if has_header:
        names = [f or f"col{i}" for i, f in enumerate(first)]
        return _TextFormat(delim, names, content[0][0], content[0][0] + 1)
    names = [f"col{i}" for i in range(len(first))]
    if comments and header is None:  # numpy.savetxt writes its header as "# a,b,c"
        candidate = _split(comments[-1].strip().lstrip("#"), delim)
        if len(candidate) == len(first) and all(c and not _is_number(c) for c in candidate):
            names = candidate
    return _TextFormat(delim, names, None, content[0][0])


def _decode_error(path: Path, exc: UnicodeDecodeError) -> DataError:
    return DataError(
        f"{_show(path)} is not UTF-8 text (byte {exc.start} of a block: {exc.reason}); "
        "re-save it as UTF-8 CSV, or check that it is really a text file."
    )


class _TextReader:
    """Parses batches of lines of one text file into float64 arrays."""

    def __init__(self, path: Path, fmt: _TextFormat, use: list[int], allow_missing: bool):
        self.path = path
        self.source = _show(path)
        self.fmt = fmt
        self.use = use
        self.full = use == list(range(fmt.n_cols))
        self.allow_missing = allow_missing

    # ------------------------------------------------------------------- batches
    def batches(self, chunk_rows: int) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        with _open_text(self.path) as f:
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
            except UnicodeDecodeError as exc:
                raise _decode_error(self.path, exc) from None

    def parse(self, lines: list[str], first_no: int) -> tuple[np.ndarray, np.ndarray]:
        """Values (n, len(use)) and 1-based line numbers (n,) of a batch of lines."""
        arr = self._fast(lines)
        rows: np.ndarray | None = None
        if arr is not None:
            if arr.shape[0] == len(lines):
                rows = np.arange(first_no, first_no + len(lines), dtype=np.int64)
            else:
                idx = [i for i, line in enumerate(lines) if _is_content(line)]
                if len(idx) == arr.shape[0]:
                    rows = first_no + np.asarray(idx, dtype=np.int64)
        if arr is None or rows is None:
            return self._slow(lines, first_no)
        if not self.allow_missing:
            bad = _first_bad(arr)
            if bad is not None:
                row, col = bad
                no = int(rows[row])
                fields = _split(lines[no - first_no], self.fmt.delimiter, strip_comment=True)
                c = self.use[col]
                text = fields[c] if c < len(fields) else str(arr[row, col])
                raise _cell_error(f"line {no}", self.fmt.names[c], text, self.source)
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
        return all(not _is_content(lines[i]) for i in bad)

    def _slow(self, lines: list[str], first_no: int) -> tuple[np.ndarray, np.ndarray]:
        """Python parsing of a batch: exact diagnostics (line, column, text)."""
        fmt = self.fmt
        values: list[list[float]] = []
        rows: list[int] = []
        for i, line in enumerate(lines):
            if not _is_content(line):
                continue
            no = first_no + i
            fields = _split(line, fmt.delimiter, strip_comment=True)
            if len(fields) != fmt.n_cols:
                raise self._ragged(no, len(fields))
            row = []
            for c in self.use:
                text = fields[c]
                try:
                    value = float(text) if text else math.nan
                except ValueError:
                    raise _cell_error(f"line {no}", fmt.names[c], text, self.source) from None
                if not self.allow_missing and not math.isfinite(value):
                    raise _cell_error(f"line {no}", fmt.names[c], text, self.source)
                row.append(value)
            values.append(row)
            rows.append(no)
        arr = np.array(values, dtype=np.float64).reshape(len(values), len(self.use))
        return arr, np.asarray(rows, dtype=np.int64)

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


# ==================================================================== binary formats
def _import_pyarrow() -> Any:
    """``(pyarrow, pyarrow.parquet, pyarrow.compute)`` or None when pyarrow is missing."""
    try:
        import pyarrow as pa
        import pyarrow.compute as pc
        import pyarrow.parquet as pq
    except ImportError:
        return None
    return pa, pq, pc


def _import_pandas() -> Any:
    try:
        import pandas as pd
    except ImportError:
        return None
    return pd


def _missing_frames(what: str) -> ImportError:
    return ImportError(f"{what} needs pyarrow (or pandas with a Parquet engine): {_FRAMES_HINT}")


_Chunks = Callable[[int], Iterator[tuple[np.ndarray, int]]]


def _check_values(
    values: np.ndarray, offset: int, names: list[str], source: str, allow_missing: bool
) -> None:
    if allow_missing:
        return
    bad = _first_bad(values)
    if bad is not None:
        row, col = bad
        raise _cell_error(
            f"row {offset + row + 1}", names[col], repr(float(values[row, col])), source
        )


def _parquet_source(path: Path, columns: Any, allow_missing: bool) -> tuple[list[str], _Chunks]:
    source = _show(path)
    mods = _import_pyarrow()
    if mods is None:
        return _parquet_source_pandas(path, columns, allow_missing)
    pa, pq, pc = mods
    try:
        pf = pq.ParquetFile(path)
    except (pa.ArrowInvalid, OSError) as exc:
        raise DataError(
            f"{source} is not a readable Parquet file ({str(exc).splitlines()[0]}); "
            "check that the file is complete and really Parquet."
        ) from None
    all_names = [str(n) for n in pf.schema_arrow.names]
    sel = _resolve(all_names, columns, source)
    use = sorted(set(sel))
    use_names = [all_names[i] for i in use]
    if pf.metadata.num_rows == 0:
        raise DataError(f"data file {source} is empty (0 rows); it needs at least one row.")

    def convert(col: Any, name: str, offset: int, origin: dict[str, int]) -> np.ndarray:
        typ = col.type
        if col.null_count and not allow_missing:
            first = int(pc.index(pc.is_null(col), True).as_py())
            raise _cell_error(f"row {offset + first + 1}", name, "", source)
        if pa.types.is_timestamp(typ) or pa.types.is_duration(typ):
            ints = col.cast(pa.int64()).to_numpy(zero_copy_only=False)
            per_second = {"s": 1, "ms": 10**3, "us": 10**6, "ns": 10**9}[typ.unit]
            t0 = origin.setdefault(name, int(ints[0]))
            return (ints - t0) / per_second
        if (
            pa.types.is_integer(typ)
            or pa.types.is_floating(typ)
            or pa.types.is_boolean(typ)
            or pa.types.is_decimal(typ)
        ):
            return col.cast(pa.float64()).to_numpy(zero_copy_only=False)
        if pa.types.is_string(typ) or pa.types.is_large_string(typ):
            try:
                return col.cast(pa.float64()).to_numpy(zero_copy_only=False)
            except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
                for k, text in enumerate(col.to_pylist()):
                    if text is not None and not _is_number(text):
                        raise _cell_error(f"row {offset + k + 1}", name, text, source) from None
                raise
        raise DataError(
            f"{source} column {name!r} has type {typ}, which is not numeric; convert it to "
            "numbers (or leave it out of the selection)."
        )

    def chunks(chunk_rows: int) -> Iterator[tuple[np.ndarray, int]]:
        offset = 0
        origin: dict[str, int] = {}
        for batch in pf.iter_batches(batch_size=chunk_rows, columns=use_names):
            cols = [
                convert(batch.column(k), use_names[k], offset, origin)
                for k in range(len(use_names))
            ]
            values = np.column_stack(cols).astype(np.float64, copy=False)
            _check_values(values, offset, use_names, source, allow_missing)
            yield values, offset
            offset += values.shape[0]

    return [all_names[i] for i in sel], _reorder(chunks, use, sel)


def _parquet_source_pandas(
    path: Path, columns: Any, allow_missing: bool
) -> tuple[list[str], _Chunks]:
    source = _show(path)
    pd = _import_pandas()
    if pd is None:
        raise _missing_frames(f"reading Parquet ({source})")
    try:
        frame = pd.read_parquet(path)
    except ImportError:
        raise _missing_frames(f"reading Parquet ({source})") from None
    all_names = [str(c) for c in frame.columns]
    sel = _resolve(all_names, columns, source)
    use = sorted(set(sel))
    if len(frame) == 0:
        raise DataError(f"data file {source} is empty (0 rows); it needs at least one row.")
    cols = []
    for i in use:
        series = frame.iloc[:, i]
        name = all_names[i]
        if not allow_missing and series.isna().any():
            first = int(np.flatnonzero(series.isna().to_numpy())[0])
            raise _cell_error(f"row {first + 1}", name, "", source)
        if pd.api.types.is_datetime64_any_dtype(series) or pd.api.types.is_timedelta64_dtype(
            series
        ):
            cols.append((series - series.iloc[0]).dt.total_seconds().to_numpy())
            continue
        try:
            cols.append(series.to_numpy(dtype=np.float64, na_value=np.nan))
        except (TypeError, ValueError):
            for k, text in enumerate(series.tolist()):
                if not _is_number(str(text)):
                    raise _cell_error(f"row {k + 1}", name, str(text), source) from None
            raise
    values = np.column_stack(cols)
    use_names = [all_names[i] for i in use]
    _check_values(values, 0, use_names, source, allow_missing)

    def chunks(chunk_rows: int) -> Iterator[tuple[np.ndarray, int]]:
        for start in range(0, values.shape[0], chunk_rows):
            yield values[start : start + chunk_rows], start

    return [all_names[i] for i in sel], _reorder(chunks, use, sel)


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
            f"{_show(path)} is not a valid {ext} file (it does not start like one); write it "
            f"with {writer}, or rename it to match its real format."
        )


def _npy_source(path: Path, columns: Any, allow_missing: bool) -> tuple[list[str], _Chunks]:
    source = _show(path)
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
    if arr.dtype.names:  # structured array: one column per field
        all_names = [str(n) for n in arr.dtype.names]
        for name in all_names:
            sub = arr.dtype.fields[name][0]
            if sub.shape or not _numeric_dtype(sub):
                raise DataError(
                    f"{source} field {name!r} has dtype {sub}; only numeric scalar fields "
                    "can be read."
                )
        if arr.ndim != 1:
            raise DataError(f"{source} holds a {arr.ndim}-D structured array; expected 1-D.")

        def block(start: int, stop: int, idx: list[int]) -> np.ndarray:
            part = arr[start:stop]
            return np.column_stack([part[all_names[i]] for i in idx]).astype(np.float64)

    else:
        if not _numeric_dtype(arr.dtype):
            raise DataError(
                f"{source} holds dtype {arr.dtype}; only real numeric arrays can be read."
            )
        if arr.ndim not in (1, 2):
            raise DataError(
                f"{source} holds a {arr.ndim}-D array of shape {arr.shape}; expected 1-D (one "
                "column) or 2-D (n_rows, n_columns)."
            )
        view = arr[:, None] if arr.ndim == 1 else arr
        all_names = [f"col{i}" for i in range(view.shape[1])]

        def block(start: int, stop: int, idx: list[int]) -> np.ndarray:
            return np.asarray(view[start:stop, idx], dtype=np.float64)

    n_rows = int(arr.shape[0])
    return _array_source(source, all_names, n_rows, block, columns, allow_missing)


def _npz_source(path: Path, columns: Any, allow_missing: bool) -> tuple[list[str], _Chunks]:
    source = _show(path)
    _check_magic(path, (b"PK\x03\x04", b"PK\x05\x06"), ".npz", "numpy.savez")
    try:
        with np.load(path, allow_pickle=False) as archive:
            arrays = {key: archive[key] for key in archive.files}
    except ValueError as exc:
        raise DataError(
            f"{source} holds arrays that are not plain numeric ({exc}); save numeric arrays "
            "with numpy.savez."
        ) from None
    except (OSError, EOFError, zipfile.BadZipFile) as exc:
        raise DataError(f"{source} is not a valid .npz file ({exc}).") from None
    names_arr = None
    one_d: dict[str, np.ndarray] = {}
    two_d: dict[str, np.ndarray] = {}
    for key, value in arrays.items():
        if value.ndim == 0:
            continue
        if key in ("columns", "names") and value.ndim == 1 and value.dtype.kind in "US":
            names_arr = [str(v) for v in value]
            continue
        if not _numeric_dtype(value.dtype):
            raise DataError(
                f"{source} array {key!r} has dtype {value.dtype}; only real numeric arrays "
                "can be read."
            )
        if value.ndim == 1:
            one_d[key] = value
        elif value.ndim == 2:
            two_d[key] = value
        else:
            raise DataError(
                f"{source} array {key!r} is {value.ndim}-D (shape {value.shape}); expected "
                "1-D columns or one 2-D table."
            )
    if two_d and (one_d or len(two_d) > 1):
        raise DataError(
            f"{source} mixes arrays {list(two_d) + list(one_d)}; a .npz table is either one "
            "2-D array or 1-D arrays of equal length (one per column)."
        )
    if two_d:
        table = next(iter(two_d.values()))
        n_cols = table.shape[1]
        all_names = (
            names_arr
            if names_arr is not None and len(names_arr) == n_cols
            else [f"col{i}" for i in range(n_cols)]
        )
    elif one_d:
        lengths = {key: value.shape[0] for key, value in one_d.items()}
        first = next(iter(lengths))
        for key, n in lengths.items():
            if n != lengths[first]:
                raise DataError(
                    f"{source} columns differ in length: {key!r} has {n} rows but {first!r} "
                    f"has {lengths[first]}; save columns of equal length."
                )
        all_names = list(one_d)
        table = np.column_stack([one_d[k] for k in all_names])
    else:
        raise DataError(f"data file {source} is empty (no arrays); it needs at least one row.")

    def block(start: int, stop: int, idx: list[int]) -> np.ndarray:
        return np.asarray(table[start:stop, idx], dtype=np.float64)

    return _array_source(source, all_names, int(table.shape[0]), block, columns, allow_missing)


def _array_source(
    source: str,
    all_names: list[str],
    n_rows: int,
    block: Callable[[int, int, list[int]], np.ndarray],
    columns: Any,
    allow_missing: bool,
) -> tuple[list[str], _Chunks]:
    sel = _resolve(all_names, columns, source)
    if n_rows == 0:
        raise DataError(f"data file {source} is empty (0 rows); it needs at least one row.")

    def chunks(chunk_rows: int) -> Iterator[tuple[np.ndarray, int]]:
        names = [all_names[i] for i in sel]
        for start in range(0, n_rows, chunk_rows):
            values = block(start, min(start + chunk_rows, n_rows), sel)
            _check_values(values, start, names, source, allow_missing)
            yield values, start

    return [all_names[i] for i in sel], chunks


def _reorder(chunks: _Chunks, use: list[int], sel: list[int]) -> _Chunks:
    """Map chunks of the sorted unique columns ``use`` to the requested order ``sel``."""
    if use == sel:
        return chunks
    take = [use.index(i) for i in sel]

    def reordered(chunk_rows: int) -> Iterator[tuple[np.ndarray, int]]:
        for values, where in chunks(chunk_rows):
            yield values[:, take], where

    return reordered


# ======================================================================== public API
def _check_chunk_rows(chunk_rows: Any) -> int:
    if isinstance(chunk_rows, bool) or not isinstance(chunk_rows, (int, np.integer)):
        raise DataError(f"chunk_rows must be an int in the range [1, inf); got {chunk_rows!r}.")
    if chunk_rows < 1:
        raise DataError(f"chunk_rows must be an int in the range [1, inf); got {chunk_rows}.")
    return int(chunk_rows)


def _open_source(
    path: PathLike,
    columns: Any,
    delimiter: str | None,
    header: bool | None,
    allow_missing: bool,
) -> tuple[Path, list[str], Callable[[int], Iterator[tuple[np.ndarray, Any]]], str]:
    """Names of the selected columns and a chunk generator ``chunks(chunk_rows)``.

    The generator yields ``(values, where)``: ``where`` is an int64 array of 1-based
    line numbers (text files, ``unit == "line"``) or the 0-based offset of the first row.
    """
    p = _check_file(path)
    kind = _kind(p)
    if kind == "text":
        fmt = _sniff(p, delimiter, header)
        sel = _resolve(fmt.names, columns, _show(p))
        use = sorted(set(sel))
        reader = _TextReader(p, fmt, use, allow_missing)
        return p, [fmt.names[i] for i in sel], _reorder(reader.batches, use, sel), "line"
    if kind == "parquet":
        names, chunks = _parquet_source(p, columns, allow_missing)
    elif kind == "npy":
        names, chunks = _npy_source(p, columns, allow_missing)
    else:
        names, chunks = _npz_source(p, columns, allow_missing)
    return p, names, chunks, "row"


def read_table(
    path: PathLike,
    *,
    columns: Sequence[ColumnKey] | ColumnKey | None = None,
    delimiter: str | None = None,
    header: bool | None = None,
    allow_missing: bool = False,
) -> Table:
    """Read a whole data file into a :class:`Table`.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.csv``/``.tsv``/``.tab``/``.txt``/``.dat`` text file (optionally ``.gz``), a
        ``.parquet``/``.pq``, ``.npy`` or ``.npz`` file.
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
    ImportError
        Parquet without pyarrow/pandas (``pip install 'clpc[frames]'``).
    """
    p, names, chunks, unit = _open_source(path, columns, delimiter, header, allow_missing)
    parts: list[np.ndarray] = []
    wheres: list[np.ndarray] = []
    for values, where in chunks(_READ_CHUNK):
        parts.append(values)
        if unit == "line":
            wheres.append(where)
    if not parts:
        raise DataError(
            f"data file {_show(p)} has a header but no data rows; it needs at least one row."
        )
    data = parts[0] if len(parts) == 1 else np.concatenate(parts)
    lines = None
    if unit == "line":
        lines = wheres[0] if len(wheres) == 1 else np.concatenate(wheres)
    return _table(names, np.ascontiguousarray(data), str(os.fspath(p)), lines)


def iter_table_chunks(
    path: PathLike,
    chunk_rows: int = 100_000,
    *,
    columns: Sequence[ColumnKey] | ColumnKey | None = None,
    delimiter: str | None = None,
    header: bool | None = None,
    allow_missing: bool = False,
) -> Iterator[tuple[list[str], np.ndarray]]:
    """Read a data file piece by piece, without holding it all in memory.

    The file is opened and its columns are resolved at the call (so a missing file or an
    unknown column raises at once); the values are parsed as the iterator advances.

    Parameters
    ----------
    path : str or os.PathLike
        As for :func:`read_table`.
    chunk_rows : int
        Rows per chunk (>= 1). Parquet and ``.npy``/``.npz`` chunks have exactly
        ``chunk_rows`` rows (the last one fewer); a text chunk holds the data rows among
        ``chunk_rows`` consecutive lines (fewer when blank or comment lines occur).
        Text, Parquet and ``.npy`` files are read piece by piece (``.npy`` memory-mapped);
        a ``.npz`` file (a zip archive) and the pandas fallback for Parquet are loaded
        whole and then sliced.
    columns, delimiter, header, allow_missing
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
    p, names, chunks, _ = _open_source(path, columns, delimiter, header, allow_missing)

    def generate() -> Iterator[tuple[list[str], np.ndarray]]:
        empty = True
        for values, _where in chunks(chunk_rows):
            empty = False
            yield names, values
        if empty:
            raise DataError(
                f"data file {_show(p)} has a header but no data rows; it needs at least one row."
            )

    return generate()


def _keys(value: Any, label: str) -> list[ColumnKey]:
    if isinstance(value, (str, int, np.integer)):
        return [value]
    if value is None:
        raise DataError(f"{label} is missing: name at least one column.")
    keys = list(value)
    if not keys:
        raise DataError(f"{label} is empty: name at least one column.")
    return keys


def load_iodata(
    path: PathLike,
    inputs: Sequence[ColumnKey] | ColumnKey,
    outputs: Sequence[ColumnKey] | ColumnKey,
    *,
    dt: float | None = None,
    time_column: ColumnKey | None = None,
    delimiter: str | None = None,
    header: bool | None = None,
    time_rtol: float = 1e-6,
) -> IOData:
    """Read an input/output record from a data file.

    Parameters
    ----------
    path : str or os.PathLike
        A data file (see :func:`read_table`).
    inputs, outputs : str, int or sequence of them
        Input and output columns, by name or 0-based index; the names become the
        record's channel names.
    dt : float, optional
        Sample time [s]. When ``time_column`` is also given, the time column must agree
        with it (within ``time_rtol``).
    time_column : str or int, optional
        A column of sample times [s]; ``dt`` is its mean step, and the steps must all be
        equal within ``time_rtol`` (relative). Without ``dt`` and ``time_column`` the
        sample time is 1 (per sample).
    delimiter, header
        Text files only, as for :func:`read_table`.
    time_rtol : float
        Relative tolerance of the uniform-sampling check (default 1e-6).

    Returns
    -------
    IOData
        ``u`` of shape (n_samples, n_inputs), ``y`` of shape (n_samples, n_outputs).

    Raises
    ------
    DataError
        Any problem of :func:`read_table`; a time column that is not increasing or not
        uniformly sampled (the message names the first offending line/row); a ``dt``
        that disagrees with the time column.
    """
    in_keys = _keys(inputs, "inputs")
    out_keys = _keys(outputs, "outputs")
    keys = in_keys + out_keys + ([] if time_column is None else [time_column])
    table = read_table(path, columns=keys, delimiter=delimiter, header=header)
    n_in, n_out = len(in_keys), len(out_keys)
    u = table.data[:, :n_in]
    y = table.data[:, n_in : n_in + n_out]
    if time_column is not None:
        step = _time_step(table, n_in + n_out, float(time_rtol))
        if dt is not None:
            given = float(dt)
            if not (math.isfinite(given) and given > 0):
                raise DataError(
                    f"dt (sample time) must be a positive number of seconds; got {dt!r}."
                )
            if abs(step - given) > time_rtol * given:
                raise DataError(
                    f"dt={given:g} s disagrees with time column {table.names[-1]!r} of "
                    f"{_show(table.source)}, whose step is {step:.12g} s; pass only one of "
                    "dt and time_column, or fix the time column."
                )
        else:
            dt = step
    return IOData(
        u,
        y,
        1.0 if dt is None else dt,
        input_names=table.names[:n_in],
        output_names=table.names[n_in : n_in + n_out],
    )


def _time_step(table: Table, col: int, rtol: float) -> float:
    t = table.data[:, col]
    name = table.names[col]
    source = _show(table.source)
    if t.size < 2:
        raise DataError(
            f"time column {name!r} of {source} has {t.size} sample(s); at least 2 are needed "
            "to find the sample time (or pass dt=)."
        )
    steps = np.diff(t)
    nonpos = np.flatnonzero(steps <= 0)
    if nonpos.size:
        k = int(nonpos[0]) + 1
        raise DataError(
            f"time column {name!r} of {source} is not increasing at {table.row_label(k)} "
            f"({t[k - 1]:.12g} -> {t[k]:.12g}); sort the record by time and remove repeated "
            "samples."
        )
    typical = float(np.median(steps))
    off = np.flatnonzero(np.abs(steps - typical) > rtol * typical)
    if off.size:
        k = int(off[0]) + 1
        rel = abs(steps[k - 1] - typical) / typical
        raise DataError(
            f"time column {name!r} of {source} is not uniformly sampled: the step from "
            f"{table.row_label(k - 1)} to {table.row_label(k)} is {steps[k - 1]:.12g} s but "
            f"the typical (median) step is {typical:.12g} s (relative deviation {rel:.3g} > "
            f"time_rtol={rtol:g}); resample the record onto a uniform grid (e.g. "
            "numpy.interp), or loosen time_rtol if the times are rounded."
        )
    step = float((t[-1] - t[0]) / (t.size - 1))
    rounded = float(f"{step:.12g}")  # 0.009999999999999998 -> 0.01
    return rounded if abs(rounded - step) <= 1e-9 * step else float(step)


# =========================================================================== writing
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
        stored, they read back as ``col0..``); ``.npz`` (one 1-D array per column).
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
    ImportError
        Parquet without pyarrow/pandas (``pip install 'clpc[frames]'``).
    """
    p = Path(os.fspath(path))
    kind = _kind(p)
    arr = np.asarray(array, dtype=np.float64)
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.ndim != 2:
        raise DataError(f"write_table needs a 1-D or 2-D array; got shape {arr.shape}.")
    names = [names] if isinstance(names, str) else [str(n) for n in names]
    if len(names) != arr.shape[1]:
        raise DataError(
            f"write_table needs one name per column: {arr.shape[1]} column(s), {len(names)} "
            f"name(s) {names}."
        )
    if kind == "text":
        if any("\n" in n or "\r" in n for n in names):
            raise DataError(f"column names of a text file cannot contain line breaks: {names}.")
        _write_text(p, names, arr, delimiter)
    elif kind == "parquet":
        _write_parquet(p, names, arr)
    elif kind == "npy":
        np.save(p, arr, allow_pickle=False)
    else:
        if len(set(names)) != len(names):
            raise DataError(f"a .npz file needs unique column names; got {names}.")
        with zipfile.ZipFile(p, "w", compression=zipfile.ZIP_STORED, allowZip64=True) as zf:
            for k, name in enumerate(names):
                with zf.open(name + ".npy", "w", force_zip64=True) as fh:
                    np.lib.format.write_array(fh, np.ascontiguousarray(arr[:, k]))


def _write_text(p: Path, names: list[str], arr: np.ndarray, delimiter: str | None) -> None:
    lower = p.name.lower().removesuffix(".gz")
    if delimiter is None:
        delimiter = "\t" if lower.endswith((".tsv", ".tab")) else ","
    if len(delimiter) != 1 or delimiter in '"#\r\n.-+0123456789eE':
        raise DataError(f"delimiter must be one separator character; got {delimiter!r}.")
    header = delimiter.join(_quote(n, delimiter) for n in names)
    row_fmt = delimiter.join(["%r"] * arr.shape[1])
    opener: Callable[..., IO[str]] = gzip.open if p.name.lower().endswith(".gz") else open
    with opener(p, "wt", encoding="utf-8", newline="") as f:
        f.write(header + "\n")
        for start in range(0, arr.shape[0], 100_000):
            rows = arr[start : start + 100_000].tolist()
            buf = io.StringIO()
            buf.write("\n".join([row_fmt % tuple(r) for r in rows]))
            buf.write("\n")
            f.write(buf.getvalue())


def _write_parquet(p: Path, names: list[str], arr: np.ndarray) -> None:
    mods = _import_pyarrow()
    if mods is not None:
        pa, pq, _ = mods
        table = pa.Table.from_arrays([pa.array(arr[:, k]) for k in range(arr.shape[1])], names)
        pq.write_table(table, p)
        return
    pd = _import_pandas()
    if pd is None:
        raise _missing_frames(f"writing Parquet ({_show(p)})")
    try:
        pd.DataFrame(arr, columns=names).to_parquet(p)
    except ImportError:
        raise _missing_frames(f"writing Parquet ({_show(p)})") from None
