"""What a saved appraiser state must satisfy before any of it reaches compiled code.

A state is JSON written by :meth:`clpc.CLPC.state_dict`. Read from a file it may be
damaged or edited; the kernel indexes the sample buffer by the counters without bounds
checks, so every field is checked here - types, shapes, bounds and the counters against the
buffer and the window - and a violation is a :class:`StateError` naming the field.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from clpc._schema import Fields, bounded_json, short

__all__ = [
    "FORMAT",
    "MAX_STATE_BYTES",
    "VERSION",
    "StateError",
    "check_digest",
    "check_header",
    "checked_array",
    "checked_decimator",
    "checked_flags",
    "checked_names",
    "digest",
    "field",
    "parse_json",
    "reading_state",
    "validate_counters",
]

FORMAT = "clpc-appraiser-state"
VERSION = 1

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


def digest(state: dict[str, Any]) -> str:
    """SHA-256 of a state's content (every field but ``digest``), canonical JSON."""
    body = {k: v for k, v in state.items() if k != "digest"}
    text = json.dumps(body, sort_keys=True, separators=(",", ":"), allow_nan=True)
    return hashlib.sha256(text.encode()).hexdigest()


def check_digest(state: dict[str, Any]) -> None:
    """The state is the one saved: any edit that passed the schema would change results."""
    stored = field(state, "digest", str)
    try:
        fresh = digest(state)
    except (TypeError, ValueError) as exc:
        raise StateError(f"the state holds values JSON cannot hold: {exc}") from None
    if stored != fresh:
        raise StateError(
            "state['digest'] does not match the state's content: the state was edited or "
            "damaged after it was saved (an edited sample, counter or setting would change "
            "the results without a word); save it again from the appraiser."
        )


def checked_names(names: Any, n_in: int, n_out: int) -> tuple[tuple[str, ...], ...] | None:
    """``state['names']``: ``None`` or [input names, output names] of the right counts."""
    if names is None:
        return None
    ok = (
        isinstance(names, list)
        and len(names) == 2
        and all(isinstance(g, list) and all(isinstance(n, str) for n in g) for g in names)
        and (len(names[0]), len(names[1])) == (n_in, n_out)
    )
    if not ok:
        raise StateError(f"state['names'] must be [{n_in} input names, {n_out} output names].")
    return tuple(names[0]), tuple(names[1])


def checked_flags(flags: Any, last_theta: np.ndarray) -> np.ndarray:
    """``state['has_model']``: one bool per output; an output with a model has a0 != 0."""
    n_out = last_theta.shape[0]
    if not isinstance(flags, list) or len(flags) != n_out:
        raise StateError(f"state['has_model'] must be {n_out} booleans; got {flags!r:.60}.")
    if not all(isinstance(x, bool) for x in flags):
        raise StateError(f"state['has_model'] must be {n_out} booleans; got {flags!r:.60}.")
    has_model = np.asarray(flags, dtype=bool)
    if np.any(has_model & ~(np.abs(last_theta[:, 0]) > 0)):
        raise StateError("state['last_theta'] has a0 = 0 for an output with a model.")
    return has_model


def checked_decimator(
    state: dict[str, Any], channels: int, decimate_to: float | None
) -> tuple[int, np.ndarray | None, int]:
    """``(factor, filter state, phase)`` of the saved decimator (``decimate_to``: the target)."""
    factor = field(state, "factor", int)
    if factor < 1 or (factor > 1 and decimate_to is None):
        raise StateError(
            f"state['factor']={factor}: decimation needs factor >= 1, and a factor above 1 "
            "needs a decimate_to to decimate to."
        )
    zi = None
    if factor > 1 and state.get("dec_zi") is not None:
        zi = checked_array(state["dec_zi"], "dec_zi", (2, 2, channels))
    phase = field(state, "dec_phase", int)
    if not 0 <= phase < factor:
        raise StateError(f"state['dec_phase'] must be in [0, {factor}); got {phase}.")
    return factor, zi, phase


def check_header(state: Any) -> None:
    """A JSON object of this format and version."""
    if not isinstance(state, dict):
        raise StateError(f"a state must be a JSON object; got {type(state).__name__}.")
    if state.get("format") != FORMAT or state.get("version") != VERSION:
        raise StateError("not a clpc appraiser state (format/version mismatch).")


@contextmanager
def reading_state() -> Iterator[None]:
    """Any failure while a state is read becomes a :class:`StateError`."""
    try:
        yield
    except StateError:
        raise
    except (TypeError, ValueError, KeyError, OverflowError, RecursionError) as exc:
        raise StateError(f"the state does not describe an appraiser: {exc}") from None
    except MemoryError:
        raise StateError(
            "the state's settings (state['config']: window_size, parameters) need more memory "
            "than is available; it is not a state this machine saved."
        ) from None
