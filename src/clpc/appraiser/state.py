"""Saving and restoring an appraiser: its FSM state and configuration as JSON-safe data.

The state is the paper's: the last window of samples, the counter (samples and updates
seen), the last parameters, plus the decimation filter's state. Floats round-trip exactly.
"""

from __future__ import annotations

import json
from dataclasses import asdict
from typing import Any

import numpy as np

from clpc.appraiser.buffer import SampleBuffer
from clpc.appraiser.decimation import Decimator
from clpc.core.rules import RobustRule

__all__ = ["FORMAT", "VERSION", "config_of", "load", "restore", "save", "snapshot"]

FORMAT = "clpc-appraiser-state"
VERSION = 1


def _arr(x: np.ndarray | None) -> Any:
    return None if x is None else {"shape": list(x.shape), "data": x.ravel().tolist()}


def _unarr(x: Any) -> np.ndarray | None:
    return None if x is None else np.asarray(x["data"], float).reshape(x["shape"])


def config_of(a: Any) -> dict[str, Any]:
    """The constructor arguments of appraiser ``a`` (JSON-safe)."""
    return {
        "parameters_size": a.parameters_size,
        "window_size": a.window_size,
        "cluster_size": a.cluster_size,
        "sample_time": a.sample_time,
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
        "data_sample_time": a.data_sample_time,
        "n_jobs": a.n_jobs,
        "chunk_samples": a.chunk_samples,
        "engine": a._engine_request,
    }


def snapshot(a: Any) -> dict[str, Any]:
    """The state of appraiser ``a`` (see :meth:`clpc.CLPC.state_dict`)."""
    buf = a._buffer
    if buf is not None:
        buf.flush()
    dec = a._decimator
    return {
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


def restore(cls: Any, state: dict[str, Any]) -> Any:
    """An appraiser of class ``cls`` that continues exactly where ``state`` left off."""
    if state.get("format") != FORMAT or state.get("version") != VERSION:
        raise ValueError("not a clpc appraiser state (format/version mismatch).")
    cfg = dict(state["config"])
    size = cfg.pop("parameters_size")
    if "gate" in cfg:  # states written before the guard was renamed
        cfg["guard"] = cfg.pop("gate")
    rule = RobustRule(**cfg.pop("rule"))
    a = cls(size, rule=rule, **cfg)
    a._n_in, a._n_out = state["n_in"], state["n_out"]
    a._names = None if state["names"] is None else tuple(tuple(n) for n in state["names"])
    if a._n_in is not None:
        a._buffer = SampleBuffer(a._n_in + a._n_out)
        data = _unarr(state["buf"])
        if data is not None and data.size:
            a._buffer.data = data
        a._buffer.start = int(state["buf_start"])
    a._n_seen = int(state["n_seen"])
    a._j_done = int(state["j_done"])
    a._last_theta = _unarr(state["last_theta"])
    a._last_c = _unarr(state["last_c"])
    hm = state["has_model"]
    a._has_model = None if hm is None else np.asarray(hm, dtype=bool)
    if state["factor"] is not None:
        a._decimator = Decimator(int(state["factor"]))
        a._decimator.zi = _unarr(state["dec_zi"])
        a._decimator.phase = int(state["dec_phase"])
    a._record_dt = state.get("record_dt")
    return a


def save(a: Any, path: str) -> None:
    """Write the state of ``a`` as JSON to ``path``."""
    with open(path, "w", encoding="utf-8") as fh:
        json.dump(snapshot(a), fh)


def load(cls: Any, path: str) -> Any:
    """Read an appraiser saved with :func:`save`."""
    with open(path, encoding="utf-8") as fh:
        return restore(cls, json.load(fh))
