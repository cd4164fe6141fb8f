"""The unit of a time column, from the user or from the column's name.

``t_ms``, ``time[ms]`` and ``timestamp_us`` hold milliseconds / microseconds, ``t`` seconds
(:func:`time_unit`); :func:`time_like` tells a column of sample times by its name. Used by
every reader (files, chunks, streams) and by :meth:`clpc.IOData.from_frame`.
"""

from __future__ import annotations

import re

from clpc.data.validation import DataError

__all__ = ["TIME_UNITS", "time_like", "time_unit"]

#: Time units and their length in seconds.
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6}

_UNIT_WORDS = {
    "ms": "ms",
    "msec": "ms",
    "millis": "ms",
    "milliseconds": "ms",
    "us": "us",
    "usec": "us",
    "µs": "us",
    "micros": "us",
    "microseconds": "us",
    "s": "s",
    "sec": "s",
    "secs": "s",
    "seconds": "s",
}


def time_unit(unit: str | None, column: str) -> str:
    """The unit of a time column: ``unit`` if given, else the one its name says, else ``s``.

    Parameters
    ----------
    unit : {"s", "ms", "us"} or None
        The unit asked for; ``None``: detected from the column's name, a word of which
        (split at non-letters, or a bracketed ``[ms]``) names a unit: ``t_ms``, ``time[ms]``,
        ``timestamp_us`` are read as milliseconds / microseconds, ``t`` as seconds.
    column : str
        The column's name.

    Returns
    -------
    str
        ``"s"``, ``"ms"`` or ``"us"``.

    Raises
    ------
    DataError
        An unknown unit.
    """
    if unit is not None:
        if unit not in TIME_UNITS:
            raise DataError(f"time unit must be one of {sorted(TIME_UNITS)}; got {unit!r}.")
        return unit
    words = [w for w in re.split(r"[^a-zµ]+", str(column).lower()) if w]
    found = {_UNIT_WORDS[w] for w in words[1:] if w in _UNIT_WORDS}  # "s" alone is a name
    return found.pop() if len(found) == 1 else "s"


#: first words of a column name that says it holds sample times (``t``, ``time_us``)
_TIME_WORDS = ("t", "time", "timestamp")


def time_like(column: str) -> str | None:
    """The unit of a column named like sample times (``t``, ``t_ms``, ``timestamp``), else None.

    Parameters
    ----------
    column : str
        A column's name: a time word (``t``, ``time``, ``timestamp``), then at most unit words
        (the rule of :func:`time_unit`), e.g. ``t_s``, ``time[ms]``, ``time_us``.

    Returns
    -------
    str or None
        ``"s"``, ``"ms"`` or ``"us"``; ``None`` for any other name (``t1``, ``torque``).
    """
    words = [w for w in re.split(r"[^a-zµ0-9]+", str(column).lower()) if w]
    if not words or words[0] not in _TIME_WORDS or any(w not in _UNIT_WORDS for w in words[1:]):
        return None
    return time_unit(None, column)
