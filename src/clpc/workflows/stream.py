"""The appraiser on a stream of text lines, one sample a line: csv or JSON lines.

The line parsers live here: :mod:`clpc.io` reads whole tables (with its own header and
number detection, not exported), not one sample at a time with per-line error recovery.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from clpc.appraiser import CLPC
from clpc.core.checks import check_choice, check_int, check_positive
from clpc.core.compact import compact_repr
from clpc.data import DataError
from clpc.report import update_records
from clpc.workflows.common import AppraiserSettings, SamplingConflictError, SettingsError
from clpc.workflows.stream_lines import (
    LineReader,
    SampleClock,
    Timed,
    parse_csv_sample,
    parse_jsonl_sample,
)

__all__ = [
    "StreamBatch",
    "StreamSettings",
    "parse_csv_sample",
    "parse_jsonl_sample",
    "stream_samples",
]

Sample = tuple[list[float], list[float]]


@dataclass(frozen=True)
class StreamSettings:
    """What :func:`stream_samples` runs and how it reads lines.

    Parameters
    ----------
    appraiser : AppraiserSettings
        The appraiser's settings.
    dt : float, optional
        Sample time of the data [s] (default 1, or from ``time_col``).
    n_in, n_out : int
        Inputs and outputs per sample (without ``inputs``/``outputs``).
    fmt : {"csv", "jsonl"}
        Lines ``"u1,...,y1,..."`` or ``{"u": ..., "y": ...}``.
    on_error : {"skip", "stop"}
        A malformed line: report it and skip it, or end the stream with ``DataError``.
    inputs, outputs : tuple of str
        Columns to use: csv names (from a header line) or 0-based indices written as
        digits; JSON keys (one number each). Empty: the first ``n_in`` fields are the
        inputs and the next ``n_out`` the outputs (csv), keys ``"u"``/``"y"`` (JSON).
    time_col : str, optional
        Column (csv name or index, JSON key) of sample times [s]: the sample time is the
        step between the first two samples; a sample off that grid is a malformed line.
    """

    appraiser: AppraiserSettings = field(default_factory=AppraiserSettings)
    dt: float | None = None
    n_in: int = 1
    n_out: int = 1
    fmt: Literal["csv", "jsonl"] = "csv"
    on_error: Literal["skip", "stop"] = "skip"
    inputs: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()
    time_col: str | None = None

    def __post_init__(self) -> None:
        if self.dt is not None:
            check_positive(self.dt, "dt", "s")
        check_int(self.n_in, "n_in", 1)
        check_int(self.n_out, "n_out", 1)
        check_choice(self.fmt, "fmt", ("csv", "jsonl"))
        check_choice(self.on_error, "on_error", ("skip", "stop"))
        if bool(self.inputs) != bool(self.outputs):
            raise SettingsError(
                "give both the input and the output columns (--input and --output), or "
                "neither (then fields are inputs first, outputs next)."
            )
        pairs = (("input", self.inputs, self.n_in), ("output", self.outputs, self.n_out))
        for kind, cols, n in pairs:
            if cols and n not in (1, len(cols)):
                raise SettingsError(
                    f"{len(cols)} {kind} column(s) were named {list(cols)} but "
                    f"--{kind}s {n} was given; drop --{kind}s."
                )
        if self.dt is not None and self.time_col is not None:
            raise SamplingConflictError()
        if self.appraiser.decimate_to is not None and self.dt is None and self.time_col is None:
            raise SettingsError(
                "--decimate-to is the rate the appraiser works at (the data are decimated to "
                "it); give the data's own sample time with --dt (or --time) as well."
            )

    @property
    def channels(self) -> tuple[int, int]:
        """Inputs and outputs per sample."""
        if self.inputs:
            return len(self.inputs), len(self.outputs)
        return self.n_in, self.n_out


@compact_repr
@dataclass(frozen=True)
class StreamBatch:
    """What one batch of lines gave.

    Attributes
    ----------
    records : list of dict
        One :func:`clpc.report.update_records` entry per cluster update (JSON-safe).
    skipped : list of str
        One message per malformed line skipped: ``"line N: what: 'text'"``.
    notes : list of str
        Lines read as something other than a sample, e.g. ``"line 1: header (column
        names): u, y"``.
    samples : int
        Valid samples in the batch.
    """

    records: list[dict[str, Any]] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    samples: int = 0


def _push(appraiser: CLPC, samples: list[Sample], n_in: int, n_out: int) -> list[dict[str, Any]]:
    if not samples:
        return []
    u = np.asarray([s[0] for s in samples]).reshape(-1, n_in)
    y = np.asarray([s[1] for s in samples]).reshape(-1, n_out)
    trace = appraiser.push(u, y)
    return update_records(trace) if len(trace) else []


class _Session:
    """The appraiser of one stream; built once the data's sample time is known."""

    def __init__(self, settings: StreamSettings) -> None:
        self.s = settings
        self.n_in, self.n_out = settings.channels
        self.clock = SampleClock() if settings.time_col is not None else None
        self.appraiser: CLPC | None = None
        self.waiting: list[Sample] = []  # samples before the sample time is known

    def accept(self, sample: Timed) -> None:
        """Check the sample's time (``ValueError`` when off the grid)."""
        if self.clock is not None:
            assert sample[2] is not None
            self.clock.check(sample[2])

    def push(self, samples: list[Sample]) -> list[dict[str, Any]]:
        if self.appraiser is None:
            if self.clock is not None and self.clock.dt is None:
                self.waiting += samples
                return []
            dt = self.clock.dt if self.clock is not None else self.s.dt
            self.appraiser = self.s.appraiser.build(dt)
            samples, self.waiting = self.waiting + samples, []
        return _push(self.appraiser, samples, self.n_in, self.n_out)


def stream_samples(
    batches: Iterable[Iterable[str]], settings: StreamSettings
) -> Iterator[StreamBatch]:
    """Run the appraiser on lines of samples, one batch of lines at a time.

    Blank lines and lines starting with ``#`` are ignored. A first csv line of names is the
    header when it has the stream's field count (or holds the named columns); it is
    reported in :attr:`StreamBatch.notes`. Any other line that is not a sample (text,
    numbers no float holds, ``1_5``, non-ASCII digits, deep JSON nesting, wrong types or
    counts, a time off the grid) is malformed. The samples of a batch are pushed to the
    appraiser together.

    Parameters
    ----------
    batches : iterable of iterables of str
        Lines as they arrive (e.g. what a pipe holds at each read).
    settings : StreamSettings
        Appraiser, channels, line format, what a malformed line does.

    Yields
    ------
    StreamBatch
        The updates of each batch, the malformed lines it skipped and its notes.

    Raises
    ------
    clpc.DataError
        A malformed line with ``on_error="stop"`` (after a last batch with the updates of
        the samples before it).
    SettingsError
        Named columns that the header does not hold (or no header to find them in).
    """
    session = _Session(settings)
    reader = LineReader(settings)
    for batch in batches:
        samples: list[Sample] = []
        skipped: list[str] = []
        for line in batch:
            try:
                sample = reader.read(line)
                if sample is not None:
                    session.accept(sample)
            except ValueError as exc:
                if isinstance(exc, SettingsError):
                    raise
                if settings.on_error == "stop":
                    notes, reader.notes = reader.notes, []
                    yield StreamBatch(session.push(samples), [], notes, len(samples))
                    raise DataError(str(exc)) from None
                skipped.append(str(exc))
                continue
            if sample is not None:
                samples.append((sample[0], sample[1]))
        notes, reader.notes = reader.notes, []
        yield StreamBatch(session.push(samples), skipped, notes, len(samples))
