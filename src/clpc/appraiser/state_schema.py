"""What a saved appraiser state must satisfy before any of it reaches compiled code.

A state is JSON written by :func:`clpc.appraiser.state.snapshot`. Read from a file it may be
damaged or edited; the kernel indexes the sample buffer by the counters without bounds
checks, so every field is checked here - types, shapes, bounds and the counters against the
buffer and the window - and a violation is a :class:`StateError` naming the field.
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

__all__ = [
    "MAX_STATE_BYTES",
    "LongNumber",
    "StateError",
    "bounded_json",
    "checked_array",
    "field",
    "parse_json",
    "validate_counters",
]

#: Largest state file read (bytes): a state holds one window of samples, a few MB at most.
MAX_STATE_BYTES = 256 * 2**20
#: Deepest JSON nesting accepted (a state is nested three levels).
MAX_DEPTH = 16
#: Longest number literal accepted (digits): 17 significant digits round-trip a double.
MAX_NUMBER_CHARS = 40


class StateError(ValueError):
    """A saved appraiser state that cannot be used; the message names the field."""


class LongNumber:
    """A number literal longer than :data:`MAX_NUMBER_CHARS`, kept unconverted.

    Neither an int nor a float: the check of the field that holds it fails and names it.
    """

    def __init__(self, text: str) -> None:
        self.chars = len(text)

    def __repr__(self) -> str:
        return f"<a number of {self.chars} characters; at most {MAX_NUMBER_CHARS}>"


def _number(text: str) -> float:
    if len(text) > MAX_NUMBER_CHARS:
        raise StateError(f"a number of {len(text)} characters; at most {MAX_NUMBER_CHARS}.")
    return float(text)


def _integer(text: str) -> int:
    if len(text) > MAX_NUMBER_CHARS:
        raise StateError(f"an integer of {len(text)} digits; at most {MAX_NUMBER_CHARS}.")
    return int(text)


def _marked_number(text: str) -> float | LongNumber:
    return LongNumber(text) if len(text) > MAX_NUMBER_CHARS else float(text)


def _marked_integer(text: str) -> int | LongNumber:
    return LongNumber(text) if len(text) > MAX_NUMBER_CHARS else int(text)


def bounded_json(
    text: str,
    *,
    max_bytes: int,
    max_depth: int,
    error: type[ValueError],
    what: str,
    constants: dict[str, float] | None = None,
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

    Raises
    ------
    error
        Too large, nested too deeply, or not JSON (the message says where).
    """
    if len(text) > max_bytes:
        raise error(f"{what} is {len(text)} bytes; at most {max_bytes} are read.")
    if _depth(text) > max_depth:
        raise error(f"{what} is nested deeper than {max_depth} levels; it is not one clpc wrote.")

    def constant(name: str) -> float:
        if constants is None or name not in constants:
            raise error(f"{what} holds {name}, which is not a number allowed here.")
        return constants[name]

    try:
        return json.loads(
            text, parse_float=_marked_number, parse_int=_marked_integer, parse_constant=constant
        )
    except json.JSONDecodeError as exc:
        raise error(
            f"{what} is not valid JSON ({exc.msg} at line {exc.lineno}, column {exc.colno}); "
            "the file is corrupted or truncated - save it again."
        ) from None


def _depth(text: str) -> int:
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


def parse_json(text: str) -> Any:
    """JSON with limits on size, nesting depth and number length (:class:`StateError`)."""
    if len(text) > MAX_STATE_BYTES:
        raise StateError(f"the state is {len(text)} bytes; at most {MAX_STATE_BYTES}.")
    if _depth(text) > MAX_DEPTH:
        raise StateError(f"the state is nested deeper than {MAX_DEPTH} levels.")
    try:
        return json.loads(text, parse_float=_number, parse_int=_integer, parse_constant=_number)
    except json.JSONDecodeError as exc:
        raise StateError(f"the state is not JSON: {exc}.") from None


def field(state: dict[str, Any], key: str, kind: Any, where: str = "state") -> Any:
    """``state[key]``, which must exist and be of ``kind`` (bool is no int here)."""
    if key not in state:
        raise StateError(f"{where} has no field {key!r}.")
    value = state[key]
    if kind is int and (isinstance(value, bool) or not isinstance(value, int)):
        raise StateError(f"{where}[{key!r}] must be an integer; got {value!r:.60}.")
    if kind is not int and not isinstance(value, kind):
        raise StateError(f"{where}[{key!r}] must be {kind}; got {type(value).__name__}.")
    return value


def checked_array(
    value: Any, name: str, shape: tuple[int | None, ...], finite: bool = True
) -> np.ndarray:
    """``{"shape": [...], "data": [...]}`` as a float array of ``shape`` (None: any length)."""
    if not isinstance(value, dict) or set(value) != {"shape", "data"}:
        raise StateError(f"state[{name!r}] must be an object with 'shape' and 'data'.")
    dims, data = value["shape"], value["data"]
    if not isinstance(dims, list) or not all(
        isinstance(d, int) and not isinstance(d, bool) and d >= 0 for d in dims
    ):
        raise StateError(f"state[{name!r}]['shape'] must be a list of sizes; got {dims!r:.60}.")
    if not isinstance(data, list) or len(data) != math.prod(dims):
        raise StateError(f"state[{name!r}] holds {len(data)} values for shape {dims}.")
    if len(dims) != len(shape) or any(
        want is not None and got != want for got, want in zip(dims, shape, strict=False)
    ):
        raise StateError(f"state[{name!r}] must have shape {shape}; got {tuple(dims)}.")
    if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in data):
        raise StateError(f"state[{name!r}] must hold numbers only.")
    try:
        arr = np.asarray(data, dtype=np.float64).reshape(dims)
    except OverflowError:
        raise StateError(f"state[{name!r}] holds an integer no float can hold.") from None
    if finite and not np.all(np.isfinite(arr)):
        raise StateError(f"state[{name!r}] holds non-finite values.")
    return arr


def validate_counters(counts: tuple[int, int, int, int], sizes: tuple[int, int, int]) -> None:
    """The counters against the buffer and the window.

    ``counts = (n_seen, j_done, buf_start, buf_rows)`` and ``sizes = (max_lag, window,
    cluster)``: the buffer must hold exactly the samples from ``buf_start`` to ``n_seen``,
    ``j_done`` must be the updates those samples completed, and the buffer must start at
    the first sample the next window needs (what the appraiser keeps).
    """
    n_seen, j_done, buf_start, rows = counts
    max_lag, window, cluster = sizes
    if min(counts) < 0:
        raise StateError(f"n_seen, j_done and buf_start must be >= 0; got {counts[:3]}.")
    if buf_start + rows != n_seen:
        raise StateError(
            f"the buffer holds samples {buf_start} .. {buf_start + rows - 1} but n_seen is "
            f"{n_seen}: they must end together."
        )
    if j_done != max(n_seen - max_lag, 0) // cluster:
        raise StateError(
            f"j_done={j_done} does not match n_seen={n_seen} (cluster {cluster}, max lag "
            f"{max_lag}: {max(n_seen - max_lag, 0) // cluster} updates)."
        )
    needed = max(0, cluster * (j_done + 1) - window - cluster)
    if buf_start != needed:
        raise StateError(
            f"buf_start={buf_start}: an appraiser with window {window} and cluster {cluster} "
            f"keeps samples from {needed} on after {j_done} updates (a changed setting?)."
        )
