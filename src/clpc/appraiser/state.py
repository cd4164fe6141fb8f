"""Saving and restoring an appraiser: its FSM state and configuration as JSON-safe data.

The state is the paper's: the last window of samples, the counter (samples and updates
seen), the last parameters, plus the decimation filter's state. Floats round-trip exactly.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict
from typing import Any

import numpy as np

from clpc.appraiser import fsm
from clpc.appraiser.decimation import Decimator
from clpc.appraiser.state_schema import (
    MAX_STATE_BYTES,
    StateError,
    checked_array,
    field,
    parse_json,
    validate_counters,
)
from clpc.core.checks import check_positive
from clpc.core.rules import RobustRule

__all__ = [
    "FORMAT",
    "VERSION",
    "StateError",
    "config_of",
    "digest",
    "load",
    "restore",
    "save",
    "snapshot",
]

FORMAT = "clpc-appraiser-state"
VERSION = 1


def _arr(x: np.ndarray | None) -> Any:
    return None if x is None else {"shape": list(x.shape), "data": x.ravel().tolist()}


def config_of(a: Any) -> dict[str, Any]:
    """The constructor arguments of appraiser ``a`` (JSON-safe)."""
    return {
        "parameters_size": a.parameters_size,
        "window_size": a.window_size,
        "cluster_size": a.cluster_size,
        **({"sample_time": a.sample_time} if a._legacy_sample_time else {}),
        **({} if a._legacy_sample_time else {"decimate_to": a.sample_time}),
        "na": a.structure.na,
        "nb": a.structure.nb,
        "nk": a.structure.nk,
        "method": a.method,
        "scaling": a.scaling,
        "mimo": a.mimo,
        "noise_ratio": a.noise_ratio,
        "noise_cov": None if a.noise_cov is None else a.noise_cov.tolist(),
        "rule": asdict(a.rule),
        "guard": a.guard,
        "trust_rows": a.trust_rows,
        "min_rows": a.min_rows,
        "dt": a.data_sample_time,
        "n_jobs": a.n_jobs,
        "chunk_samples": a.chunk_samples,
    }


def digest(state: dict[str, Any]) -> str:
    """SHA-256 of a state's content (every field but ``digest``), canonical JSON."""
    body = {k: v for k, v in state.items() if k != "digest"}
    text = json.dumps(body, sort_keys=True, separators=(",", ":"), allow_nan=True)
    return hashlib.sha256(text.encode()).hexdigest()


def _check_digest(state: dict[str, Any]) -> None:
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


def snapshot(a: Any) -> dict[str, Any]:
    """The state of appraiser ``a`` (see :meth:`clpc.CLPC.state_dict`)."""
    buf = a._buffer
    if buf is not None:
        buf.flush()
    dec = a._decimator
    out: dict[str, Any] = {
        "format": FORMAT,
        "version": VERSION,
        "config": config_of(a),
        "n_in": a._n_in,
        "n_out": a._n_out,
        "names": None if a._names is None else [list(n) for n in a._names],
        "buf": _arr(np.empty((0, 0)) if buf is None else buf.data),
        "buf_start": 0 if buf is None else buf.start,
        "n_seen": a._n_seen,
        "j_done": a._j_done,
        "last_theta": _arr(a._last_theta),
        "last_c": _arr(a._last_c),
        "has_model": None if a._has_model is None else a._has_model.tolist(),
        "factor": None if dec is None else dec.factor,
        "dec_zi": None if dec is None else _arr(dec.zi),
        "dec_phase": 0 if dec is None else dec.phase,
        "record_dt": a._record_dt,
    }
    out["digest"] = digest(out)
    return out


def restore(cls: Any, state: Any) -> Any:
    """An appraiser of class ``cls`` that continues exactly where ``state`` left off.

    Every field is checked first (:mod:`clpc.appraiser.state_schema`); a damaged or edited
    state raises :class:`~clpc.appraiser.state_schema.StateError` naming the field.
    """
    try:
        return _restore(cls, state)
    except StateError:
        raise
    except (TypeError, ValueError, KeyError, OverflowError, RecursionError) as exc:
        raise StateError(f"the state does not describe an appraiser: {exc}") from None
    except MemoryError:
        raise StateError(
            "the state's settings (state['config']: window_size, parameters) need more memory "
            "than is available; it is not a state this machine saved."
        ) from None


