"""The appraiser over a record read in chunks: a trace file, figures and a report."""

from __future__ import annotations

import dataclasses
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np

from clpc.appraiser import CLPC
from clpc.appraiser.decimation import Decimator, decimation_factor
from clpc.appraiser.scanned import ScannedTrace
from clpc.appraiser.tracefile import ThinnedTrace, TraceWriter
from clpc.core.checks import check_choice, check_int
from clpc.core.output_folder import OutputFolder
from clpc.data import DataError
from clpc.data.chunked_time import ChunkedTimeBase
from clpc.io import iter_table_chunks, save_model
from clpc.io.roles import check_column_roles
from clpc.io.text_format import sniff
from clpc.workflows.common import AppraiserSettings, RecordSpec, SettingsError
from clpc.workflows.save_check import save_refusal
from clpc.workflows.track_report import REPORT_SAMPLES, Appraised, TrackResult, write_report

__all__ = [
    "REPORT_SAMPLES",
    "Appraised",
    "Chunk",
    "ChunkFilter",
    "TrackResult",
    "TrackSettings",
    "count_data_lines",
    "track_file",
    "write_report",
]

#: column names and values of a block of rows (see :func:`clpc.io.iter_table_chunks`)
Chunk = tuple[list[str], np.ndarray]
#: wraps the chunks as they are read, e.g. to show progress
ChunkFilter = Callable[[Iterator[Chunk]], Iterator[Chunk]]

TraceFormat = Literal["csv", "parquet"]
_TEXT_SUFFIXES = (".csv", ".tsv", ".tab", ".txt", ".dat")


@dataclass(frozen=True)
class TrackSettings:
    """What :func:`track_file` runs, and where it writes.

    Parameters
    ----------
    record : RecordSpec
        The record and its input/output (and time) columns.
    out_dir : str
        Folder for trace, figures and report (created).
    appraiser : AppraiserSettings
        The appraiser's settings.
    fmt : {"csv", "parquet"}
        Format of the trace file ``OUT/trace.FMT``.
    chunk_rows : int
        Rows read from the file at a time.
    save : str, optional
        Save the steady-state model to this JSON file.
    figure_updates : int
        The figures show at most about twice this many updates (evenly thinned); counts,
        convergence and the steady-state model always come from every update.
    """

    record: RecordSpec
    out_dir: str
    appraiser: AppraiserSettings = field(default_factory=AppraiserSettings)
    fmt: TraceFormat = "csv"
    chunk_rows: int = 100_000
    save: str | None = None
    figure_updates: int = 20_000

    def __post_init__(self) -> None:
        check_choice(self.fmt, "fmt", ("csv", "parquet"))
        check_int(self.chunk_rows, "chunk_rows", 1)
        check_int(self.figure_updates, "figure_updates", 1)
        record = self.record
        if self.appraiser.decimate_to is not None and record.dt is None and not record.time_col:
            raise SettingsError(
                "--decimate-to is the rate the appraiser works at (the data are decimated to "
                "it); give the data's own sample time with --dt (or --time) as well."
            )


