"""Samples fed to the appraiser: shape and finiteness, checked before anything is kept."""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.data import DataError
from clpc.data.samples import as_samples

__all__ = ["SCALAR_TYPES", "as_columns", "check_finite", "check_noise_cov"]

#: scalar sample types :meth:`clpc.CLPC.step` takes without building arrays
SCALAR_TYPES = frozenset({float, int, np.float64, np.float32, np.int64, np.int32})
#: finiteness is checked this many samples at a time (bounded temporaries)
CHECK_SLICE = 1 << 20


def as_columns(x: Any, name: str, *, allow_empty: bool = True) -> np.ndarray:
    """``x`` as a float array of shape (n, channels); scalars and 1-D become columns.

    The input policy is :func:`clpc.data.samples.as_samples` (complex, dates, text and
    magnitudes double precision cannot solve are refused). ``allow_empty=False`` refuses
    zero samples (a whole record must have some; a chunk of a stream may be empty).
    """
    arr, _ = as_samples(x, name)
    if arr.ndim == 0:
        arr = arr[None, None]
    elif arr.ndim == 1:
        arr = arr[:, None]
    elif arr.ndim != 2:
        raise DataError(f"{name} must be 1-D or 2-D; got shape {arr.shape}.")
    if not allow_empty and arr.shape[0] == 0:
        raise DataError(f"{name} is empty (shape {arr.shape}); at least one sample is needed.")
    return arr


def check_noise_cov(value: Any) -> np.ndarray | None:
    """``noise_cov`` as finite variances (1-D) or a symmetric covariance (2-D), else ``None``.

    Raises
    ------
    ValueError
        Not numbers, not 1-D or square 2-D, not finite, negative variances, or not symmetric.
    """
    if value is None:
        return None
    try:
        arr, _ = as_samples(value, "noise_cov")
    except DataError as exc:
        raise ValueError(str(exc)) from None
    ok_shape = arr.ndim == 1 or (arr.ndim == 2 and arr.shape[0] == arr.shape[1])
    if not ok_shape or arr.size == 0:
        raise ValueError(
            "noise_cov must be the lag vector's noise variances (1-D) or its covariance "
            f"(square 2-D); got shape {arr.shape}."
        )
    diag = arr if arr.ndim == 1 else np.diag(arr)
    if not np.all(np.isfinite(arr)) or np.any(diag < 0):
        raise ValueError("noise_cov must hold finite numbers with variances >= 0.")
    if arr.ndim == 2 and not np.allclose(arr, arr.T, rtol=1e-12, atol=0):
        raise ValueError("noise_cov must be symmetric (a covariance matrix).")
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
