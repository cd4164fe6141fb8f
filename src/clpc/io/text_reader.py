"""Reading the numbers of a text data file (CSV/TSV/whitespace) with ``pyarrow.csv``.

pyarrow parses the cells (delimiter, quotes, float64 conversion), block by block. Around it,
this module keeps each row's file line and one number syntax for every reader:

- :class:`~clpc.io.text_lines.DataLines` hands pyarrow the data lines without blank and
  comment lines, and gives every row its line in the file.
- Columns are read as float64. From the first block where pyarrow refuses a cell, or that
  holds a NaN or inf, the rest of the file is read as text and every cell judged by the
  number syntax of :func:`clpc.io.errors.parse_number`, so that a message names the line,
  the column and the text of the first bad cell. An empty cell is refused unless
  ``allow_missing``; a row with another number of fields than the header is refused.
"""

from __future__ import annotations

import stat
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from clpc.data import DataError
from clpc.data.samples import NUMBER_TEXT
from clpc.io.errors import cell_error, show
from clpc.io.table import Chunks, Columns, reorder_columns, resolve_columns
from clpc.io.text_format import READ_ERRORS, TextFormat, read_error, sniff
from clpc.io.text_lines import BLOCK_BYTES, DataLines, copy_stream

__all__ = ["rechunk", "text_source"]

#: the number syntax of :func:`clpc.io.errors.parse_number`, for pyarrow's RE2
_NUMBER_RE2 = f"^{NUMBER_TEXT.pattern}$"


class _Reader:
    """The float64 values of the selected columns of one text file, with their lines."""

    def __init__(
        self, path: Path, source: str, fmt: TextFormat, use: list[int], allow_missing: bool
    ):
        self.path, self.source, self.fmt = path, source, fmt
        self.use = use
        self.allow_missing = allow_missing
        self.ragged: dict[bytes, int] = {}  # text -> fields of the ragged rows pyarrow met
        self.whole = False  # the caller holds every value at once (read_table)

    def _open(self, as_text: bool) -> tuple[DataLines, Any]:
        import pyarrow as pa
        from pyarrow import csv

        names = [f"c{i}" for i in range(self.fmt.n_cols)]
        wanted = [names[i] for i in self.use]
        lines = DataLines(self.path, self.fmt)
        delimiter = "\t" if self.fmt.delimiter is None else self.fmt.delimiter

        def ragged(row: Any) -> str:
            self.ragged[str(row.text).strip().encode()] = int(row.actual_columns)
            return "error"

        if not lines.peek():
            return lines, iter(())  # no data lines (pyarrow: "Empty CSV file")
        options = {
            "read_options": csv.ReadOptions(
                column_names=names, block_size=max(BLOCK_BYTES, lines.longest + 2)
            ),
            "parse_options": csv.ParseOptions(
                delimiter=delimiter, quote_char='"', invalid_row_handler=ragged
            ),
            "convert_options": csv.ConvertOptions(
                include_columns=wanted,
                column_types=dict.fromkeys(wanted, pa.string() if as_text else pa.float64()),
                null_values=[""],
                strings_can_be_null=True,
            ),
        }
        gz = self.path.name.lower().endswith(".gz")  # its size is unknown: block by block
        if self.whole and not as_text and not gz:  # all at once: parsed in parallel
            return lines, iter(csv.read_csv(lines, **options).to_batches())
        return lines, csv.open_csv(lines, **options)

    def batches(self) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """Values ``(n, len(use))`` and the 1-based file line of each row, block by block."""
        import pyarrow as pa

        done = 0
        try:
            try:
                lines, reader = self._open(as_text=False)
                with lines:
                    for batch in reader:
                        values, missing = _float_batch(batch)
                        if not np.isfinite(values[~missing]).all():
                            break  # a NaN or inf: its text decides
                        where = lines.lines_of(done, batch.num_rows, self.fmt.data_line)
                        if missing.any() and not self.allow_missing:
                            row, col = np.argwhere(missing)[0]
                            raise self._cell(where[row], col, "")
                        yield values, where
                        done += batch.num_rows
                    else:
                        return
            except pa.ArrowInvalid:
                if self.ragged:
                    raise self._ragged_error() from None
            yield from self._text_batches(done)
        except READ_ERRORS as exc:
            raise read_error(self.path, exc) from None

    def _text_batches(self, start: int) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        """As :meth:`batches` from data row ``start`` on, every cell judged by its text."""
        import pyarrow as pa

        done = 0
        lines, reader = self._open(as_text=True)
        with lines:
            try:
                for batch in reader:
                    n = batch.num_rows
                    if done + n > start:
                        skip = max(start - done, 0)
                        where = lines.lines_of(done + skip, n - skip, self.fmt.data_line)
                        yield self._judge(batch.slice(skip), where), where
                    done += n
            except pa.ArrowInvalid as exc:
                if self.ragged:
                    raise self._ragged_error() from None
                if "UTF8" in str(exc):
                    raise DataError(
                        f"{self.source} is not UTF-8 text (a cell holds other bytes); re-save "
                        "it as UTF-8 CSV, or check that it is really a text file."
                    ) from None
                raise DataError(f"{self.source} cannot be read as a table: {exc}") from None

    def _judge(self, batch: Any, where: np.ndarray) -> np.ndarray:
        """float64 values of a text batch; the first bad cell (row by row) raises."""
        import pyarrow as pa
        import pyarrow.compute as pc

        n, k = batch.num_rows, batch.num_columns
        values = np.empty((n, k))
        bad = np.zeros((n, k), dtype=bool)
        for j in range(k):
            text = pc.utf8_trim_whitespace(batch.column(j))
            empty = pc.fill_null(pc.equal(text, ""), True)
            number = pc.fill_null(
                pc.match_substring_regex(text, _NUMBER_RE2, ignore_case=True), False
            )
            parsed = pc.cast(pc.if_else(number, text, pa.scalar(None, pa.string())), pa.float64())
            col, _ = _float64(pc.fill_null(parsed, np.nan))
            values[:, j] = col
            ok = _float64(pc.cast(pc.or_(empty, number), pa.float64()))[0] > 0
            missing = _float64(pc.cast(empty, pa.float64()))[0] > 0
            bad[:, j] = ~ok if self.allow_missing else ~ok | missing | ~np.isfinite(col)
        if bad.any():
            row, col = np.argwhere(bad)[0]
            raise self._cell(where[row], col, batch.column(int(col))[int(row)].as_py() or "")
        return values

    def _cell(self, line: int, col: int, text: str) -> DataError:
        return cell_error(f"line {int(line)}", self.fmt.names[self.use[col]], text, self.source)

    def _ragged_error(self) -> DataError:
        fmt = self.fmt
        line, got = self._first_ragged()
        if fmt.header_line is not None:
            ref = f"the header (line {fmt.header_line})"
        else:
            ref = f"the first data row (line {fmt.data_line})"
        return DataError(
            f"{self.source} line {line} has {got} field(s) but {ref} has "
            f"{fmt.n_cols} (delimiter {fmt.describe_delimiter()}); fix or remove that row, or "
            "pass delimiter= if the separator was guessed wrongly."
        )

    def _first_ragged(self) -> tuple[int | str, int]:
        """Line and field count of the first ragged row (pyarrow's threads give its text)."""
        row = 0
        with DataLines(self.path, self.fmt) as lines:
            for block in lines.blocks():
                for line in block.split(b"\n")[:-1]:
                    got = self.ragged.get(line.strip())
                    if got is not None:
                        return int(lines.lines_of(row, 1, self.fmt.data_line)[0]), got
                    row += 1
        return "?", next(iter(self.ragged.values()))


