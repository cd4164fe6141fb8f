"""Each window's mean output (its operating level), in one pass over the record.

A window of ``rows`` lag vectors ending at decimated sample ``k`` spans record samples
``(k - rows + 1) f .. k f`` (``f`` the decimation factor). Its mean is a difference of two
prefix sums of ``y - ref`` (``ref`` the column's mean, so the sums stay small), divided by
the count. The prefix sums are the sequential ones of ``numpy.cumsum``, bit for bit, but
are walked with two pointers instead of being stored: no temporary of the record's size
(a 1e7-sample record made three of 80 MB, 0.6 s of page faults and copies in ``CLPC.run``).
Each window's first and last sample are worked out in the same compiled loop: no temporary
of the windows' length either (seven of them, 45 MiB at 1e7 samples and C = 12, were the
largest part of ``CLPC.run``'s memory besides its trace).
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

__all__ = ["attach_levels", "window_levels"]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _window_means(
    column: np.ndarray,
    ref: float,
    windows: tuple[np.ndarray, np.ndarray],
    span: tuple[int, int, int],
    out: np.ndarray,
) -> None:
    """``out[i]``: the mean of window ``i``'s samples of ``column``, summed about ``ref``.

    ``windows = (index, rows)``, ``span = (factor, n_raw, offset)`` as for
    :func:`window_levels`. The sum of a window is ``P(last + 1) - P(first)``, ``P(k)`` the sum
    of ``column[:k] - ref`` in order from sample 0 (as ``numpy.cumsum``); two running sums
    follow ``first`` and ``last``, and start again from 0 where either goes back. Each
    window's first and last sample are worked out here, so no array of the windows' length
    is made besides ``out``.
    """
    index, rows = windows
    factor, n_raw, offset = span
    k_lo, s_lo = 0, 0.0
    k_hi, s_hi = 0, 0.0
    for i in range(index.shape[0]):
        last = min(index[i] * factor, n_raw - 1)
        first = min(max((index[i] - rows[i] + 1) * factor, 0), last) - offset
        last -= offset
        if first < 0 or last >= column.shape[0]:
            raise ValueError("clpc internal error: a window reaches outside the samples given")
        if first < k_lo:
            k_lo, s_lo = 0, 0.0
        while k_lo < first:
            s_lo += column[k_lo] - ref
            k_lo += 1
        if last + 1 < k_hi:
            k_hi, s_hi = 0, 0.0
        while k_hi <= last:
            s_hi += column[k_hi] - ref
            k_hi += 1
        out[i] = (s_hi - s_lo) / float(last - first + 1) + ref


def window_levels(
    y: np.ndarray,
    index: np.ndarray,
    rows: np.ndarray,
    factor: int = 1,
    span: tuple[int, int] | None = None,
) -> np.ndarray:
    """Each window's mean output: the mean of record samples ``first .. last`` (both included).

    A window of ``rows`` lag vectors ending at decimated sample ``index`` spans record samples
    ``first = max((index - rows + 1) f, 0)`` to ``last = min(index f, n_raw - 1)`` (``first``
    at most ``last``). Memory: the result only; no array of the record's or of the windows'
    length is made (one column's contiguous copy when ``y`` has several).

    Parameters
    ----------
    y : ndarray, shape (T, n_out)
        The outputs (float64): record samples ``offset .. offset + T - 1``.
    index, rows : ndarray of int64, shape (n,)
        Each window's newest decimated sample and its lag vectors (a trace's ``index`` and
        ``rows``).
    factor : int
        The decimation factor ``f`` (1: none).
    span : (int, int), optional
        ``(offset, n_raw)``: the record sample of ``y[0]`` and the record's length (a piece
        of a longer record); default ``(0, T)``.

    Raises
    ------
    ValueError
        A window reaches outside ``y`` (the caller's windows do not belong to these samples).

    Returns
    -------
    ndarray, shape (n, n_out)
        The means; each column is summed about its own mean over ``y``.
    """
    offset, n_raw = span if span is not None else (0, y.shape[0])
    idx = np.asarray(index, dtype=np.int64)
    counts = np.asarray(rows, dtype=np.int64)
    out = np.empty((idx.shape[0], y.shape[1]))
    for k in range(y.shape[1]):
        column = np.ascontiguousarray(y[:, k])
        ref = float(column.mean())
        _window_means(column, ref, (idx, counts), (factor, n_raw, offset), out[:, k])
    return out


def attach_levels(trace: Any, y: np.ndarray, factor: int) -> None:
    """Store each window's mean output in ``trace.meta["window_level"]`` (n_updates, n_out).

    ``y`` (shape (T, n_out)) is the record given to :meth:`clpc.CLPC.run` at the data's
    rate; decimated sample ``k`` is record sample ``k * factor``, so a window of ``rows``
    lag vectors ending at ``k`` spans record samples ``(k - rows + 1) f .. k f``.
    """
    if len(trace) == 0:
        return
    yy = np.asarray(y, dtype=np.float64)
    trace.meta["window_level"] = window_levels(yy, trace.index, trace.rows, factor)
