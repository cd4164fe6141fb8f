"""The model layer's error and the shape check of signals fed to a model."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["ModelError", "as_2d", "require_siso"]


class ModelError(ValueError):
    """The requested operation does not exist for this model (e.g. an unstable inverse)."""


def require_siso(model: Any, what: str) -> None:
    """Raise :class:`ModelError` unless ``model`` has one input and one output.

    Parameters
    ----------
    model : LinearModel
        The model asked for ``what``.
    what : str
        The method or property asked for, named in the message.
    """
    if not model.is_siso:
        raise ModelError(
            f"{what} is defined for single-input single-output models; this model has "
            f"{model.n_inputs} input(s) and {model.n_outputs} output(s). "
            "Use numerators/denominators or to_control()."
        )


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
