"""The time-base rule applied one sample at a time, for a stream that cannot stop.

The rule is :mod:`clpc.data.timebase`'s (one for every command): times in the unit the
column's name says or ``time_unit``, each step within ``time_rtol`` of the typical step
(:func:`clpc.data.timebase.step_deviation`), samples within
:data:`~clpc.data.timebase.MAX_DRIFT_SAMPLES` of their grid. A file reader refuses a record
that breaks it; a stream reports the sample that breaks it and goes on:

- the sample time is the mean of the first :data:`WARMUP_STEPS` steps, less those that
  deviate from their median (a gap among them does not bias it);
- a step of ``m`` whole sample times (within ``time_rtol`` each, ``m`` up to
  :data:`MAX_GAP_SAMPLES`) means ``m - 1`` dropped samples: reported once, the sample is
  used and the grid re-anchored at it;
- a stamp that does not increase, lands between grid points or far ahead, is a bad stamp: the sample
  is refused and the grid stays where it was; two samples in a row one step apart on another
  grid re-anchor the grid there (a clock that jumped), so later samples are used.
"""

from __future__ import annotations

import math

import numpy as np

from clpc.data.time_gaps import MAX_GAP_SAMPLES, whole_steps
from clpc.data.time_units import TIME_UNITS, time_unit
from clpc.data.timebase import (
    DEFAULT_TIME_RTOL,
    MAX_DRIFT_SAMPLES,
    rounded_step,
    step_deviation,
)

__all__ = ["MAX_GAP_SAMPLES", "WARMUP_STEPS", "TimeGrid"]

#: Steps whose mean is a stream's sample time.
WARMUP_STEPS = 64


class TimeGrid:
    """The sample time and grid of a stream of time stamps, checked stamp by stamp.

    Parameters
    ----------
    name : str
        The time column's name (its unit is read from it, e.g. ``t_ms``).
    rtol : float
        Largest relative deviation of one step from the typical step.
    unit : {"s", "ms", "us"}, optional
        Unit of the stamps; default from ``name`` (else seconds).
    warmup : int
        Steps whose mean is the sample time (fewer when the stream ends earlier).
    """

    def __init__(
        self,
        name: str,
        rtol: float = DEFAULT_TIME_RTOL,
        unit: str | None = None,
        warmup: int = WARMUP_STEPS,
    ) -> None:
        self.name = name
        self.rtol = float(rtol)
        self.scale = TIME_UNITS[time_unit(unit, name)]
        self.warmup = int(warmup)
        self.dt: float | None = None  # the sample time [s], fixed after the warm-up
        self._first: list[tuple[float, str]] = []  # warm-up stamps [s] and their labels
        self._anchor = 0.0  # time of the last re-anchoring [s]
        self._since = 0  # grid steps since the anchor
        self._last = -math.inf  # last used stamp [s]
        self._odd: float | None = None  # a refused stamp just before [s]
        self._steps = 0.0  # sum of the steps used for the running mean [s]
        self._n_steps = 0
        self.refused = 0
        self.gaps = 0

    def feed(self, stamp: float, label: str) -> list[str]:
        """Check the next stamp (in the column's unit).

        Parameters
        ----------
        stamp : float
            The sample's time, in the column's unit.
        label : str
            Where the sample is, for messages (e.g. ``"line 12"``).

        Returns
        -------
        list of str
            Notes on gaps found (dropped samples, a re-anchored grid), usually none.

        Raises
        ------
        ValueError
            A bad stamp: the sample must not be used (counted in :attr:`refused`).
        """
        t = float(stamp) * self.scale
        if self.dt is None:
            if not t > self._last:
                self.refused += 1
                raise ValueError(self._backwards(t))
            self._first.append((t, label))
            self._last = t
            return self.settle() if len(self._first) > self.warmup else []
        return self._check(t, label)

    def settle(self) -> list[str]:
        """Fix the sample time from the stamps so far (at least 2); notes on their gaps.

        Returns
        -------
        list of str
            Notes on gaps among the warm-up stamps.
        """
        if self.dt is not None or len(self._first) < 2:
            return []
        t = np.array([s for s, _ in self._first])
        self.dt = float(np.median(np.diff(t)))  # the typical step, to find the gaps
        self._anchor, self._since, self._last = float(t[0]), 0, float(t[0])
        notes = []
        for s, label in self._first[1:]:
            m = (s - self._last) / self.dt
            whole = round(m)
            if whole == 1 and step_deviation(m, 1) <= self.rtol:
                self._since += 1
                self._add_step(s - self._last)
                self._last = s
            else:  # already waiting to be used: reported, and the grid re-anchored
                notes.append(self._gap(s, m, label))
        self._first = []
        self.dt = rounded_step(self._mean_step())  # the mean step, as the readers'
        return notes

    def _check(self, t: float, label: str) -> list[str]:
        assert self.dt is not None
        step = self._mean_step()
        m = (t - self._last) / step
        whole = whole_steps(t - self._last, step, self.rtol)  # the readers' rule
        if whole:  # one sample time, or dropped samples
            drift = abs(t - (self._anchor + (self._since + whole) * step)) / step
            prev, self._odd = self._last, None
            if whole == 1 and drift <= MAX_DRIFT_SAMPLES:
                self._since, self._last = self._since + 1, t
                self._add_step(t - prev)
                return []
            return [self._gap(t, m, label)]
        if self._odd is not None and t > self._odd:
            m_odd = (t - self._odd) / step
            if step_deviation(m_odd, 1) <= self.rtol:  # a clock that jumped: follow it
                self._odd, self._last = None, t
                self._anchor, self._since = t, 0
                self.gaps += 1
                return [
                    f"{label}: the {self.name!r} clock jumped (two samples one step apart "
                    f"off the grid); the grid is re-anchored at {t / self.scale:.16g}"
                ]
        self._odd = t
        self.refused += 1
        if not t > self._last:
            raise ValueError(self._backwards(t))
        raise ValueError(
            f"time {t / self.scale:.16g} is {m:.4g} sample times after the previous sample "
            f"({self._last / self.scale:.16g}), not a whole number of them (up to "
            f"{MAX_GAP_SAMPLES}) within "
            f"time_rtol={self.rtol:g} (dt = {step:.12g} s); sample refused"
        )

    def _gap(self, t: float, m: float, label: str) -> str:
        """Re-anchor the grid at ``t``, ``m`` sample times after the previous sample."""
        self._anchor, self._since, self._last = t, 0, t
        self.gaps += 1
        whole = round(m)
        if whole >= 2 and step_deviation(m, whole) <= self.rtol:
            what = f"{whole - 1} sample(s) missing before this one"
        else:
            what = "a sample off the grid"
        return (
            f"{label}: {what} on time column {self.name!r} (a step of {m:.6g} sample "
            f"times, dt = {self._mean_step():.12g} s); the grid is re-anchored here and "
            "the later samples are used"
        )

    def _add_step(self, step: float) -> None:
        self._steps += step
        self._n_steps += 1

    def _mean_step(self) -> float:
        """The mean of the single steps used so far (the sample time before any) [s]."""
        assert self.dt is not None
        return self._steps / self._n_steps if self._n_steps else self.dt

    def _backwards(self, t: float) -> str:
        return (
            f"time {t / self.scale:.16g} does not increase (previous "
            f"{self._last / self.scale:.16g} on column {self.name!r}); sample refused"
        )
