"""The appraiser on a stream of text lines, one sample a line: csv or JSON lines.

The line parsers live here: :mod:`clpc.io` reads whole tables (with its own header and
number detection, not exported), not one sample at a time with per-line error recovery.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from typing import Literal

from clpc.core.checks import check_choice, check_int, check_positive
from clpc.data.time_units import TIME_UNITS
from clpc.data.timebase import DEFAULT_TIME_RTOL
from clpc.workflows.common import AppraiserSettings, SamplingConflictError, SettingsError
from clpc.workflows.stream_lines import parse_csv_sample, parse_jsonl_sample
from clpc.workflows.stream_session import LineStream, StreamBatch

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
        Column (csv name or index, JSON key) of sample times: the rule of
        :mod:`clpc.data.timegrid` (the mean of the first steps; a gap is reported and the
        grid re-anchored; a stamp that does not increase or lands between grid points is a
        malformed line).
    time_unit : {"s", "ms", "us"}, optional
        Unit of ``time_col``; default from its name (``t_ms`` is in ms), else seconds.
    time_rtol : float
        Largest relative deviation of one time step from the typical step.
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
    time_unit: str | None = None
    time_rtol: float = DEFAULT_TIME_RTOL

    def __post_init__(self) -> None:
        if self.dt is not None:
            check_positive(self.dt, "dt", "s")
        check_int(self.n_in, "n_in", 1)
        check_int(self.n_out, "n_out", 1)
        check_choice(self.fmt, "fmt", ("csv", "jsonl"))
        check_choice(self.on_error, "on_error", ("skip", "stop"))
        check_positive(self.time_rtol, "time_rtol")
        if self.time_unit is not None:
            check_choice(self.time_unit, "time_unit", tuple(TIME_UNITS))
            if self.time_col is None:
                raise SettingsError("--time-unit is the unit of the --time column; give --time.")
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
    yield from LineStream(settings).run(batches)
