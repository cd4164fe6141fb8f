"""What a saved appraiser state must satisfy before any of it reaches compiled code.

A state is JSON written by :func:`clpc.appraiser.state.snapshot`. Read from a file it may be
damaged or edited; the kernel indexes the sample buffer by the counters without bounds
checks, so every field is checked here - types, shapes, bounds and the counters against the
buffer and the window - and a violation is a :class:`StateError` naming the field.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from clpc._schema import Fields, bounded_json, short

__all__ = [
    "MAX_STATE_BYTES",
    "StateError",
    "checked_array",
    "field",
    "parse_json",
    "validate_counters",
]

#: Largest state file read (bytes): a state holds one window of samples, a few MB at most.
MAX_STATE_BYTES = 256 * 2**20
#: Deepest JSON nesting accepted (a state is nested three levels).
MAX_DEPTH = 16


class StateError(ValueError):
    """A saved appraiser state that cannot be used; the message names the field."""


#: the checks of :mod:`clpc._schema`, as StateError (fields are named ``state['key']``)
_FIELDS = Fields(StateError, whole="the state")


def parse_json(text: str) -> Any:
    """JSON with limits on size, nesting depth and number length (:class:`StateError`)."""
    nonfinite = {"NaN": math.nan, "Infinity": math.inf, "-Infinity": -math.inf}
    return bounded_json(
        text,
        max_bytes=MAX_STATE_BYTES,
        max_depth=MAX_DEPTH,
        error=StateError,
        what="the state",
        constants=nonfinite,  # refused where they matter: arrays must be finite
        long_numbers=False,
    )


def field(state: dict[str, Any], key: str, kind: Any, where: str = "state") -> Any:
    """``state[key]``, which must exist and be of ``kind`` (bool is no int here)."""
    name = f"{where}[{key!r}]"
    value = _FIELDS.require(state, key, name)
    if kind is int:
        return _FIELDS.integer(value, name)
    return _FIELDS.kind(value, name, kind)


def checked_array(
    value: Any, name: str, shape: tuple[int | None, ...], finite: bool = True
) -> np.ndarray:
    """``{"shape": [...], "data": [...]}`` as a float array of ``shape`` (None: any length)."""
    label = f"state[{name!r}]"
    if not isinstance(value, dict) or set(value) != {"shape", "data"}:
        raise StateError(f"{label} must be an object with 'shape' and 'data'.")
    dims, data = value["shape"], value["data"]
    if not isinstance(dims, list) or not all(
        isinstance(d, int) and not isinstance(d, bool) and d >= 0 for d in dims
    ):
        raise StateError(f"{label}['shape'] must be a list of sizes; got {short(dims)}.")
    if not isinstance(data, list) or len(data) != math.prod(dims):
        size = len(data) if isinstance(data, list) else type(data).__name__
        raise StateError(f"{label} holds {size} values for shape {dims}.")
    flat = _FIELDS.floats(data, label, (len(data),), finite=finite)
    return _FIELDS.shaped(flat.reshape(dims), label, shape)


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
