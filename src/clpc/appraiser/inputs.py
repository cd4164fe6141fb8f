"""Samples fed to the appraiser: shape and finiteness, checked before anything is kept."""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.core.checks import check_positive
from clpc.data import DataError, IOData, as_iodata
from clpc.data.samples import as_samples

__all__ = [
    "SCALAR_TYPES",
    "as_chunk",
    "as_columns",
    "as_record",
    "check_chunk",
    "check_finite",
    "check_noise_cov",
]

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


def as_chunk(u: Any, y: Any, offset: int) -> tuple[np.ndarray, np.ndarray]:
    """A chunk of samples as columns of the same length, finite (``offset``: samples before)."""
    return check_chunk(as_columns(u, "u"), as_columns(y, "y"), offset)


def check_chunk(u2: np.ndarray, y2: np.ndarray, offset: int) -> tuple[np.ndarray, np.ndarray]:
    """Columns from :func:`as_columns` of the same length and finite; returns them."""
    if u2.shape[0] != y2.shape[0]:
        raise DataError(
            f"u and y must have the same length; got len(u)={u2.shape[0]}, len(y)={y2.shape[0]}."
        )
    check_finite(u2, "u", offset)
    check_finite(y2, "y", offset)
    return u2, y2


def as_record(u: Any, y: Any, dt: Any) -> tuple[np.ndarray, np.ndarray, float | None, Any]:
    """One continuous record: ``(u, y, its sample time or None, channel names or None)``."""
    if isinstance(u, np.ndarray) and isinstance(y, np.ndarray):
        # plain arrays: checked by push, without IOData's defensive copy of the record
        u_arr = as_columns(u, "u", allow_empty=False)
        y_arr = as_columns(y, "y", allow_empty=False)
        return u_arr, y_arr, None if dt is None else check_positive(dt, "dt", "s"), None
    data = as_iodata(u, y, dt)
    if data.n_experiments > 1:
        raise DataError(
            f"CLPC runs over one continuous record; this one holds {data.n_experiments} "
            "experiments, and its windows would reach across their boundaries. Run each "
            "experiment on its own (IOData.split())."
        )
    data_dt = data.dt if isinstance(u, IOData) or dt is not None else None
    return data.u, data.y, data_dt, (data.input_names, data.output_names)
