"""Each window's mean output (its operating level), in one pass over the record.

A window of ``rows`` lag vectors ending at decimated sample ``k`` spans record samples
``(k - rows + 1) f .. k f`` (``f`` the decimation factor). Its mean is a difference of two
prefix sums of ``y - ref`` (``ref`` the column's mean, so the sums stay small), divided by
the count. The prefix sums are the sequential ones of ``numpy.cumsum``, bit for bit, but
are walked with two pointers instead of being stored: no temporary of the record's size
(a 1e7-sample record made three of 80 MB, 0.6 s of page faults and copies in ``CLPC.run``).
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

__all__ = ["attach_levels", "window_means"]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _window_sums(
    column: np.ndarray, ref: float, first: np.ndarray, last: np.ndarray, out: np.ndarray
) -> None:
    """``out[i] = P(last[i] + 1) - P(first[i])``, ``P(k)`` the sum of ``column[:k] - ref``.

    ``P`` is summed in order from sample 0 (as ``numpy.cumsum``); two running sums follow
    ``first`` and ``last``, and start again from 0 where either goes back.
    """
    k_lo, s_lo = 0, 0.0
    k_hi, s_hi = 0, 0.0
    for i in range(first.shape[0]):
        if first[i] < k_lo:
            k_lo, s_lo = 0, 0.0
        while k_lo < first[i]:
            s_lo += column[k_lo] - ref
            k_lo += 1
        if last[i] + 1 < k_hi:
            k_hi, s_hi = 0, 0.0
        while k_hi <= last[i]:
            s_hi += column[k_hi] - ref
            k_hi += 1
        out[i] = s_hi - s_lo


def window_means(y: np.ndarray, first: np.ndarray, last: np.ndarray) -> np.ndarray:
    """Mean of ``y[first[i] .. last[i]]`` (both included) for every window ``i``.

    Parameters
    ----------
    y : ndarray, shape (T, n_out)
        The outputs (float64).
    first, last : ndarray of int64, shape (n,)
        Each window's first and last sample, ``0 <= first <= last < T``.

    Returns
    -------
    ndarray, shape (n, n_out)
        The means; each column is summed about its own mean over ``y``.
    """
    count = (last - first + 1).astype(np.float64)
    out = np.empty((first.shape[0], y.shape[1]))
    sums = np.empty(first.shape[0])
    for k in range(y.shape[1]):
        column = np.ascontiguousarray(y[:, k])
        ref = float(column.mean())
        _window_sums(column, ref, first, last, sums)
        out[:, k] = sums / count + ref
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
    index = np.asarray(trace.index, dtype=np.int64)
    last = np.minimum(index * factor, yy.shape[0] - 1)
    first = np.maximum((index - np.asarray(trace.rows, dtype=np.int64) + 1) * factor, 0)
    trace.meta["window_level"] = window_means(yy, np.minimum(first, last), last)
