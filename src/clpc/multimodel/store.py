"""Saving a :class:`clpc.MultiModel` as JSON; loading it back simulates bit for bit.

Every float is written with Python's shortest round-tripping ``repr`` (``json``'s
default), so the loaded local models have the same ``theta`` and ``c`` bits and therefore
the same monic coefficients and the same free run. An infinite width (a single model) is
written as ``null``. A callable schedule cannot be saved.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from clpc.core.atomic import write_file
from clpc.core.jsonable import jsonable
from clpc.model import LinearModel
from clpc.multimodel.fitting import Fitted

__all__ = ["FORMAT", "from_dict", "load", "save", "to_dict"]

FORMAT = "clpc-multimodel"
VERSION = 1


def to_dict(mm: Any) -> dict[str, Any]:
    """The fitted multi-model as a JSON-safe dict."""
    models, centres, widths = mm.local_models, mm.centres, mm.widths
    if callable(mm.schedule_spec):
        raise ValueError(
            "a multi-model scheduled on a Python callable cannot be saved to JSON; use "
            "schedule='y', 'u' or a lag-vector column."
        )
    s = mm.structure
    return {
        "format": FORMAT,
        "version": VERSION,
        "structure": {"na": s.na, "nb": s.nb, "nk": s.nk},
        "n_inputs": mm.n_inputs,
        "dt": mm.dt,
        "schedule": mm.schedule_spec,
        "settings": dict(mm.settings),
        "centres": [float(c) for c in centres],
        "widths": [None if not math.isfinite(w) else float(w) for w in widths],
        "local_models": [
            {
                "theta": [float(v) for v in np.atleast_2d(m.theta)[0]],
                "c": float(np.atleast_1d(m.c)[0]),
                "estimator": m.info.get("estimator"),
                "replaced": bool(m.info.get("replaced", False)),
                "weight": float(m.info.get("weight", 0.0)),
            }
            for m in models
        ],
        "diagnostics": jsonable(mm.diagnostics),
    }


def _field(data: dict[str, Any], key: str, where: str = "the file") -> Any:
    """``data[key]``, or a ValueError naming the missing field."""
    if not isinstance(data, dict) or key not in data:
        raise ValueError(f"{where} has no {key!r} field; it is not a multi-model clpc wrote.")
    return data[key]


def _finite(values: Any, name: str) -> np.ndarray:
    """``values`` as a float64 array, or a ValueError when an entry is not a finite number."""
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must hold numbers; got {values!r:.80}.") from None
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite; got {arr.ravel()[:6]} (NaN or inf).")
    return arr


def from_dict(cls: Any, data: dict[str, Any]) -> Any:
    """Rebuild a multi-model (``cls``) from :func:`to_dict` output; checks the format.

    Every field is checked before use: a missing field, a local model whose theta has the
    wrong length or a non-finite entry, non-finite centres, widths that are not positive (or
    null for an unbounded one), a sample time that is not positive: a ValueError that says
    which.
    """
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise ValueError(
            f"not a clpc multi-model: expected a JSON object with format {FORMAT!r}; got "
            f"{data.get('format') if isinstance(data, dict) else type(data).__name__!r}."
        )
    if data.get("version") != VERSION:
        raise ValueError(
            f"unsupported multi-model version {data.get('version')!r}; this clpc reads {VERSION}."
        )
    s = _field(data, "structure")
    settings = dict(_field(data, "settings"))
    settings.pop("engine", None)  # files written while the free run had an engine setting
    orders = {key: _field(s, key, "structure") for key in ("na", "nb", "nk")}
    mm = cls(**orders, schedule=_field(data, "schedule"), **settings)
    n_inputs, dt = _field(data, "n_inputs"), float(_finite(_field(data, "dt"), "dt"))
    if not (isinstance(n_inputs, int) and n_inputs >= 1) or dt <= 0:
        raise ValueError(f"n_inputs must be an int >= 1 and dt > 0; got {n_inputs!r}, {dt!r}.")
    mm.n_inputs, mm.dt = n_inputs, dt
    structure = mm.structure
    models = []
    for k, item in enumerate(_field(data, "local_models")):
        where = f"local model {k}"
        theta = _finite(_field(item, "theta", where), f"{where}'s theta")
        if theta.shape != (structure.n_params(mm.n_inputs),):
            want = structure.n_params(mm.n_inputs)
            raise ValueError(f"a local model's theta has {theta.size} entries; expected {want}.")
        models.append(
            LinearModel(
                theta=theta[None, :],
                structure=structure,
                n_inputs=mm.n_inputs,
                mode="siso" if mm.n_inputs == 1 else "miso",
                c=_finite([_field(item, "c", where)], f"{where}'s c"),
                dt=mm.dt,
                info={key: item.get(key) for key in ("estimator", "replaced", "weight")},
            )
        )
    raw_widths = _field(data, "widths")
    widths = np.array([math.inf if w is None else _finite(w, "widths") for w in raw_widths])
    if not np.all(widths > 0):
        raise ValueError(f"widths must be positive (null: unbounded); got {raw_widths!r:.80}.")
    centres = _finite(_field(data, "centres"), "centres")
    if not (centres.ndim == 1 and centres.size == widths.size == len(models) >= 1):
        raise ValueError("centres, widths and local_models must have the same (nonzero) length.")
    fitted = Fitted(models, centres, widths, dict(data.get("diagnostics") or {}))
    return mm.install_fit(fitted, mm.n_inputs, mm.dt)


def save(mm: Any, path: Any) -> None:
    """Write the multi-model as JSON to ``path``."""
    write_file(path, json.dumps(to_dict(mm), indent=1))  # atomic: see clpc.core.atomic


def load(cls: Any, path: Any) -> Any:
    """Read a multi-model written by :func:`save`."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path} is not valid JSON: {exc}") from None
    return from_dict(cls, data)
