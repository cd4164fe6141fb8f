"""The model layer's error and the shape check of signals fed to a model."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["ModelError", "as_2d"]


class ModelError(ValueError):
    """The requested operation does not exist for this model (e.g. an unstable inverse)."""


def as_2d(x: Any, n_cols: int, name: str) -> tuple[np.ndarray, bool]:
    """``x`` as (n_samples, n_cols) finite floats, and whether it was 1-D."""
    arr = np.asarray(x, dtype=np.float64)
    was_1d = arr.ndim == 1
    if was_1d:
        arr = arr[:, None]
    if arr.ndim != 2 or arr.shape[1] != n_cols:
        raise ValueError(
            f"{name} must have shape (n_samples,) or (n_samples, {n_cols}); got {arr.shape}."
        )
    if not np.all(np.isfinite(arr)):
        bad = int(np.argwhere(~np.isfinite(arr))[0, 0])
        raise ValueError(f"{name} must be finite; the first non-finite sample is at {bad}.")
    return arr, was_1d
