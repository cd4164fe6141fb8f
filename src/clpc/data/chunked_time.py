"""The time base of a record read in chunks, checked chunk by chunk (``clpc track``).

The rule of :func:`clpc.data.timebase.check_time_base`, applied to a time column that arrives
in pieces: the sample time is the first chunk's mean step; later samples keep to its grid as
closely (each step within ``time_rtol`` of the typical step, each sample within
:data:`~clpc.data.timebase.MAX_DRIFT_SAMPLES` of the grid). Dropped samples are reported
and the grid re-anchored after them (:mod:`clpc.data.time_gaps`). A record that breaks the
rule is refused at the first bad row, as a file reader refuses it whole.
"""

from __future__ import annotations

import numpy as np

from clpc.data.time_gaps import classify_steps, warn_gaps
from clpc.data.time_units import TIME_UNITS, time_unit
from clpc.data.timebase import MAX_DRIFT_SAMPLES, check_time_base
from clpc.data.validation import DataError

__all__ = ["MAX_GAP_NOTES", "ChunkedTimeBase"]

#: Gaps after which a record's later chunks report theirs no more (one line per chunk).
MAX_GAP_NOTES = 5


class ChunkedTimeBase:
    """Sample time from a time column read in chunks.

    The rule of :func:`clpc.data.timebase.check_time_base`, applied chunk by chunk: the
    sample time is the first chunk's mean step; later samples keep to its grid as closely.

    Parameters
    ----------
    name : str
        The time column's name, for messages.
    rtol : float
        Largest relative deviation of one step from the typical step.
    unit : {"s", "ms", "us"}, optional
        Unit of the times; default from the column's name as read (else seconds).
    """

    def __init__(self, name: str, rtol: float, unit: str | None) -> None:
        self.name = name
        self.rtol = rtol
        self.unit = unit
        self.scale: float | None = None
        self.last: float | None = None
        self.dt: float | None = None  # the sample time [s], once two samples were seen
        self.typical = 0.0
        self.t0 = 0.0  # time of the grid's anchor [s]
        self.k0 = 0  # index of the anchor sample
        self.seen = 0
        self.gaps = 0  # gaps found so far

    def feed(self, t: np.ndarray, name: str) -> None:
        """Check the next chunk of times.

        Parameters
        ----------
        t : ndarray, shape (n,)
            The chunk's times, in the column's unit.
        name : str
            The column's name in the file (its unit is read from it when not given).

        Raises
        ------
        DataError
            A time that does not increase, a step off by more than ``rtol``, or a sample
            more than ``MAX_DRIFT_SAMPLES`` off the grid; the message names the data row.
        """
        if t.size == 0:
            return
        if self.scale is None:
            self.scale = TIME_UNITS[time_unit(self.unit, name)]
        t = t * self.scale
        if self.dt is None:
            full = t if self.last is None else np.concatenate([[self.last], t])
            if full.size >= 2:
                base = check_time_base(
                    full, repr(self.name), self.rtol, lambda k: f"data row {k + 1}"
                )
                self.dt, self.typical, self.t0 = base.dt, float(np.median(np.diff(full))), full[0]
                if base.gaps:  # full[0] is sample 0
                    self.k0 = base.gaps[-1][0]
                    self.t0 = float(full[self.k0])
                    self.gaps += len(base.gaps)
        else:
            steps = np.diff(np.concatenate([[self.last], t]))
            k = self.seen + np.arange(t.size)
            dev = np.abs(steps - self.typical) / self.typical
            single, missing = classify_steps(steps, self.typical, self.rtol)
            after = np.maximum.accumulate(np.where(missing > 0, np.arange(t.size), -1))
            anchor_t = np.where(after >= 0, t[np.maximum(after, 0)], self.t0)
            anchor_k = np.where(after >= 0, k[np.maximum(after, 0)], self.k0)
            drift = np.abs(t - (anchor_t + (k - anchor_k) * self.dt)) / self.dt
            good = (steps > 0) & (single | (missing > 0)) & (drift <= MAX_DRIFT_SAMPLES)
            bad = np.flatnonzero(~good)
            if bad.size:
                j = int(bad[0])
                prev = self.last if j == 0 else t[j - 1]
                raise DataError(
                    f"time column {self.name!r} is not uniformly increasing at data row "
                    f"{self.seen + j + 1} ({prev:.12g} -> {t[j]:.12g}: step deviation "
                    f"{dev[j]:.2g} relative, {drift[j]:.2g} samples off the grid of dt = "
                    f"{self.dt:.12g} s; accepted: time_rtol={self.rtol:g}, drift <= "
                    f"{MAX_DRIFT_SAMPLES:g} samples); resample the record onto a uniform grid, "
                    "raise --time-rtol if the clock only jitters, or use --dt."
                )
            at = np.flatnonzero(missing)
            if at.size:
                self.t0, self.k0 = float(t[at[-1]]), int(k[at[-1]])
                if self.gaps < MAX_GAP_NOTES:
                    gaps = [(int(k[j]), int(missing[j])) for j in at]
                    warn_gaps(repr(self.name), gaps, lambda i: f"data row {i + 1}", self.dt)
                self.gaps += at.size
        self.last = float(t[-1])
        self.seen += t.size
