"""The appraiser on a stream of text lines, one sample a line: csv or JSON lines.

The line parsers live here: :mod:`clpc.io` reads whole tables (with its own header and
number detection, not exported), not one sample at a time with per-line error recovery.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from clpc.appraiser import CLPC
from clpc.core.checks import check_choice, check_int, check_positive
from clpc.data import DataError
from clpc.report import update_records
from clpc.workflows.common import AppraiserSettings

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
        Sample time of the data [s] (default 1).
    n_in, n_out : int
        Inputs and outputs per sample.
    fmt : {"csv", "jsonl"}
        Lines ``"u1,...,y1,..."`` or ``{"u": ..., "y": ...}``.
    on_error : {"skip", "stop"}
        A malformed line: report it and skip it, or end the stream with ``DataError``.
    """

    appraiser: AppraiserSettings = field(default_factory=AppraiserSettings)
    dt: float | None = None
    n_in: int = 1
    n_out: int = 1
    fmt: Literal["csv", "jsonl"] = "csv"
    on_error: Literal["skip", "stop"] = "skip"

    def __post_init__(self) -> None:
        if self.dt is not None:
            check_positive(self.dt, "dt", "s")
        check_int(self.n_in, "n_in", 1)
        check_int(self.n_out, "n_out", 1)
        check_choice(self.fmt, "fmt", ("csv", "jsonl"))
        check_choice(self.on_error, "on_error", ("skip", "stop"))


@dataclass(frozen=True)
class StreamBatch:
    """What one batch of lines gave.

    Attributes
    ----------
    records : list of dict
        One :func:`clpc.report.update_records` entry per cluster update (JSON-safe).
    skipped : list of str
        One message per malformed line skipped: ``"line N: what: 'text'"``.
    """

    records: list[dict[str, Any]] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)


def _finite(values: list[float]) -> None:
    for i, v in enumerate(values, 1):
        if not math.isfinite(v):
            raise ValueError(f"value {i} is {v}; samples must be finite")


def parse_csv_sample(line: str, n_in: int, n_out: int) -> Sample:
    """One sample from a line ``"u1,...,y1,..."``.

    Parameters
    ----------
    line : str
        The line, without its newline.
    n_in, n_out : int
        Inputs and outputs per sample.

    Returns
    -------
    u, y : list of float
        The inputs and the outputs.

    Raises
    ------
    ValueError
        Wrong number of fields, a field that is not a number, a value that is not finite.
    """
    fields = [f.strip() for f in line.split(",")]
    if len(fields) != n_in + n_out:
        raise ValueError(
            f"expected {n_in + n_out} comma-separated numbers ({n_in} input(s) then "
            f"{n_out} output(s)); got {len(fields)} field(s)"
        )
    values = []
    for i, f in enumerate(fields, 1):
        try:
            values.append(float(f))
        except ValueError:
            raise ValueError(f"field {i} {f!r} is not a number") from None
    _finite(values)
    return values[:n_in], values[n_in:]


def parse_jsonl_sample(line: str, n_in: int, n_out: int) -> Sample:
    """One sample from a line ``{"u": ..., "y": ...}`` (a number, or a list per channel).

    Parameters
    ----------
    line : str
        The line, without its newline.
    n_in, n_out : int
        Inputs and outputs per sample.

    Returns
    -------
    u, y : list of float
        The inputs and the outputs.

    Raises
    ------
    ValueError
        Not JSON, not such an object, wrong counts or types, values that are not finite.
    """
    try:
        obj = json.loads(line)
    except json.JSONDecodeError as exc:
        raise ValueError(f"not valid JSON ({exc.msg})") from None
    except RecursionError:
        raise ValueError("not a sample: JSON nested too deeply") from None
    if not isinstance(obj, dict) or "u" not in obj or "y" not in obj:
        raise ValueError('expected an object {"u": ..., "y": ...}')
    out = []
    for key, n in (("u", n_in), ("y", n_out)):
        val = obj[key]
        vals = val if isinstance(val, list) else [val]
        if len(vals) != n or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals
        ):
            want = "a number" if n == 1 else f"a list of {n} numbers"
            raise ValueError(f"{key!r} must be {want}; got {val!r}")
        try:
            out.append([float(v) for v in vals])
        except OverflowError:
            raise ValueError(f"{key!r} holds a number too large for a float") from None
    _finite(out[0] + out[1])
    return out[0], out[1]


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _is_header(line: str) -> bool:
    fields = [f.strip() for f in line.split(",")]
    return all(f and not _is_float(f) for f in fields)


class _LineReader:
    """Samples from numbered lines: skips blanks, comments and a first csv header line."""

    def __init__(self, settings: StreamSettings) -> None:
        self.n_in, self.n_out = settings.n_in, settings.n_out
        self.parse: Callable[[str, int, int], Sample] = (
            parse_csv_sample if settings.fmt == "csv" else parse_jsonl_sample
        )
        self.header_possible = settings.fmt == "csv"
        self.no = 0  # physical line number (1-based)

    def read(self, line: str) -> Sample | None:
        """The sample of the next line, or None; ``ValueError("line N: ...")`` if malformed."""
        self.no += 1
        text = line.strip().lstrip("\ufeff")
        if not text or text.startswith("#"):
            return None
        if self.header_possible and _is_header(text):
            self.header_possible = False
            return None
        self.header_possible = False
        try:
            return self.parse(text, self.n_in, self.n_out)
        except ValueError as exc:
            raise ValueError(f"line {self.no}: {exc}: {text[:80]!r}") from None


def _push(appraiser: CLPC, samples: list[Sample], n_in: int, n_out: int) -> list[dict[str, Any]]:
    if not samples:
        return []
    u = np.asarray([s[0] for s in samples]).reshape(-1, n_in)
    y = np.asarray([s[1] for s in samples]).reshape(-1, n_out)
    trace = appraiser.push(u, y)
    return update_records(trace) if len(trace) else []


def stream_samples(
    batches: Iterable[Iterable[str]], settings: StreamSettings
) -> Iterator[StreamBatch]:
    """Run the appraiser on lines of samples, one batch of lines at a time.

    Blank lines and lines starting with ``#`` are ignored, and a first csv line of names
    is a header. The samples of a batch are pushed to the appraiser together.

    Parameters
    ----------
    batches : iterable of iterables of str
        Lines as they arrive (e.g. what a pipe holds at each read).
    settings : StreamSettings
        Appraiser, channel counts, line format, what a malformed line does.

    Yields
    ------
    StreamBatch
        The updates of each batch and the malformed lines it skipped.

    Raises
    ------
    clpc.DataError
        A malformed line with ``on_error="stop"`` (after a last batch with the updates of
        the samples before it).
    """
    appraiser = settings.appraiser.build(settings.dt)
    reader = _LineReader(settings)
    n_in, n_out = settings.n_in, settings.n_out
    for batch in batches:
        samples: list[Sample] = []
        skipped: list[str] = []
        for line in batch:
            try:
                sample = reader.read(line)
            except ValueError as exc:
                if settings.on_error == "stop":
                    yield StreamBatch(_push(appraiser, samples, n_in, n_out))
                    raise DataError(str(exc)) from None
                skipped.append(str(exc))
                continue
            if sample is not None:
                samples.append(sample)
        yield StreamBatch(_push(appraiser, samples, n_in, n_out), skipped)
