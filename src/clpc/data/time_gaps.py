"""Dropped samples in a time column: found, counted and reported, one rule for every command.

A step of ``m`` whole sample times (each within ``time_rtol`` of a whole number, ``m`` up to
:data:`MAX_GAP_SAMPLES`) is ``m - 1`` dropped samples. Every reader takes it as a stream
does (:class:`clpc.data.timegrid.TimeGrid`): the gap is reported once, the samples on either
side are used as consecutive samples and the grid is re-anchored at the sample after it, so
``clpc track`` and ``clpc stream`` give the same updates on the same log. Across a gap the
lag vectors that straddle it mix samples ``m`` sample times apart: one dropped sample in a
long log costs about ``na + nb`` slightly wrong rows of the least-squares problem; many
gaps are better filled by interpolation (``resample=True``, ``--resample``), which the note
says.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable

import numpy as np

__all__ = ["MAX_GAP_SAMPLES", "classify_steps", "gap_note", "warn_gaps", "whole_steps"]

#: Longest gap taken at once [sample times]; a longer step is refused by a file reader, and
#: after it a stream's next sample must confirm the new grid (a stamp far ahead is more often
#: a bad stamp than a pause).
MAX_GAP_SAMPLES = 1000


def classify_steps(steps: np.ndarray, typical: float, rtol: float) -> tuple[np.ndarray, np.ndarray]:
    """Which time steps are one sample time, and how many samples each gap drops.

    Parameters
    ----------
    steps : ndarray, shape (n,)
        Time steps [s].
    typical : float
        The typical (median) step [s], positive.
    rtol : float
        Largest relative deviation of a step from the typical step (of a gap of ``m``
        sample times from ``m`` of them).

    Returns
    -------
    single : ndarray of bool, shape (n,)
        The step is one sample time (within ``rtol``).
    missing : ndarray of int, shape (n,)
        Samples dropped in the step: ``m - 1`` for a gap of ``m`` whole sample times, else 0.
    """
    ratio = steps / typical
    single = np.abs(ratio - 1.0) <= rtol
    whole = np.rint(ratio)
    with np.errstate(invalid="ignore", divide="ignore"):
        gap = (
            ~single
            & (whole >= 2)
            & (whole <= MAX_GAP_SAMPLES)
            & (np.abs(ratio - whole) <= rtol * whole)
        )
    return single, np.where(gap, whole - 1, 0).astype(np.int64)


def whole_steps(step: float, typical: float, rtol: float) -> int:
    """:func:`classify_steps` for one step, in plain floats (a stream's per-sample path).

    Parameters
    ----------
    step, typical, rtol
        As :func:`classify_steps` (one step [s]).

    Returns
    -------
    int
        1 for one sample time, ``m`` for a gap of ``m`` sample times, 0 for neither.
    """
    ratio = step / typical
    if abs(ratio - 1.0) <= rtol:
        return 1
    whole = round(ratio) if math.isfinite(ratio) else 0
    return whole if 2 <= whole <= MAX_GAP_SAMPLES and abs(ratio - whole) <= rtol * whole else 0


def gap_note(name: str, gaps: list[tuple[int, int]], label: Callable[[int], str], dt: float) -> str:
    """One line on the gaps of a time column (the first named, the rest counted).

    Parameters
    ----------
    name : str
        The time column's name and source, for the message.
    gaps : list of (int, int)
        Index of the sample after each gap, and the samples it dropped; not empty.
    label : callable
        ``label(k)`` names sample ``k`` (e.g. ``"line 12"``).
    dt : float
        The sample time [s].

    Returns
    -------
    str
    """
    first, missing = gaps[0]
    text = f"time column {name}: {missing} sample(s) missing before {label(first)}"
    if len(gaps) > 1:
        total = sum(m for _, m in gaps)
        text += f" and {len(gaps) - 1} more gap(s) ({total} samples missing in all)"
    return (
        f"{text} (dt = {dt:.12g} s); the samples either side of a gap are used as consecutive "
        "samples, as clpc stream does. Resample the record (resample=True, --resample) to "
        "fill the gaps by interpolation instead."
    )


def warn_gaps(
    name: str, gaps: list[tuple[int, int]], label: Callable[[int], str], dt: float
) -> None:
    """Issue :func:`gap_note` as a :class:`UserWarning` when there are gaps.

    Parameters
    ----------
    name, gaps, label, dt
        As :func:`gap_note` (``gaps`` may be empty: nothing is issued).
    """
    if gaps:
        warnings.warn(gap_note(name, gaps, label, dt), UserWarning, stacklevel=3)
