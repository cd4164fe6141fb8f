"""Samples fed to the appraiser: shape and finiteness, checked before anything is kept."""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.data import DataError

__all__ = ["SCALAR_TYPES", "as_columns", "check_finite"]

#: scalar sample types :meth:`clpc.CLPC.step` takes without building arrays
SCALAR_TYPES = frozenset({float, int, np.float64, np.float32, np.int64, np.int32})
#: finiteness is checked this many samples at a time (bounded temporaries)
CHECK_SLICE = 1 << 20


def as_columns(x: Any, name: str) -> np.ndarray:
    """``x`` as a float array of shape (n, channels); scalars and 1-D become columns.

    Complex values are refused (casting would drop the imaginary part without a word).
    """
    if np.iscomplexobj(x):
        raise DataError(
            f"{name} must hold real numbers; got complex values. Pass the real part (or the "
            "magnitude) explicitly if that is what you mean."
        )
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise DataError(f"{name} must hold numbers; got {type(x).__name__}.") from None
    if arr.ndim == 0:
        arr = arr[None, None]
    elif arr.ndim == 1:
        arr = arr[:, None]
    elif arr.ndim != 2:
        raise DataError(f"{name} must be 1-D or 2-D; got shape {arr.shape}.")
    return arr


def check_finite(arr: np.ndarray, name: str, offset: int) -> None:
    """Raise a :class:`DataError` naming the first non-finite sample (counted from ``offset``)."""
    for lo in range(0, arr.shape[0], CHECK_SLICE):
        bad = ~np.isfinite(arr[lo : lo + CHECK_SLICE])
        if bad.any():
            row, col = np.argwhere(bad)[0]
            raise DataError(
                f"{name} channel {col} is not finite at sample {offset + lo + row} (counting "
                "from the first sample fed); remove or interpolate missing samples."
            )
