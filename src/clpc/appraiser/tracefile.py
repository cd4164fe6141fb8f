"""Long CLPC runs in bounded memory: traces written part by part, and a thinned summary.

A record of 1e7 samples gives about 8e5 cluster updates; keeping every row of their trace in
memory costs about 300 bytes each. :class:`TraceWriter` appends the rows of each part to the
trace file as they arrive (the columns of :func:`clpc.appraiser.trace_table.trace_columns`),
and :class:`ThinnedTrace` keeps at most ``2 * max_updates`` of them for figures and summaries
(every update until the cap, then every 2nd, 4th, ... update).
"""

from __future__ import annotations

import contextlib
import csv
import io
import os
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from clpc.appraiser.thinned import ThinnedTrace
from clpc.appraiser.trace import Trace
from clpc.appraiser.trace_table import is_integer, trace_column_list, trace_columns
from clpc.core.atomic import OutputError, atomic_path
from clpc.data import DataError

__all__ = ["ThinnedTrace", "TraceWriter", "trace_column_list", "trace_columns"]


def _arrow() -> Any:
    """Pyarrow (with its csv module), or None when it is missing or ``CLPC_FAST_IO=0``."""
    if os.environ.get("CLPC_FAST_IO", "1") == "0":
        return None
    try:
        import pyarrow as pa
        import pyarrow.csv
    except ImportError:
        return None
    return pa


def _csv_header(names: list[str]) -> str:
    """The header line of a csv trace: names quoted as RFC 4180 says where they need it.

    A channel name with a comma, quote or line break (``"out,1:a0"``) is quoted, so that
    any csv reader finds one column per name.
    """
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerow(names)
    return buffer.getvalue()


