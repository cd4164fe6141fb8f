"""Model files: a :class:`~clpc.model.LinearModel` as versioned, exact JSON.

>>> import numpy as np, clpc                                           # doctest: +SKIP
>>> from clpc.model_io import save_model, load_model                  # doctest: +SKIP
>>> save_model(model, "servo.json"); same = load_model("servo.json")  # doctest: +SKIP

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
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from clpc.data import DataError
from clpc.io.tables import DataFileNotFoundError
from clpc.model import LinearModel, ModelError
from clpc.model.structure import Structure

__all__ = [
    "FORMAT",
    "SCHEMA_VERSION",
    "ModelFileError",
    "load_model",
    "model_from_dict",
    "model_to_dict",
    "save_model",
]

FORMAT = "clpc-model"
SCHEMA_VERSION = 1
_MAX_INFO_ELEMENTS = 100_000
_NONFINITE = {"NaN": math.nan, "Infinity": math.inf, "-Infinity": -math.inf}
_DROP = object()


class ModelFileError(DataError):
    """A model file or dict cannot be read as a clpc model (a :class:`DataError`)."""


# =========================================================================== to JSON
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
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, int):
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
    return arr.tolist()


def model_to_dict(model: LinearModel) -> dict[str, Any]:
    """The JSON-ready description of a model (schema version 1; see the module doc).

    Parameters
    ----------
    model : LinearModel
        The model to describe.

    Returns
    -------
    dict
        Plain Python values only (``json.dumps`` works on it directly, strict JSON).

    Raises
    ------
    ModelFileError
        ``theta``, ``c`` or ``dt`` are not finite.
    """
    from clpc._version import __version__

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
        "theta": _finite_list(model.theta, "theta"),
        "c": _finite_list(model.c, "c"),
        "den": den,
        "num": num,
        "info": info,
    }


# ========================================================================= from JSON
def _fail(where: str, msg: str) -> ModelFileError:
    return ModelFileError(f"{where}{msg}")


def _get(d: dict[str, Any], key: str, where: str) -> Any:
    if key not in d:
        raise _fail(where, f"the required field {key!r} is missing; the file is incomplete.")
    return d[key]


def _int_field(value: Any, name: str, low: int, where: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise _fail(where, f"{name} must be an integer >= {low}; got {value!r}.")
    return value


def _array_field(value: Any, name: str, shape: tuple[int, ...], where: str) -> np.ndarray:
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise _fail(
            where, f"{name} must be a (nested) list of numbers of shape {shape}; got {value!r}."
        ) from None
    if arr.shape != shape:
        raise _fail(where, f"{name} must have shape {shape}; got {arr.shape}.")
    if not np.all(np.isfinite(arr)):
        raise _fail(where, f"{name} must hold finite numbers; got {arr.tolist()}.")
    return arr


def _names_field(value: Any, name: str, n: int, where: str) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise _fail(where, f"{name} must be a list of strings; got {value!r}.")
    if len(value) != n:
        raise _fail(where, f"{name} must name {n} channel(s); got {len(value)}: {value}.")
    return tuple(value)


def _info_from_json(value: Any) -> Any:
    """Inverse of :func:`_json_safe`: numeric lists become arrays again."""
    if isinstance(value, dict):
        return {k: _info_from_json(v) for k, v in value.items()}
    if isinstance(value, str):
        return _NONFINITE.get(value, value)
    if isinstance(value, list):
        items = [_info_from_json(v) for v in value]
        try:
            arr = np.array(items)
        except (TypeError, ValueError):  # ragged
            return items
        if arr.dtype.kind in "biuf" and (arr.size or not value):
            return arr
        return items
    return value


def model_from_dict(d: dict[str, Any], *, source: str | None = None) -> LinearModel:
    """Rebuild a model from :func:`model_to_dict` output (validated).

    Parameters
    ----------
    d : dict
        A decoded clpc model file.
    source : str, optional
        Where ``d`` came from (a file name), used in error messages.

    Returns
    -------
    LinearModel
        ``info`` lists of numbers come back as numpy arrays.

    Raises
    ------
    ModelFileError
        Not a clpc model, a newer schema version, a missing field, wrong shapes or types,
        or ``num``/``den`` that disagree with ``theta``.
    """
    where = f"model file '{source}': " if source else "model dict: "
    if not isinstance(d, dict):
        raise _fail(where, f"expected a JSON object; got {type(d).__name__}.")
    fmt = d.get("format")
    if fmt != FORMAT:
        raise _fail(
            where,
            f"not a clpc model (format {fmt!r}, expected {FORMAT!r}); pass a file written by "
            "clpc's save_model.",
        )
    version = d.get("schema_version")
    if isinstance(version, bool) or not isinstance(version, int) or version < 1:
        raise _fail(where, f"schema_version must be a positive integer; got {version!r}.")
    if version > SCHEMA_VERSION:
        raise _fail(
            where,
            f"schema_version {version} is newer than this clpc reads ({SCHEMA_VERSION}); "
            "upgrade clpc (pip install -U clpc) to load it.",
        )
    st = _get(d, "structure", where)
    if not isinstance(st, dict):
        raise _fail(where, f"structure must be an object with na, nb, nk; got {st!r}.")
    structure = Structure(
        _int_field(_get(st, "na", where), "structure.na", 1, where),
        _int_field(_get(st, "nb", where), "structure.nb", 0, where),
        _int_field(_get(st, "nk", where), "structure.nk", 0, where),
    )
    mode = _get(d, "mode", where)
    if mode not in ("siso", "paired", "miso"):
        raise _fail(where, f"mode must be 'siso', 'paired' or 'miso'; got {mode!r}.")
    n_inputs = _int_field(_get(d, "n_inputs", where), "n_inputs", 1, where)
    theta_raw = _get(d, "theta", where)
    n_outputs = len(theta_raw) if isinstance(theta_raw, list) else 0
    if "n_outputs" in d:
        n_outputs = _int_field(d["n_outputs"], "n_outputs", 1, where)
    if n_outputs < 1:
        raise _fail(
            where, f"theta must be a list of one parameter list per output; got {theta_raw!r}."
        )
    if mode == "siso" and (n_inputs, n_outputs) != (1, 1):
        raise _fail(
            where, f"mode 'siso' needs 1 input and 1 output; got {n_inputs} and {n_outputs}."
        )
    if mode == "paired" and n_inputs != n_outputs:
        raise _fail(
            where,
            f"mode 'paired' needs as many inputs as outputs; got {n_inputs} and {n_outputs}.",
        )
    p = structure.n_params(n_inputs if mode == "miso" else 1)
    theta = _array_field(theta_raw, "theta", (n_outputs, p), where)
    c = _array_field(_get(d, "c", where), "c", (n_outputs,), where)
    dt = _get(d, "dt", where)
    if (
        isinstance(dt, bool)
        or not isinstance(dt, (int, float))
        or not (math.isfinite(dt) and dt > 0)
    ):
        raise _fail(where, f"dt must be a positive number of seconds; got {dt!r}.")
    input_names = _names_field(_get(d, "input_names", where), "input_names", n_inputs, where)
    output_names = _names_field(_get(d, "output_names", where), "output_names", n_outputs, where)
    info = d.get("info", {})
    if not isinstance(info, dict):
        raise _fail(where, f"info must be an object; got {type(info).__name__}.")
    model = LinearModel(
        theta=theta,
        structure=structure,
        n_inputs=n_inputs,
        mode=mode,
        c=c,
        dt=float(dt),
        input_names=input_names,
        output_names=output_names,
        info=_info_from_json(info),
    )
    _check_transfer(model, d, where)
    return model


def _check_transfer(model: LinearModel, d: dict[str, Any], where: str) -> None:
    """``num``/``den`` in the file (informative) must match those recomputed from theta."""
    stored = {k: d.get(k) for k in ("den", "num")}
    if all(v is None for v in stored.values()):
        return
    try:
        fresh = {"den": model.denominators, "num": model.numerators}
    except ModelError:
        raise _fail(
            where,
            "num/den are given but theta has a0 about 0 (no monic form); remove num and den "
            "or fix theta.",
        ) from None
    for key, value in stored.items():
        if value is None:
            continue
        try:
            arr = np.array(value, dtype=np.float64)
        except (TypeError, ValueError):
            raise _fail(where, f"{key} must be a (nested) list of numbers.") from None
        ref = fresh[key]
        if arr.shape != ref.shape or not np.allclose(arr, ref, rtol=1e-9, atol=1e-12):
            raise _fail(
                where,
                f"{key} does not match the one computed from theta (edited by hand?); {key} "
                "is informative: fix theta, or delete num and den from the file.",
            )


# ============================================================================= files
def _dumps(value: Any, indent: int = 0) -> str:
    """JSON with objects spread over lines and lists of numbers kept on one line."""
    pad = "  " * (indent + 1)
    if isinstance(value, dict):
        if len(value) <= 4 and not any(isinstance(v, (list, dict)) for v in value.values()):
            return json.dumps(value, allow_nan=False)  # e.g. the structure, on one line
        items = [f"{pad}{json.dumps(k)}: {_dumps(v, indent + 1)}" for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + "  " * indent + "}"
    if isinstance(value, list) and any(isinstance(v, (list, dict)) for v in value):
        items = [f"{pad}{_dumps(v, indent + 1)}" for v in value]
        return "[\n" + ",\n".join(items) + "\n" + "  " * indent + "]"
    return json.dumps(value, allow_nan=False)


def save_model(model: LinearModel, path: str | os.PathLike[str]) -> None:
    """Write a model to a JSON file (atomically: a partial file never replaces a good one).

    Parameters
    ----------
    model : LinearModel
        The model.
    path : str or os.PathLike
        Destination, conventionally ``*.json``; overwritten if it exists.

    Raises
    ------
    ModelFileError
        The model has non-finite parameters.
    """
    p = Path(os.fspath(path))
    text = _dumps(model_to_dict(model)) + "\n"
    if not p.parent.is_dir():
        raise DataFileNotFoundError(
            f"cannot save the model to '{p}': the directory '{p.parent}' does not exist; "
            "create it first."
        )
    if p.exists():
        mode = p.stat().st_mode & 0o777
    else:  # what open() would give: 0o666 minus the umask
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".tmp", dir=p.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
        os.chmod(tmp, mode)
        os.replace(tmp, p)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def load_model(path: str | os.PathLike[str]) -> LinearModel:
    """Read a model written by :func:`save_model`.

    Parameters
    ----------
    path : str or os.PathLike
        A clpc model JSON file.

    Returns
    -------
    LinearModel
        The same model: ``theta``, ``c``, ``dt`` bit for bit, hence identical ``num``,
        ``den`` and simulations.

    Raises
    ------
    DataFileNotFoundError
        The file does not exist.
    ModelFileError
        Not JSON (corrupted or truncated), not a clpc model, a newer schema version, or
        invalid content; the message names the file and the problem.
    """
    p = Path(os.fspath(path))
    if not p.exists():
        raise DataFileNotFoundError(
            f"model file '{p}' does not exist (resolved to '{p.resolve()}'); check the path."
        )
    if p.is_dir():
        raise ModelFileError(f"'{p}' is a directory, not a model file; pass a .json file.")
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise ModelFileError(
            f"model file '{p}' is not UTF-8 text; it is corrupted or not a clpc model file."
        ) from None
    try:
        d = json.loads(text, parse_constant=lambda name: _NONFINITE[name])
    except json.JSONDecodeError as exc:
        raise ModelFileError(
            f"model file '{p}' is not valid JSON ({exc.msg} at line {exc.lineno}, column "
            f"{exc.colno}); the file is corrupted or truncated - save the model again."
        ) from None
    return model_from_dict(d, source=str(p))
