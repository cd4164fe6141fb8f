"""Argument checks of the simulated plants and the experiment's settings.

The same message style as the library's own checks: "what must hold; what was given; how to
fix". Booleans are never numbers here (``True`` is refused where an int or a float is
expected).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = [
    "REAL",
    "check_choice",
    "check_int",
    "check_nonnegative",
    "check_positive",
    "check_real",
]


def check_int(value: Any, name: str, low: int = 0, high: int | None = None) -> int:
    """``value`` as an int in ``[low, high]``; ``ValueError`` naming ``name`` otherwise."""
    span = f"[{low}, inf)" if high is None else f"[{low}, {high}]"
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{name} must be an int in the range {span}; got {value!r}.")
    if value < low or (high is not None and value > high):
        raise ValueError(f"{name} must be an int in the range {span}; got {value}.")
    return int(value)


#: Types accepted as real scalars (``bool`` is refused separately).
REAL = (int, float, np.integer, np.floating)


def check_real(value: Any, name: str, unit: str = "") -> float:
    """``value`` as a finite float; booleans, strings and other objects are refused."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, REAL):
        raise ValueError(f"{name} must be a real number{_unit(unit)}; got {value!r}. Pass a float.")
    try:
        v = float(value)
    except OverflowError:  # an int no float holds
        v = math.inf
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite; got {value!r}. Pass a finite float.")
    return v


def check_positive(value: Any, name: str, unit: str = "") -> float:
    """``value`` as a finite float > 0 (``unit`` names it in the message, e.g. ``"s"``)."""
    v = check_real(value, name, unit)
    if v <= 0:
        raise ValueError(f"{name} must be > 0{_unit(unit)}; got {value!r}. Pass a positive value.")
    return v


def check_nonnegative(value: Any, name: str, unit: str = "") -> float:
    """``value`` as a finite float >= 0."""
    v = check_real(value, name, unit)
    if v < 0:
        raise ValueError(
            f"{name} must be >= 0{_unit(unit)}; got {value!r}. Pass zero or a positive value."
        )
    return v


def _unit(unit: str) -> str:
    return f" [{unit}]" if unit else ""


def check_choice(value: Any, name: str, choices: tuple[str, ...]) -> str:
    """``value`` if it is one of ``choices``."""
    if not isinstance(value, str) or value not in choices:
        listed = ", ".join(repr(c) for c in choices)
        raise ValueError(f"{name} must be one of {listed}; got {value!r}.")
    return value
