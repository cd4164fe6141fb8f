"""Real-number argument checks shared by the plants (one wording for every plant input).

The plants keep their own wording ("``name`` must be > 0; got ... Pass a positive value.")
rather than :mod:`clpc.core.checks`' because callers and tests match on it; integer and
choice arguments use :func:`clpc.core.checks.check_int` and
:func:`clpc.core.checks.check_choice`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["REAL", "nonnegative", "positive", "real"]

#: Types accepted as real scalars (``bool`` is rejected separately).
REAL = (int, float, np.integer, np.floating)


def real(value: Any, name: str) -> float:
    """``value`` as a finite float; ``ValueError`` naming ``name`` otherwise.

    Parameters
    ----------
    value : Any
        The argument; ``bool`` and non-numbers are refused.
    name : str
        Its name in the message.

    Returns
    -------
    float
        The value.
    """
    if isinstance(value, bool) or not isinstance(value, REAL):
        raise ValueError(f"{name} must be a real number; got {value!r}. Pass a float.")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} must be finite; got {value!r}. Pass a finite float.")
    return value


def positive(value: Any, name: str) -> float:
    """``value`` as a finite float > 0 (see :func:`real`)."""
    value = real(value, name)
    if value <= 0:
        raise ValueError(f"{name} must be > 0; got {value!r}. Pass a positive value.")
    return value


def nonnegative(value: Any, name: str) -> float:
    """``value`` as a finite float >= 0 (see :func:`real`)."""
    value = real(value, name)
    if value < 0:
        raise ValueError(f"{name} must be >= 0; got {value!r}. Pass zero or a positive value.")
    return value
