"""The appraiser's saved form: its state as JSON-safe data, every field checked when read.

:func:`saved_form` is what :meth:`clpc.CLPC.state_dict` returns - format, version, the
settings, the FSM state of an :class:`~clpc.appraiser.state.AppraiserState` (floats
round-trip exactly) and a digest; :func:`restored` reads it back, every field checked
(:mod:`clpc.appraiser.state_schema`). Its JSON file: :mod:`clpc.appraiser.state_file`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.appraiser.decimation import Decimator
from clpc.appraiser.settings import Settings
from clpc.appraiser.state import AppraiserState
from clpc.appraiser.state_schema import (
    FORMAT,
    VERSION,
    StateError,
    check_digest,
    check_header,
    checked_array,
    checked_decimator,
    checked_flags,
    checked_names,
    digest,
    field,
    reading_state,
    validate_counters,
)
from clpc.core.checks import check_positive

__all__ = ["restored", "saved_form"]


def saved_form(config: dict[str, Any], state: AppraiserState) -> dict[str, Any]:
    """An appraiser's state and configuration as a JSON-safe dict, with its digest.

    Parameters
    ----------
    config : dict
        The appraiser's constructor arguments (:meth:`Settings.config`).
    state : AppraiserState
        Its FSM state (pending samples are moved into the buffer first).
    """
    out = {"format": FORMAT, "version": VERSION, "config": config}
    out.update(_fields(state))
    out["digest"] = digest(out)
    return out


def restored(saved: dict[str, Any]) -> AppraiserState:
    """The state (with its settings) that :func:`saved_form` saved; it continues identically.

    Parameters
    ----------
    saved : dict
        What :func:`saved_form` returned (e.g. decoded from a state file).

    Raises
    ------
    StateError
        A damaged or edited state: every field is checked first and the error names it.
    """
    with reading_state():
        check_header(saved)
        settings = Settings.from_config(field(saved, "config", dict))
        state = _from_fields(settings, saved)
        check_digest(saved)
    return state


def _fields(state: AppraiserState) -> dict[str, Any]:
    """The FSM state as JSON-safe data (floats round-trip exactly), without the settings."""
    buf, dec = state.buffer, state.decimator
    if buf is not None:
        buf.flush()
    return {
        "n_in": state.n_in,
        "n_out": state.n_out,
        "names": None if state.names is None else [list(n) for n in state.names],
        "buf": _arr(np.empty((0, 0)) if buf is None else buf.data),
        "buf_start": 0 if buf is None else buf.start,
        "n_seen": state.n_seen,
        "j_done": state.j_done,
        "last_theta": _arr(state.last_theta),
        "last_c": _arr(state.last_c),
        "has_model": None if state.has_model is None else state.has_model.tolist(),
        "factor": None if dec is None else dec.factor,
        "dec_zi": None if dec is None else _arr(dec.zi),
        "dec_phase": 0 if dec is None else dec.phase,
        "record_dt": state.record_dt,
    }


def _from_fields(settings: Settings, saved: dict[str, Any]) -> AppraiserState:
    """The state saved by :func:`_fields`, every field checked (:class:`StateError`)."""
    new = AppraiserState(settings)
    n_in, n_out = saved.get("n_in"), saved.get("n_out")
    n_seen, j_done = field(saved, "n_seen", int), field(saved, "j_done", int)
    if n_in is None or n_out is None:
        if n_in is not None or n_out is not None or n_seen or j_done:
            raise StateError("a state without channels (n_in, n_out) must have seen nothing.")
        return new
    n_in, n_out = field(saved, "n_in", int), field(saved, "n_out", int)
    if n_in < 1 or n_out < 1:
        raise StateError(f"n_in and n_out must be >= 1; got {n_in}, {n_out}.")
    new.init_channels(n_in, n_out, checked_names(saved.get("names"), n_in, n_out))
    buf = checked_array(field(saved, "buf", dict), "buf", (None, n_in + n_out))
    start = field(saved, "buf_start", int)
    sizes = (new.max_lag, settings.window_size, settings.cluster_size)
    validate_counters((n_seen, j_done, start, buf.shape[0]), sizes)
    p = new.n_params()
    last_theta = checked_array(saved.get("last_theta"), "last_theta", (n_out, p))
    last_c = checked_array(saved.get("last_c"), "last_c", (n_out,))
    has_model = checked_flags(saved.get("has_model"), last_theta)
    if saved.get("factor") is not None:
        new.set_decimator(Decimator(*checked_decimator(saved, n_in + n_out, settings.decimate_to)))
    record_dt = saved.get("record_dt")
    if record_dt is not None:
        record_dt = check_positive(record_dt, "state['record_dt']", "s")
    new.resume((buf, start), (n_seen, j_done), (last_theta, last_c, has_model), record_dt)
    return new


def _arr(x: np.ndarray | None) -> Any:
    return None if x is None else {"shape": list(x.shape), "data": x.ravel().tolist()}
