"""Decimation to the appraiser's sample time: one anti-alias filter, carried across chunks.

The filter is a causal 4th-order Butterworth at 0.8 of the new Nyquist frequency, started
at rest at the first sample (no offset transient); the kept samples are ``0, f, 2f, ...``
of the whole record, whatever the chunking.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.data import DataError

__all__ = ["Decimator", "decimate", "decimation_factor", "decimation_filter"]

#: relative tolerance of "an integer multiple of the data's sample time"
FACTOR_RTOL = 1e-9


def decimation_factor(target: float | None, data_dt: float | None) -> int:
    """The integer factor from the data's sample time to the target one (1: none).

    Raises
    ------
    DataError
        When ``target`` is not an integer multiple of ``data_dt``.
    """
    if target is None or data_dt is None:
        return 1
    ratio = target / data_dt
    factor = round(ratio)
    if factor < 1 or abs(ratio - factor) > FACTOR_RTOL * max(ratio, 1.0):
        raise DataError(
            f"decimate_to={target:g} s (the rate the appraiser works at) must be an integer "
            f"multiple of the data's sample time dt = {data_dt:g} s (ratio {ratio:g}); resample "
            "the data or choose decimate_to accordingly."
        )
    return factor


def decimation_filter(factor: int) -> np.ndarray:
    """Second-order sections of the anti-alias filter for ``factor`` (>= 2)."""
    from scipy import signal  # imported when used: scipy.signal costs ~0.8 s

    return signal.butter(4, 0.8 / factor, output="sos")


class Decimator:
    """Filter and keep every ``factor``-th sample of a record fed in chunks.

    Parameters
    ----------
    factor : int
        Decimation factor (``decimate_to / dt``), >= 1.
    zi : ndarray, optional
        The filter's state, (sections, 2, channels) (``None``: at rest at the first sample).
    phase : int
        Samples fed so far, modulo ``factor``.
    """

    def __init__(self, factor: int, zi: np.ndarray | None = None, phase: int = 0) -> None:
        self.factor = int(factor)
        self.zi = zi
        self.phase = phase

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """Decimate the next chunk ``x`` (T, channels); returns the kept samples."""
        f = self.factor
        if f == 1 or x.shape[0] == 0:
            return x
        sos = decimation_filter(f)
        from scipy import signal  # imported when used: scipy.signal costs ~0.8 s

        if self.zi is None:  # start at rest at the first sample
            self.zi = signal.sosfilt_zi(sos)[:, :, None] * x[0][None, None, :]
        filtered, self.zi = signal.sosfilt(sos, x, axis=0, zi=self.zi)
        first = (-self.phase) % f
        self.phase = (self.phase + x.shape[0]) % f
        return filtered[first::f]


def decimate(x: Any, factor: int) -> np.ndarray:
    """Decimate a whole 1-D or 2-D signal at once, exactly as :class:`clpc.CLPC` does.

    Parameters
    ----------
    x : array_like, shape (T,) or (T, channels)
        Signal logged at the fast rate.
    factor : int
        Decimation factor.

    Returns
    -------
    ndarray, shape (ceil(T / factor),) or (ceil(T / factor), channels)
    """
    arr = np.asarray(x, dtype=np.float64)
    flat = arr.ndim == 1
    cols = arr[:, None] if flat else arr
    out = Decimator(factor)(cols).copy()
    return out[:, 0] if flat else out
