"""One checker for the JSON that clpc reads back: model files and appraiser states.

Both are parsed with limits on size, nesting and number length (:func:`bounded_json`) and
checked field by field with :class:`Fields`, bound to the format's error class and to where
the data came from, so that a problem reads alike in both: where (the file, the field),
what is wrong (with the value found) and, where there is one, how to fix it. What is
particular to each format (shapes that depend on other fields, the counters of a state) is
in :mod:`clpc.io.model_validation` and :mod:`clpc.appraiser.state_schema`.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["MAX_NUMBER_CHARS", "Fields", "LongNumber", "bounded_json", "json_depth", "short"]

#: Longest number literal kept as a number (digits): 17 significant digits round-trip a double.
MAX_NUMBER_CHARS = 40

#: how a JSON type is named in a message
_KIND_NAMES = {dict: "an object", list: "a list", str: "a string", bool: "a boolean"}


class LongNumber:
    """A number literal longer than :data:`MAX_NUMBER_CHARS`, kept unconverted.

    Neither an int nor a float: the check of the field that holds it fails and names it.
    """

    def __init__(self, text: str) -> None:
        self.chars = len(text)

    def __repr__(self) -> str:
        return f"<a number of {self.chars} characters; at most {MAX_NUMBER_CHARS}>"


def json_depth(text: str) -> int:
    """The deepest nesting of arrays and objects in JSON ``text`` (brackets in strings skipped)."""
    depth = deepest = 0
    in_string = escaped = False
    for ch in text:
        if in_string:
            if escaped:
                escaped = False
            elif ch == "\\":
                escaped = True
            elif ch == '"':
                in_string = False
            continue
        if ch == '"':
            in_string = True
        elif ch in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif ch in "]}":
            depth -= 1
    return deepest


def bounded_json(
    text: str,
    *,
    max_bytes: int,
    max_depth: int,
    error: type[ValueError],
    what: str,
    constants: dict[str, float] | None = None,
    long_numbers: bool = True,
) -> Any:
    """JSON with limits on size and nesting; too long numbers become :class:`LongNumber`.

    Parameters
    ----------
    text : str
        The JSON text.
    max_bytes, max_depth : int
        Longest text and deepest nesting of arrays and objects accepted.
    error : type
        The exception raised (a ``ValueError`` subclass taking one message).
    what : str
        What the text is, for the messages (e.g. ``"model file 'm.json'"``).
    constants : dict, optional
        Values of ``NaN``, ``Infinity`` and ``-Infinity`` (default: refused).
    long_numbers : bool
        Keep a number literal of more than :data:`MAX_NUMBER_CHARS` characters as a
        :class:`LongNumber` (the field check that meets it names the field); ``False``:
        refuse the text.

    Raises
    ------
    error
        Too large, nested too deeply, or not JSON (the message says where).
    """
    if len(text) > max_bytes:
        raise error(f"{what} is {len(text)} bytes; at most {max_bytes} are read.")
    if json_depth(text) > max_depth:
        raise error(f"{what} is nested deeper than {max_depth} levels; it is not one clpc wrote.")

    def constant(name: str) -> float:
        if constants is None or name not in constants:
            raise error(f"{what} holds {name}, which is not a number allowed here.")
        return constants[name]

    def number(convert: Callable[[str], Any]) -> Callable[[str], Any]:
        def parse(text: str) -> Any:
            if len(text) <= MAX_NUMBER_CHARS:
                return convert(text)
            if long_numbers:
                return LongNumber(text)
            raise error(
                f"{what} holds a number of {len(text)} characters; at most {MAX_NUMBER_CHARS}."
            )

        return parse

    try:
        return json.loads(
            text, parse_float=number(float), parse_int=number(int), parse_constant=constant
        )
    except json.JSONDecodeError as exc:
        raise error(
            f"{what} is not valid JSON ({exc.msg} at line {exc.lineno}, column {exc.colno}); "
            "the file is corrupted or truncated - save it again."
        ) from None


def short(value: Any, chars: int = 60) -> str:
    """``repr(value)``, cut to ``chars`` characters with an ellipsis (for messages)."""
    text = repr(value)
    return text if len(text) <= chars else text[: chars - 3] + "..."


def _numbers_only(value: Any) -> bool:
    if isinstance(value, list):
        return all(_numbers_only(v) for v in value)
    return isinstance(value, (int, float)) and not isinstance(value, bool)


@dataclass(frozen=True)
class Fields:
    """Checks of decoded JSON fields; each failure is ``error(where + message)``.

    Parameters
    ----------
    error : type
        The exception raised (a ``ValueError`` subclass taking one message).
    where : str
        Prefix of every message, e.g. ``"model file 'm.json': "``.
    whole : str
        What an incomplete one is, for a missing field (e.g. ``"the file"``).
    """

    error: type[ValueError]
    where: str = ""
    whole: str = "the file"

    def fail(self, message: str) -> ValueError:
        """The error to raise, with :attr:`where` in front of ``message``."""
        return self.error(f"{self.where}{message}")

    def require(self, d: dict[str, Any], key: str, name: str | None = None) -> Any:
        """``d[key]``; a missing key (``name`` in the message) is an incomplete file."""
        if key not in d:
            field = repr(key) if name is None else name
            raise self.fail(f"the required field {field} is missing; {self.whole} is incomplete.")
        return d[key]

    def kind(self, value: Any, name: str, kind: type) -> Any:
        """``value``, which must be a ``kind`` (``dict``: a JSON object, ``list``, ``str``)."""
        if not isinstance(value, kind):
            what = _KIND_NAMES.get(kind, kind.__name__)
            raise self.fail(f"{name} must be {what}; got {type(value).__name__}.")
        return value

    def integer(self, value: Any, name: str, low: int | None = None) -> int:
        """``value``, an int (a bool is none) of at least ``low``."""
        if (
            isinstance(value, bool)
            or not isinstance(value, int)
            or (low is not None and value < low)
        ):
            bound = "" if low is None else f" >= {low}"
            raise self.fail(f"{name} must be an integer{bound}; got {short(value)}.")
        return value

    def positive(self, value: Any, name: str, unit: str) -> float:
        """``value`` as a finite float > 0 (an int no float holds fails too)."""
        x = math.nan
        if not isinstance(value, bool) and isinstance(value, (int, float)):
            try:
                x = float(value)
            except OverflowError:
                pass
        if not (math.isfinite(x) and x > 0):
            raise self.fail(f"{name} must be a positive number of {unit}; got {short(value)}.")
        return x

    def strings(self, value: Any, name: str, n: int) -> tuple[str, ...]:
        """A list of ``n`` strings (channel names) as a tuple."""
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise self.fail(f"{name} must be a list of strings; got {short(value)}.")
        if len(value) != n:
            raise self.fail(f"{name} must name {n} channel(s); got {len(value)}: {value}.")
        return tuple(value)

    def shaped(self, arr: np.ndarray, name: str, shape: Sequence[int | None]) -> np.ndarray:
        """``arr``, which must have ``shape`` (``None``: any size along that axis)."""
        want = tuple(shape)
        if arr.ndim != len(want) or any(
            w is not None and g != w for g, w in zip(arr.shape, want, strict=False)
        ):
            raise self.fail(f"{name} must have shape {want}; got {arr.shape}.")
        return arr

    def floats(
        self,
        value: Any,
        name: str,
        shape: Sequence[int | None],
        *,
        finite: bool = True,
        max_abs: float | None = None,
    ) -> np.ndarray:
        """A (nested) list of numbers as a float array of ``shape`` (``None``: any size).

        Numbers only (no bool, no string); with ``finite``, no NaN or infinity; with
        ``max_abs``, no magnitude above it (larger values overflow later computations).
        """
        want = tuple(shape)
        try:
            ok = _numbers_only(value)
            arr = np.array(value, dtype=np.float64) if ok else None
        except (ValueError, OverflowError, RecursionError):  # ragged, a huge int, deep
            arr = None
        if arr is None:
            raise self.fail(
                f"{name} must be a (nested) list of numbers of shape {want}; got {short(value)}."
            )
        self.shaped(arr, name, want)
        if finite and not np.all(np.isfinite(arr)):
            raise self.fail(
                f"{name} holds non-finite values; it must hold finite numbers: "
                f"{short(arr.tolist(), 80)}."
            )
        if max_abs is not None and arr.size and np.abs(arr).max() > max_abs:
            raise self.fail(
                f"{name} holds {np.abs(arr).max():.3g}; values beyond {max_abs:.0e} overflow "
                "double precision when the model is used (the file was edited or damaged)."
            )
        return arr
