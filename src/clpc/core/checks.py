"""Argument checks shared by every public entry point (one message style).

Messages read "what must hold; what was given; how to fix". Booleans are never numbers here
(``True`` is refused where an int or a float is expected).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = [
    "REAL",
    "check_bool",
    "check_choice",
    "check_int",
    "check_nonnegative",
    "check_positive",
    "check_real",
    "resolve_order",
    "same_setting",
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


def check_bool(value: Any, name: str) -> bool:
    """``value`` as a bool; strings such as ``"no"`` are refused (they are truthy)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False; got {value!r}.")
    return bool(value)


def check_choice(value: Any, name: str, choices: tuple[str, ...]) -> str:
    """``value`` if it is one of ``choices``."""
    if not isinstance(value, str) or value not in choices:
        listed = ", ".join(repr(c) for c in choices)
        raise ValueError(f"{name} must be one of {listed}; got {value!r}.")
    return value


def resolve_order(order: Any, parameters_size: Any, default: int = 2) -> int:
    """The model order ``N`` from ``order`` or the paper's ``parameters_size`` (``N + 1``).

    Parameters
    ----------
    order : int or None
        ``N`` (``na = nb = N``).
    parameters_size : int or None
        The paper's name: the size of ``a`` and of ``b``, ``N + 1`` (an alias).
    default : int
        ``N`` when neither is given.

    Returns
    -------
    int
        ``N >= 1``.

    Raises
    ------
    ValueError
        Either is out of range, or both are given and disagree.
    """
    if parameters_size is not None:
        from_size = check_int(parameters_size, "parameters_size", 2) - 1
        if order is not None and check_int(order, "order", 1) != from_size:
            raise ValueError(
                f"order and parameters_size name one setting (parameters_size = order + 1); "
                f"got order={order} and parameters_size={parameters_size}. Pass one of them."
            )
        return from_size
    return check_int(default if order is None else order, "order", 1)


def same_setting(new: Any, old: Any, new_name: str, old_name: str) -> Any:
    """The one value of a setting known by two names (``new`` preferred, ``old`` an alias).

    Raises
    ------
    ValueError
        Both are given and differ.
    """
    if new is not None and old is not None and new != old:
        raise ValueError(
            f"{new_name} and {old_name} are the same setting ({old_name} is its former name); "
            f"got {new_name}={new!r} and {old_name}={old!r}. Pass {new_name} only."
        )
    return new if new is not None else old