class TraceWriter:
    """Append trace parts to a CSV or Parquet file (``trace_columns`` layout).

    Counts and flags are written as integers, other numbers in their shortest exact form
    (the readers return exactly the values of :func:`trace_columns`). CSV rows are written
    by pyarrow's CSV writer when pyarrow is installed (a C++ loop), else by one ``%``
    format per row.

    The rows go to a temporary file beside ``path`` that is renamed to ``path`` when the
    writer is closed without an error (:func:`clpc.core.atomic.atomic_path`): a run that
    fails or is killed leaves no partial trace. A write error (a full disk) is raised as
    :class:`clpc.core.atomic.OutputError` naming ``path``.

    Parameters
    ----------
    path : str or Path
        ``.csv`` or ``.parquet`` (needs pyarrow).
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.suffix = self.path.suffix.lower()
        if self.suffix not in (".csv", ".parquet"):
            raise DataError(f"trace files are .csv or .parquet; got {self.path.name!r}.")
        self._fh: Any = None
        self._writer: Any = None
        self._names: list[str] | None = None
        self._row_format = ""
        self._pa: Any = None
        self._csv_options: Any = None
        self._pool: ThreadPoolExecutor | None = None
        self._pending: Future[Any] | None = None
        self._target: contextlib.AbstractContextManager[Path] | None = None
        self._failed: OutputError | None = None
        self.rows = 0

    def write(self, part: Trace) -> None:
        """Append the rows of ``part`` (a trace of consecutive updates)."""
        if not len(part):
            return
        if self._failed is not None:
            raise self._failed
        try:
            self._write(part)
        except OSError as exc:
            raise self._fail(exc) from exc
        self.rows += len(part)

    def _fail(self, exc: OSError) -> OutputError:
        """Discard the file after a write error; later writes raise the same error."""
        self.discard()
        self._failed = exc if isinstance(exc, OutputError) else OutputError(self.path, exc)
        return self._failed

    def _write(self, part: Trace) -> None:
        names, cols = trace_column_list(part)
        if self._names is None:
            self._names = names
            self._open(names, cols)
        if self.suffix == ".parquet":
            pa = self._pa
            self._writer.write_table(_arrow_table(pa, names, cols))
        elif self._pa is not None:
            pa = self._pa
            table = _arrow_table(pa, [f"c{i}" for i in range(len(cols))], cols)
            self._in_background(pa.csv.write_csv, table, self._fh, self._csv_options)
        else:
            rows = np.column_stack([c.astype(object) for c in cols]).tolist()
            fmt = self._row_format
            self._fh.write("".join([fmt % tuple(r) for r in rows]))

    def _open(self, names: list[str], cols: list[np.ndarray]) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._target = atomic_path(self.path)
        tmp = self._target.__enter__()
        header = _csv_header(names).encode()
        if self.suffix == ".csv":
            self._pa = _arrow()
            if self._pa is not None:
                self._fh = tmp.open("wb")
                self._fh.write(header)
                self._csv_options = self._pa.csv.WriteOptions(include_header=False)
            else:
                self._fh = tmp.open("w", encoding="utf-8")
                self._fh.write(header.decode())
                formats = ["%d" if is_integer(c) else "%r" for c in cols]
                self._row_format = ",".join(formats) + "\n"
            return
        import pyarrow as pa  # a dependency of clpc, imported when a Parquet trace is written
        import pyarrow.parquet as pq

        self._pa = pa
        schema = pa.schema(
            [
                (n, pa.int64() if is_integer(c) else pa.float64())
                for n, c in zip(names, cols, strict=True)
            ]
        )
        # no dictionary encoding: the trace's numbers are nearly all distinct, and the
        # dictionary pass cost about four fifths of the writing time (distributed/part_file.py)
        self._writer = pq.ParquetWriter(tmp, schema, use_dictionary=False)

    def _in_background(self, fn: Callable[..., Any], *args: Any) -> None:
        """Run ``fn(*args)`` in a thread, after the writes before it.

        pyarrow's CSV writer releases the GIL: the rows are formatted while the appraiser
        computes the next chunk. The error of an earlier write is raised here (once; that
        part is not retried and this one is not written).
        """
        self.drain()
        if self._pool is None:
            self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="clpc-trace")
        self._pending = self._pool.submit(fn, *args)

    def drain(self) -> None:
        """Wait until every part handed over so far is written (its error is raised once)."""
        pending, self._pending = self._pending, None
        if pending is not None:
            pending.result()

    def close(self) -> None:
        """Finish the writes, close the file and rename it to :attr:`path`.

        Raises
        ------
        OutputError
            A write failed (the partial file is removed; ``path`` is left as it was).
        """
        try:
            try:
                self.drain()
            finally:
                self._stop_pool()
                self._close_files()
        except OSError as exc:
            raise self._fail(exc) from exc
        target, self._target = self._target, None
        if target is not None:
            target.__exit__(None, None, None)

    def discard(self) -> None:
        """Stop writing and remove the partial file (``path`` is left as it was)."""
        with contextlib.suppress(Exception):
            self._stop_pool()
        with contextlib.suppress(Exception):
            self._close_files()
        target, self._target = self._target, None
        if target is not None:
            with contextlib.suppress(Exception):
                target.__exit__(_Discarded, _Discarded(), None)

    def _stop_pool(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True)
            self._pool = None

    def _close_files(self) -> None:
        if self._fh is not None:
            self._fh.close()
            self._fh = None
        if self._writer is not None:
            self._writer.close()
            self._writer = None

    def __enter__(self) -> TraceWriter:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, *exc: object) -> None:
        if exc_type is None:
            self.close()
        else:
            self.discard()


class _Discarded(Exception):
    """Thrown into the temporary file's context to remove it."""


def _arrow_table(pa: Any, names: list[str], cols: list[np.ndarray]) -> Any:
    """int64 / float64 columns as a pyarrow Table, built on their buffers.

    The same table as ``pa.table(dict(zip(names, cols)))`` (NaN stays a NaN value, not a
    null), without pyarrow's pandas check: ``pa.array`` imports pandas (~0.2 s) when it is
    installed.
    """
    arrays = []
    for c in cols:
        c = np.ascontiguousarray(c)
        kind = pa.int64() if c.dtype == np.int64 else pa.float64()
        arrays.append(pa.Array.from_buffers(kind, c.size, [None, pa.py_buffer(c)]))
    return pa.Table.from_arrays(arrays, names=names)
