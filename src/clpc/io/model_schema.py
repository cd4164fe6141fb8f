"""The model file schema, and a :class:`~clpc.model.LinearModel` written into it.

Schema (``schema_version`` 1)::

    {
      "format": "clpc-model",
      "schema_version": 1,
      "clpc_version": "0.1.0",                      # informative
      "structure": {"na": 2, "nb": 2, "nk": 0},
      "mode": "siso" | "paired" | "miso",
      "n_inputs": 1,
      "n_outputs": 1,
      "dt": 0.01,                                   # sample time [s]
      "input_names": ["u"],
      "output_names": ["y"],
      "theta": [[a0, ..., a_na, b0, ..., b_nb]],    # (n_outputs, n_params), paper convention
      "c": [c],                                     # (n_outputs,)
      "den": [[1, a1/a0, ...]],                     # (n_outputs, na + 1), informative
      "num": [[[0, ..., -b0/a0, ...]]],             # (n_outputs, n_inputs, nk + nb + 1)
      "info": {"D": [...], "method": "robust", ...}
    }

``theta`` and ``c`` define the model; ``num``/``den`` (monic, ascending powers of
``z^-1``, :attr:`LinearModel.numerators`/:attr:`~LinearModel.denominators`) are written
for people and other tools, recomputed on load and checked against the stored copy (they
are ``null`` when ``a0`` is about 0). Floats are written with Python's shortest exact
``repr``, so ``theta``, ``c`` and ``dt`` come back bit for bit. Non-finite statistics in
``info`` are written as the strings ``"NaN"``, ``"Infinity"``, ``"-Infinity"`` (the file is
strict JSON); entries that are not numbers, strings, booleans, lists or dicts of them, or
arrays larger than 100 000 elements, are left out.

Reading a dict back (with every field checked) is :mod:`clpc.io.model_validation`; the
files themselves are :mod:`clpc.io.model_files`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from clpc.data import DataError
from clpc.model import LinearModel, ModelError

__all__ = ["FORMAT", "NONFINITE", "SCHEMA_VERSION", "ModelFileError", "model_to_dict"]

FORMAT = "clpc-model"
SCHEMA_VERSION = 1
#: how non-finite floats are spelled in a file
NONFINITE = {"NaN": math.nan, "Infinity": math.inf, "-Infinity": -math.inf}
_MAX_INFO_ELEMENTS = 100_000
_DROP = object()


class ModelFileError(DataError):
    """A model file or dict cannot be read as a clpc model (a :class:`DataError`)."""


def _float_to_json(x: float) -> float | str:
    if math.isfinite(x):
        return x
    return "NaN" if math.isnan(x) else ("Infinity" if x > 0 else "-Infinity")


def _json_safe(value: Any) -> Any:
    """A JSON-safe copy of ``value`` (numpy -> Python), or ``_DROP``."""
    if isinstance(value, np.ndarray):
        if value.size > _MAX_INFO_ELEMENTS or value.dtype.kind not in "biuf":
            return _DROP
        return _json_safe(value.tolist())
    if isinstance(value, np.generic):
        if value.dtype.kind not in "biufU":
            return _DROP
        return _json_safe(value.item())
    if value is None or isinstance(value, (bool, str, int)):
        return value
    if isinstance(value, float):
        return _float_to_json(value)
    if isinstance(value, (list, tuple)):
        items = [_json_safe(v) for v in value]
        return _DROP if any(v is _DROP for v in items) else items
    if isinstance(value, dict):
        out = {}
        for key, item in value.items():
            if not isinstance(key, (str, int)) or isinstance(key, bool):
                continue
            safe = _json_safe(item)
            if safe is not _DROP:
                out[str(key)] = safe
        return out
    return _DROP


def _finite_list(arr: np.ndarray, what: str) -> list[Any]:
    if not np.all(np.isfinite(arr)):
        raise ModelFileError(f"cannot save the model: {what} holds non-finite values {arr}.")
    values: list[Any] = arr.tolist()
    return values


def model_to_dict(model: LinearModel) -> dict[str, Any]:
    """The JSON-ready description of a model (schema version 1; see the module doc).

    Parameters
    ----------
    model : LinearModel
        The model to describe.

    Returns
    -------
    dict
        Plain Python values only (``json.dumps`` works on it directly, strict JSON). The
        evidence a fit offers on demand (held-out fit, residual tests, covariance) is
        computed first (:meth:`LinearModel.assess`): a saved model carries it.

    Raises
    ------
    ModelFileError
        ``theta``, ``c`` or ``dt`` are not finite.
    """
    from clpc._version import __version__

    model.assess()
    s = model.structure
    dt = float(model.dt)
    if not (math.isfinite(dt) and dt > 0):
        raise ModelFileError(f"cannot save the model: dt must be a positive number; got {dt!r}.")
    try:
        num: Any = model.numerators.tolist()
        den: Any = model.denominators.tolist()
    except ModelError:  # a0 about 0: no monic form
        num = den = None
    info = _json_safe(dict(model.info)) if isinstance(model.info, dict) else {}
    return {
        "format": FORMAT,
        "schema_version": SCHEMA_VERSION,
        "clpc_version": __version__,
        "structure": {"na": int(s.na), "nb": int(s.nb), "nk": int(s.nk)},
        "mode": str(model.mode),
        "n_inputs": int(model.n_inputs),
        "n_outputs": int(model.n_outputs),
        "dt": dt,
        "input_names": [str(n) for n in model.input_names],
        "output_names": [str(n) for n in model.output_names],
        "theta": _finite_list(model.theta_matrix, "theta"),
        "c": _finite_list(model.c, "c"),
        "den": den,
        "num": num,
        "info": info,
    }
