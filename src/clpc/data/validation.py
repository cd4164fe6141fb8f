"""Validation of user data: the checks :class:`~clpc.data.IOData` runs once, and its error."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from clpc.data.errors import DataError
from clpc.data.samples import as_samples

__all__ = ["DataError", "channel_names", "check_dt", "check_finite", "to_2d_float"]


def to_2d_float(values: Any, name: str) -> tuple[np.ndarray, list[str] | None]:
    """Convert array-like data to a float64 array of shape (n_samples, n_channels).

    The input policy is :func:`clpc.data.samples.as_samples`. Returns the array and the
    column names found on pandas objects (else ``None``).
    """
    arr, columns = as_samples(values, name)
    if arr.ndim == 0:
        raise DataError(f"{name} must be 1-D or 2-D; got a scalar. Pass one value per sample.")
    if arr.ndim == 1:
        arr = arr[:, None]
    elif arr.ndim != 2:
        raise DataError(
            f"{name} must be 1-D (one channel) or 2-D (n_samples, n_channels); "
            f"got {arr.ndim}-D with shape {arr.shape}."
        )
    if arr.shape[0] == 0 or arr.shape[1] == 0:
        raise DataError(f"{name} is empty (shape {arr.shape}); at least one sample is needed.")
    # an owned copy: the caller's array is neither aliased nor made read-only
    return np.array(arr, dtype=np.float64, order="C", copy=True), columns


def check_finite(arr: np.ndarray, name: str, channels: Sequence[str]) -> None:
    """Refuse a NaN or inf in ``arr`` (the message names the channel and the first sample)."""
    bad = ~np.isfinite(arr)
    if bad.any():
        row, col = np.argwhere(bad)[0]
        kind = "NaN" if np.isnan(arr[row, col]) else "inf"
        count = int(bad[:, col].sum())
        raise DataError(
            f"{name} channel '{channels[col]}' has {count} non-finite value(s); "
            f"the first is {kind} at sample index {row}. "
            "Remove or interpolate missing samples before identification."
        )


def check_dt(dt: Any) -> float:
    """``dt`` as a positive finite number of seconds (:class:`DataError` otherwise)."""
    if isinstance(dt, (bool, np.bool_, str, bytes)):
        raise DataError(f"dt (sample time) must be a number of seconds; got {dt!r}.")
    try:
        value = float(dt)
    except (TypeError, ValueError, OverflowError):
        raise DataError(f"dt (sample time) must be a number of seconds; got {dt!r:.60}.") from None
    if not np.isfinite(value) or value <= 0:
        raise DataError(
            f"dt (sample time) must be a positive finite number of seconds; got {dt!r}."
        )
    return value


def channel_names(
    given: Sequence[str] | None, found: list[str] | None, n: int, prefix: str, label: str
) -> tuple[str, ...]:
    """Channel names: ``given``, else the DataFrame's ``found``, else ``u0, u1, ...``."""
    if given is None:
        given = found if found is not None and len(found) == n else None
    if given is None:
        return tuple(f"{prefix}{i}" for i in range(n)) if n > 1 else (prefix,)
    if isinstance(given, str):
        given = [given]
    names = tuple(str(g) for g in given)
    if len(names) != n:
        raise DataError(f"{label} must name {n} channel(s); got {len(names)}: {list(names)}.")
    return names
