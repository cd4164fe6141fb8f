"""A record's time column: how uniform it is, and a uniform grid on request.

One rule for every reader (:func:`clpc.io.load_iodata` on a whole file, ``clpc track`` on
chunks): the sample time is the mean step, each step may deviate from the typical (median)
step by at most ``time_rtol`` (relative), and the samples may drift from the uniform grid
``t0 + k dt`` by at most :data:`MAX_DRIFT_SAMPLES` of a sample. Real data-acquisition clocks
jitter (a 1 kHz drive log measured 4e-5 relative). A step of a whole number of sample times
is dropped samples: reported, and the grid re-anchored after it, as a stream does
(:mod:`clpc.data.time_gaps`). A doubled sample or a step off by a fraction of a sample, and a
clock that drifts off its grid, misplace samples: they are refused, with what was measured.
The unit of a time column is read by :mod:`clpc.data.time_units`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.data.time_gaps import classify_steps, warn_gaps
from clpc.data.validation import DataError

__all__ = [
    "DEFAULT_TIME_RTOL",
    "MAX_DRIFT_SAMPLES",
    "TimeBase",
    "check_time_base",
    "measure_time_base",
    "resample_to_grid",
    "rounded_step",
    "step_deviation",
]

#: Largest relative deviation of one step from the median step accepted by default: 100x
#: the jitter of a real 1 kHz drive log (4e-5) and 100x below a missing sample (1.0).
DEFAULT_TIME_RTOL = 1e-2
#: Largest distance of a sample time from the uniform grid ``t0 + k dt`` [samples].
MAX_DRIFT_SAMPLES = 0.5


def rounded_step(step: float) -> float:
    """A mean step rounded to 12 significant digits when that changes it by at most 1e-9.

    Parameters
    ----------
    step : float
        A mean time step [s].

    Returns
    -------
    float
        The sample time [s]: ``0.009999999999999998`` becomes ``0.01``.
    """
    rounded = float(f"{step:.12g}")
    return rounded if abs(rounded - step) <= 1e-9 * abs(step) else float(step)


def step_deviation(step: Any, typical: float) -> Any:
    """Relative deviation of time steps from the typical step: the one tolerance test.

    A step is on the time base when this is at most ``time_rtol`` (every reader, and
    :class:`clpc.data.timegrid.TimeGrid` for a stream).

    Parameters
    ----------
    step : float or ndarray
        Time steps [s] (or steps counted in sample times, with ``typical`` a whole number).
    typical : float
        The typical step, in the same unit.

    Returns
    -------
    float or ndarray
        ``|step - typical| / |typical|`` (infinite for a typical step of 0).
    """
    if not typical:
        return np.full(np.shape(step), np.inf) if np.ndim(step) else float("inf")
    return np.abs(np.subtract(step, typical)) / abs(typical)


@dataclass(frozen=True)
class TimeBase:
    """What a time column measured.

    Attributes
    ----------
    dt : float
        Sample time [s]: the mean step (rounded to 12 significant digits when that changes
        it by less than 1e-9 relative).
    n_samples : int
        Samples in the column.
    jitter : float
        Largest relative deviation of one step from the median step.
    drift : float
        Largest distance of a sample from the grid ``t0 + k dt`` [samples].
    worst_step : int
        0-based index ``k`` of the step ``t[k] -> t[k + 1]`` with the largest deviation.
    gaps : tuple of (int, int)
        Dropped samples (:mod:`clpc.data.time_gaps`): the index of the sample after each
        gap and how many samples it dropped; gaps are left out of ``jitter``, and the grid
        is re-anchored after each one.
    """

    dt: float
    n_samples: int
    jitter: float
    drift: float
    worst_step: int
    gaps: tuple[tuple[int, int], ...] = ()

    def describe(self) -> str:
        """One line: ``dt = 0.001 s from 12000 samples (jitter 3.4e-05, drift 0.01 samples)``."""
        return (
            f"dt = {self.dt:.12g} s from {self.n_samples} samples (largest step deviation "
            f"{self.jitter:.2g} relative, largest drift from the grid {self.drift:.2g} samples)"
        )


def measure_time_base(t: Any, rtol: float = DEFAULT_TIME_RTOL) -> TimeBase:
    """Measure a time column without judging it (see :func:`check_time_base`).

    Parameters
    ----------
    t : array_like, shape (n,)
        Increasing sample times [s], ``n >= 2``.
    rtol : float
        Tolerance that tells a gap of whole sample times from a step that is off
        (:func:`clpc.data.time_gaps.classify_steps`).

    Returns
    -------
    TimeBase
        The sample time is the mean step between gaps; the drift is measured from the
        grid re-anchored at the sample after each gap.
    """
    t = np.asarray(t, dtype=np.float64)
    steps = np.diff(t)
    typical = float(np.median(steps))
    dev = step_deviation(steps, typical)
    missing = classify_steps(steps, typical, rtol)[1] if typical > 0 else np.zeros(0)
    at = np.flatnonzero(missing)  # gap steps t[j] -> t[j + 1]
    first = np.concatenate([[0], at + 1])  # first sample of each stretch between gaps
    last = np.concatenate([at, [t.size - 1]])
    if at.size:
        step = float(np.sum(t[last] - t[first]) / max(int(np.sum(last - first)), 1))
        dev[at] = 0.0
    else:
        step = float((t[-1] - t[0]) / (t.size - 1))
    stretch = np.repeat(np.arange(first.size), last - first + 1)
    grid = t[first][stretch] + (np.arange(t.size) - first[stretch]) * step
    drift = float(np.max(np.abs(t - grid)) / abs(step)) if step else float("inf")
    worst = int(np.argmax(dev))
    gaps = tuple((int(j) + 1, int(missing[j])) for j in at)
    return TimeBase(rounded_step(step), int(t.size), float(dev[worst]), drift, worst, gaps)


def check_time_base(
    t: Any,
    name: str,
    rtol: float = DEFAULT_TIME_RTOL,
    row_label: Callable[[int], str] = lambda k: f"row {k}",
) -> TimeBase:
    """Measure a time column and refuse one that is not increasing and uniform.

    Parameters
    ----------
    t : array_like, shape (n,)
        Sample times [s] (already in seconds).
    name : str
        The column's name and source, for messages.
    rtol : float
        Largest relative deviation of one step from the median step.
    row_label : callable
        ``row_label(k)`` names sample ``k`` in a message (e.g. ``"line 12"``).

    Returns
    -------
    TimeBase
        What was measured. Dropped samples (a step of whole sample times) are accepted and
        reported by one :class:`UserWarning` (:func:`clpc.data.time_gaps.warn_gaps`).

    Raises
    ------
    DataError
        Fewer than 2 samples, a step that is not positive, a step off by more than
        ``rtol`` that is not a gap, or a drift from the uniform grid above
        :data:`MAX_DRIFT_SAMPLES`; the message says what was measured and how to proceed
        (``resample``).
    """
    t = np.asarray(t, dtype=np.float64)
    if t.size < 2:
        raise DataError(
            f"time column {name} has {t.size} sample(s); at least 2 are needed to find the "
            "sample time (or pass dt=)."
        )
    steps = np.diff(t)
    nonpos = np.flatnonzero(~(steps > 0))
    if nonpos.size:
        k = int(nonpos[0]) + 1
        raise DataError(
            f"time column {name} is not increasing at {row_label(k)} "
            f"({t[k - 1]:.12g} -> {t[k]:.12g}); sort the record by time and remove repeated "
            "samples."
        )
    base = measure_time_base(t, rtol)
    if base.jitter > rtol or base.drift > MAX_DRIFT_SAMPLES:
        k = base.worst_step + 1
        typical = float(np.median(steps))
        raise DataError(
            f"time column {name} is not uniformly sampled: measured {base.describe()}; "
            f"the step from {row_label(k - 1)} to {row_label(k)} is {steps[k - 1]:.12g} s "
            f"against a typical (median) {typical:.12g} s. Accepted: step deviation <= "
            f"time_rtol={rtol:g}, drift <= {MAX_DRIFT_SAMPLES:g} samples. Resample the "
            "record onto a uniform grid (resample=True, --resample), or raise time_rtol "
            "(--time-rtol) if the clock only jitters."
        )
    warn_gaps(name, list(base.gaps), row_label, base.dt)
    return base


def resample_to_grid(t: Any, values: Any, dt: float | None = None) -> tuple[float, np.ndarray]:
    """Values of an irregularly timed record on the uniform grid ``t0 + k dt``.

    Linear interpolation between neighbouring samples (``numpy.interp`` per column): right
    for a jittery clock whose samples are close to the grid; a record with gaps gets straight
    lines across them.

    Parameters
    ----------
    t : array_like, shape (n,)
        Increasing sample times [s].
    values : array_like, shape (n, k)
        Samples.
    dt : float, optional
        Grid step [s]; default the mean step.

    Returns
    -------
    dt : float
        The grid step [s].
    values : ndarray, shape (m, k)
        The samples on the grid ``t0, t0 + dt, ...`` up to ``t[-1]``.

    Raises
    ------
    DataError
        Fewer than 2 samples, or times that are not strictly increasing.
    """
    t = np.asarray(t, dtype=np.float64)
    vals = np.asarray(values, dtype=np.float64)
    if t.size < 2 or not np.all(np.diff(t) > 0):
        raise DataError(
            "resampling needs at least 2 strictly increasing sample times; sort the record "
            "by time and remove repeated samples first."
        )
    step = measure_time_base(t).dt if dt is None else float(dt)
    m = int(np.floor((t[-1] - t[0]) / step * (1 + 1e-12))) + 1
    grid = t[0] + np.arange(m) * step
    cols = [np.interp(grid, t, vals[:, j]) for j in range(vals.shape[1])]
    return step, np.column_stack(cols) if cols else np.empty((m, 0))
