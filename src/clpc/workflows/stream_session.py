"""One stream's run: lines in, samples checked against their clock, updates out.

:class:`LineStream` owns the line reader, the time grid of a time column
(:class:`clpc.data.timegrid.TimeGrid`) and the appraiser, which a caller may give (a resumed
state) and may save at any point between batches.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from clpc.appraiser import CLPC
from clpc.core.compact import compact_repr
from clpc.data import DataError
from clpc.data.timegrid import TimeGrid
from clpc.report import update_records
from clpc.workflows.common import SettingsError
from clpc.workflows.stream_lines import CutLine, LineReader, Timed

__all__ = ["LineStream", "StreamBatch"]

Sample = tuple[list[float], list[float]]


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


class LineStream:
    """The appraiser on lines of samples, batch by batch (see :func:`stream_samples`).

    Parameters
    ----------
    settings : StreamSettings
        Appraiser, channels, line format, time column, what a malformed line does.
    appraiser : CLPC, optional
        An appraiser to continue (e.g. loaded from a saved state); default a new one built
        from ``settings`` once the sample time is known.
    """

    def __init__(self, settings: Any, appraiser: CLPC | None = None) -> None:
        self.s = settings  # a StreamSettings
        self.n_in, self.n_out = settings.channels
        self.reader = LineReader(settings)
        self.clock: TimeGrid | None = None
        self.appraiser = appraiser
        self.waiting: list[Sample] = []  # samples before the sample time is known
        self.updates = 0

    def run(self, batches: Iterable[Iterable[str]]) -> Iterator[Any]:
        """Yield a :class:`StreamBatch` per batch of lines, and one at the end of the stream.

        Parameters
        ----------
        batches : iterable of iterables of str
            Lines as they arrive, without their newlines; a last line that had none is a
            :class:`~clpc.workflows.stream_lines.CutLine`.

        Yields
        ------
        StreamBatch
            The updates, skipped lines and notes of each batch.
        """
        for batch in batches:
            samples: list[Sample] = []
            skipped: list[str] = []
            notes: list[str] = []
            for line in batch:
                try:
                    sample = self.reader.read(line, not isinstance(line, CutLine))
                    if sample is not None:
                        notes += self._clock(sample)
                except SettingsError:
                    raise
                except ValueError as exc:
                    if self.s.on_error == "stop":
                        notes = self.reader.notes + notes
                        yield StreamBatch(self._push(samples), [], notes, len(samples))
                        raise DataError(str(exc)) from None
                    skipped.append(str(exc))
                    continue
                if sample is not None:
                    samples.append((sample[0], sample[1]))
            notes, self.reader.notes = self.reader.notes + notes, []
            yield StreamBatch(self._push(samples), skipped, notes, len(samples))
        notes = self.clock.settle() if self.clock is not None else []
        yield StreamBatch(self._push([]), [], notes, 0)

    def clock_problem(self) -> str | None:
        """Why no update came from the samples, when the time column is the reason."""
        if self.clock is None or self.updates:
            return None
        if self.clock.dt is None and self.waiting:
            return (
                f"time column {self.clock.name!r}: only one sample arrived; 2 are needed "
                "to find the sample time"
            )
        if self.clock.refused:
            return (
                f"no update: {self.clock.refused} sample(s) were refused for their time "
                f"column {self.clock.name!r} (see the lines above); check its unit "
                "(--time-unit) and tolerance (--time-rtol), or give --dt instead of --time"
            )
        return None

    def _clock(self, sample: Timed) -> list[str]:
        """Check the sample's time; notes on gaps, ``ValueError`` for a bad stamp."""
        if self.s.time_col is None:
            return []
        if self.clock is None:
            self.clock = TimeGrid(self.reader.time_name, self.s.time_rtol, self.s.time_unit)
        assert sample[2] is not None
        label = f"line {self.reader.no}"
        try:
            return self.clock.feed(sample[2], label)
        except ValueError as exc:
            raise ValueError(f"{label}: {exc}") from None

    def _push(self, samples: list[Sample]) -> list[dict[str, Any]]:
        if self.appraiser is None:
            dt = self.s.dt
            if self.clock is not None or self.s.time_col is not None:
                if self.clock is None or self.clock.dt is None:
                    self.waiting += samples
                    return []
                dt = self.clock.dt
            self.appraiser = self.s.appraiser.build(dt)
        samples, self.waiting = self.waiting + samples, []
        if not samples:
            return []
        u = np.asarray([s[0] for s in samples]).reshape(-1, self.n_in)
        y = np.asarray([s[1] for s in samples]).reshape(-1, self.n_out)
        trace = self.appraiser.push(u, y)
        records = update_records(trace) if len(trace) else []
        self.updates += len(records)
        return records