def count_data_lines(path: str, skip_rows: int = 0) -> int | None:
    """Lines after the header (and a units row) of an uncompressed text file, else ``None``.

    Parameters
    ----------
    path : str
        A data file; only csv, tsv, tab, txt and dat files are counted.
    skip_rows : int
        Lines passed over at the top (see :func:`clpc.io.read_table`).

    Returns
    -------
    int or None
        At least 1 for a text file; ``None`` for other formats.
    """
    p = Path(path)
    if p.suffix.lower() not in _TEXT_SUFFIXES:
        return None
    lines = 0
    with p.open("rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            lines += block.count(b"\n")
    try:
        before = sniff(p, None, None, skip_rows).data_line - 1  # header, units, skipped
    except DataError:
        before = 1 + skip_rows
    return max(lines - before, 1)


class _Tail:
    """The last :data:`REPORT_SAMPLES` rows at the appraiser's rate (bounded memory)."""

    def __init__(self, factor: int) -> None:
        self.decimator = Decimator(factor)
        self.rows = np.empty((0, 0))

    def feed(self, values: np.ndarray) -> None:
        kept = self.decimator(values)
        both = kept if self.rows.size == 0 else np.concatenate([self.rows, kept])
        self.rows = both[-REPORT_SAMPLES:]


@dataclass
class _Run:
    """The state of one pass over the record."""

    appraiser: CLPC
    kept: ThinnedTrace
    n_raw: int
    tail: _Tail
    data_dt: float
    whole: ScannedTrace = field(default_factory=lambda: ScannedTrace(Path(tempfile.gettempdir())))


def _appraise(settings: TrackSettings, trace_file: Path, progress: ChunkFilter | None) -> _Run:
    """Feed the record to the appraiser chunk by chunk; write every update to ``trace_file``."""
    record = settings.record
    n_in, n_out = len(record.inputs), len(record.outputs)
    clock = (
        ChunkedTimeBase(str(record.time_col), record.time_rtol, record.time_unit)
        if record.time_col
        else None
    )
    run: _Run | None = None
    with TraceWriter(trace_file) as writer:
        for names, values in _chunks(record, settings.chunk_rows, progress):
            if clock is not None:
                clock.feed(values[:, n_in + n_out], names[n_in + n_out])
                if run is None and clock.dt is None:
                    raise DataError(
                        f"time column {record.time_col!r}: the first chunk has one sample; "
                        "use a larger --chunk-rows or --dt."
                    )
            if run is None:
                check_column_roles(record.file, names, n_in, n_out)
                data_dt = clock.dt if clock is not None else record.dt
                kept = ThinnedTrace(settings.figure_updates)
                appraiser = settings.appraiser.build(data_dt)
                rate = data_dt if data_dt is not None else appraiser.dt
                factor = decimation_factor(appraiser.decimate_to, rate)
                run = _Run(appraiser, kept, 0, _Tail(factor), rate)
            run.n_raw += values.shape[0]
            run.tail.feed(values[:, : n_in + n_out])
            _push(run, names, values, writer, n_in, n_out)
    assert run is not None  # iter_table_chunks raises on a file without rows
    return run


def _push(
    run: _Run, names: Any, values: np.ndarray, writer: TraceWriter, n_in: int, n_out: int
) -> None:
    """Appraise ``values`` (inputs, outputs, then other columns); keep and write the updates."""
    if not values.shape[0]:
        return
    part = run.appraiser.push(values[:, :n_in], values[:, n_in : n_in + n_out])
    if len(part):
        part = dataclasses.replace(
            part,
            input_names=tuple(names[:n_in]),
            output_names=tuple(names[n_in : n_in + n_out]),
        )
        writer.write(part)
        run.kept.add(part)
        run.whole.add(part)


def _chunks(record: RecordSpec, chunk_rows: int, progress: ChunkFilter | None) -> Iterator[Chunk]:
    chunks = iter_table_chunks(
        record.file, chunk_rows, columns=record.columns(), skip_rows=record.skip_rows
    )
    return chunks if progress is None else progress(chunks)


def _check_long_enough(run: _Run, settings: TrackSettings, trace_file: Path) -> None:
    needed = settings.appraiser.window_size + run.appraiser.structure.max_lag
    if run.appraiser.n_samples < needed or not run.kept.seen:
        trace_file.unlink(missing_ok=True)
        raise DataError(
            f"the record is too short for the window: {run.appraiser.n_samples} sample(s) "
            f"(of {run.n_raw} read) but --window-size {settings.appraiser.window_size} with "
            f"--order {settings.appraiser.order} needs at least {needed}; "
            "use a smaller --window-size or a longer record."
        )


def track_file(settings: TrackSettings, progress: ChunkFilter | None = None) -> TrackResult:
    """Run the CLPC appraiser over a record (read in chunks); write a trace and a report.

    Writes ``OUT/trace.FMT`` (one row per cluster update), the figures and ``report.html``
    (see :func:`clpc.report.write_track_report`), and the steady-state model if asked.
    ``OUT`` is written as one transaction (:class:`clpc.core.output_folder.OutputFolder`):
    locked against a second run, the files staged in a hidden folder and moved in when all
    are complete, the previous run's files replaced; an error or a kill leaves ``OUT`` as
    it was.
    The figures use a thinned copy of the trace when there are many updates; every count,
    the convergence point and the steady-state model come from all updates, gathered in one
    pass in memory that does not grow with the record
    (:class:`clpc.appraiser.scanned.ScannedTrace`).

    Parameters
    ----------
    settings : TrackSettings
        Record, appraiser, output folder and formats.
    progress : callable, optional
        Wraps the iterator of chunks ``(names, values)`` read from the file (once the file
        is open) and yields them on, e.g. to show a progress bar.

    Returns
    -------
    TrackResult
        Summary, steady-state model and the files written.

    Raises
    ------
    SamplingConflictError
        The record has both ``dt`` and ``time_col``.
    clpc.DataError
        Unreadable record; a time column that is not uniform; too few samples.
    clpc.core.atomic.OutputError
        ``OUT`` is locked by another run, a target is a symbolic link, or a file could not
        be written (the message names it).
    """
    settings.record.check_sampling()
    if settings.record.resample:
        raise SettingsError(
            "track reads the record in chunks and cannot resample it; resample it first "
            "(clpc.IOData.resample, or load_iodata(..., resample=True) and write_table)."
        )
    with OutputFolder(settings.out_dir, "--out") as folder:
        trace_file = folder.staging / f"trace.{settings.fmt}"
        run = _appraise(settings, trace_file, progress)
        try:
            result = _finish(settings, run, trace_file, folder.staging)
        finally:
            run.whole.close()
        folder.commit()
        files = [folder.final(f) for f in result.files]
    refused = None
    if settings.save and result.model is not None:
        refused = save_refusal(result.model, settings.save)
        if refused is None:
            save_model(result.model, settings.save)
            files.append(Path(settings.save))
    return dataclasses.replace(result, files=files, save_refused=refused)


def _finish(settings: TrackSettings, run: _Run, trace_file: Path, out: Path) -> TrackResult:
    """The report of an appraised record, written into ``out``."""
    _check_long_enough(run, settings, trace_file)
    done = Appraised(
        run.appraiser.config(),
        run.appraiser.n_samples,
        run.kept.trace(),
        run.whole,
        run.whole.last,
        run.tail.rows,
        run.appraiser.rule,
        run.n_raw,
        run.data_dt,
    )
    return write_report(settings, done, trace_file, out)