def _restore(cls: Any, state: Any) -> Any:
    if not isinstance(state, dict):
        raise StateError(f"a state must be a JSON object; got {type(state).__name__}.")
    if state.get("format") != FORMAT or state.get("version") != VERSION:
        raise StateError("not a clpc appraiser state (format/version mismatch).")
    a = _configured(cls, field(state, "config", dict))
    n_in, n_out = state.get("n_in"), state.get("n_out")
    n_seen, j_done = field(state, "n_seen", int), field(state, "j_done", int)
    if n_in is None or n_out is None:
        if n_in is not None or n_out is not None or n_seen or j_done:
            raise StateError("a state without channels (n_in, n_out) must have seen nothing.")
        _check_digest(state)
        return a
    n_in, n_out = field(state, "n_in", int), field(state, "n_out", int)
    if n_in < 1 or n_out < 1:
        raise StateError(f"n_in and n_out must be >= 1; got {n_in}, {n_out}.")
    fsm.init_channels(a, n_in, n_out, _names(state.get("names"), n_in, n_out))
    buf = checked_array(field(state, "buf", dict), "buf", (None, n_in + n_out))
    start = field(state, "buf_start", int)
    sizes = (a.structure.max_lag, a.window_size, a.cluster_size)
    validate_counters((n_seen, j_done, start, buf.shape[0]), sizes)
    assert a._buffer is not None
    if buf.size:
        a._buffer.data = buf
    a._buffer.start = start
    a._n_seen, a._j_done = n_seen, j_done
    p = a._last_theta.shape[1]
    a._last_theta = checked_array(state.get("last_theta"), "last_theta", (n_out, p))
    a._last_c = checked_array(state.get("last_c"), "last_c", (n_out,))
    hm = state.get("has_model")
    if not isinstance(hm, list) or len(hm) != n_out or not all(isinstance(x, bool) for x in hm):
        raise StateError(f"state['has_model'] must be {n_out} booleans; got {hm!r:.60}.")
    a._has_model = np.asarray(hm, dtype=bool)
    if np.any(a._has_model & ~(np.abs(a._last_theta[:, 0]) > 0)):
        raise StateError("state['last_theta'] has a0 = 0 for an output with a model.")
    _restore_decimator(a, state, n_in + n_out)
    record_dt = state.get("record_dt")
    if record_dt is not None:
        a._record_dt = check_positive(record_dt, "state['record_dt']", "s")
    _check_digest(state)
    return a


def _configured(cls: Any, config: dict[str, Any]) -> Any:
    """A new appraiser from the saved constructor arguments (checked by the constructor)."""
    cfg = dict(config)
    size = cfg.pop("parameters_size", None)
    if "gate" in cfg:  # states written before the guard was renamed
        cfg["guard"] = cfg.pop("gate")
    cfg.pop("engine", None)  # states written while the kernel had an engine setting
    rule = cfg.pop("rule", None)
    if not isinstance(rule, dict):
        raise StateError("state['config']['rule'] must be an object of thresholds.")
    try:
        return cls(size, rule=RobustRule(**rule), **cfg)
    except (TypeError, ValueError) as exc:
        raise StateError(f"state['config'] does not describe an appraiser: {exc}") from None


def _names(names: Any, n_in: int, n_out: int) -> tuple[tuple[str, ...], ...] | None:
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


def _restore_decimator(a: Any, state: dict[str, Any], channels: int) -> None:
    factor = state.get("factor")
    if factor is None:
        return
    factor = field(state, "factor", int)
    if factor < 1 or (factor > 1 and a.sample_time is None):
        raise StateError(
            f"state['factor']={factor}: decimation needs factor >= 1, and a factor above 1 "
            "needs a sample_time to decimate to."
        )
    a._decimator = Decimator(factor)
    if factor > 1 and state.get("dec_zi") is not None:
        a._decimator.zi = checked_array(state["dec_zi"], "dec_zi", (2, 2, channels))
    phase = field(state, "dec_phase", int)
    if not 0 <= phase < factor:
        raise StateError(f"state['dec_phase'] must be in [0, {factor}); got {phase}.")
    a._decimator.phase = phase


def save(a: Any, path: str) -> None:
    """Write the state of ``a`` as JSON to ``path``."""
    with open(path, "w", encoding="utf-8") as fh:
        json.dump(snapshot(a), fh)


def load(cls: Any, path: str) -> Any:
    """Read an appraiser saved with :func:`save`."""
    with open(path, encoding="utf-8") as fh:
        text = fh.read(MAX_STATE_BYTES + 1)
    return restore(cls, parse_json(text))