def _float_batch(batch: Any) -> tuple[np.ndarray, np.ndarray]:
    """float64 values ``(n, k)`` of a batch and where a cell is empty (a null)."""
    n, k = batch.num_rows, batch.num_columns
    values = np.empty((n, k))
    missing = np.zeros((n, k), dtype=bool)
    for j in range(k):
        col, null = _float64(batch.column(j))
        values[:, j] = col
        if null is not None:
            values[null, j] = np.nan
            missing[:, j] = null
    return values, missing


def _float64(arr: Any) -> tuple[np.ndarray, np.ndarray | None]:
    """A float64 pyarrow Array as numpy (a read-only view) and its null mask (None: no nulls).

    Read from the Array's buffers: pyarrow's ``to_numpy`` imports pandas (about 0.2 s). The
    values under a null are undefined.
    """
    if hasattr(arr, "combine_chunks"):
        arr = arr.combine_chunks()
    n, off = len(arr), arr.offset
    validity, data = arr.buffers()[:2]
    if n == 0 or data is None:
        return np.zeros(n), None
    values = np.frombuffer(data, dtype=np.float64, count=n, offset=8 * off)
    if not arr.null_count or validity is None:
        return values, None
    bits = np.unpackbits(np.frombuffer(validity, dtype=np.uint8), bitorder="little")
    return values, ~bits[off : off + n].astype(bool)


def text_source(
    path: Path,
    columns: Columns,
    delimiter: str | None,
    header: bool | None,
    allow_missing: bool,
    skip_rows: int = 0,
    whole: bool = False,
) -> tuple[list[str], Chunks]:
    """Names of the selected columns of a text file and a chunk generator over them.

    Parameters
    ----------
    path : Path
        An existing text data file.
    columns, delimiter, header, allow_missing, skip_rows
        As for :func:`clpc.io.read_table`.
    whole : bool
        Every value will be held at once (:func:`clpc.io.read_table`): pyarrow parses the
        whole file in parallel instead of block after block.

    Returns
    -------
    names : list of str
        The selected column names, in the order asked for.
    chunks : Chunks
        ``chunks(chunk_rows)`` yields values and the 1-based line number of each row.
    """
    spool, given = None, path
    if not stat.S_ISREG(path.stat().st_mode):
        spool, path = copy_stream(path)
    fmt = sniff(path, delimiter, header, skip_rows)
    sel = resolve_columns(fmt.names, columns, show(given))
    use = sorted(set(sel))
    reader = _Reader(path, show(given), fmt, use, allow_missing)
    reader.whole = whole

    def batches(chunk_rows: int) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        # read_table joins pyarrow's blocks as they come; iter_table_chunks re-cuts them
        blocks = reader.batches() if whole else rechunk(reader.batches(), chunk_rows)
        if spool is None:
            yield from blocks
            return
        with spool:  # removed once read
            yield from blocks

    return [fmt.names[i] for i in sel], reorder_columns(batches, use, sel)


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
