"""Reading a model back from a decoded model file, with every field checked.

The schema is described in :mod:`clpc.io.model_schema`. Each problem raises a
:class:`~clpc.io.model_schema.ModelFileError` that names the file and the field.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from clpc.appraiser.state_schema import LongNumber
from clpc.io.model_schema import FORMAT, NONFINITE, SCHEMA_VERSION, ModelFileError
from clpc.model import LinearModel, ModelError
from clpc.model.structure import Structure

__all__ = ["model_from_dict"]

_MODES = ("siso", "paired", "miso")
#: largest parameter magnitude read: norms and products of larger values overflow
_MAX_VALUE = 1e150
#: most numerator coefficients (outputs x inputs x (nk + nb + 1)) a model file may imply:
#: the delay ``nk`` is not tied to the length of ``theta``, and an edited ``nk = 10**9``
#: would otherwise allocate gigabytes when the transfer functions are formed
_MAX_NUM_COEFFICIENTS = 10_000_000


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
    if arr.size and np.abs(arr).max() > _MAX_VALUE:
        raise _fail(
            where,
            f"{name} holds {np.abs(arr).max():.3g}; values beyond {_MAX_VALUE:.0e} overflow "
            "double precision when the model is used (the file was edited or damaged).",
        )
    return arr


def _names_field(value: Any, name: str, n: int, where: str) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise _fail(where, f"{name} must be a list of strings; got {value!r}.")
    if len(value) != n:
        raise _fail(where, f"{name} must name {n} channel(s); got {len(value)}: {value}.")
    return tuple(value)


def _dt_field(dt: Any, where: str) -> float:
    value = math.nan
    if not isinstance(dt, bool) and isinstance(dt, (int, float)):
        try:
            value = float(dt)
        except OverflowError:  # an int no float holds
            pass
    if not (math.isfinite(value) and value > 0):
        raise _fail(where, f"dt must be a positive number of seconds; got {dt!r:.60}.")
    return value


def _info_from_json(value: Any) -> Any:
    """Inverse of the writer's JSON conversion: numeric lists become arrays again."""
    if isinstance(value, dict):
        return {k: _info_from_json(v) for k, v in value.items()}
    if isinstance(value, str):
        return NONFINITE.get(value, value)
    if isinstance(value, LongNumber) or (isinstance(value, int) and abs(value) > 2**63):
        raise ValueError(f"a number out of range: {value!r:.60}")
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


def _check_format(d: dict[str, Any], where: str) -> None:
    """A clpc model of a schema version this clpc reads."""
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


def _structure(d: dict[str, Any], where: str) -> Structure:
    st = _get(d, "structure", where)
    if not isinstance(st, dict):
        raise _fail(where, f"structure must be an object with na, nb, nk; got {st!r}.")
    return Structure(
        _int_field(_get(st, "na", where), "structure.na", 1, where),
        _int_field(_get(st, "nb", where), "structure.nb", 0, where),
        _int_field(_get(st, "nk", where), "structure.nk", 0, where),
    )


def _channels(d: dict[str, Any], mode: str, where: str) -> tuple[int, int]:
    """``(n_inputs, n_outputs)``, consistent with ``mode`` (``n_outputs``: rows of theta)."""
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
    return n_inputs, n_outputs


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
    _check_format(d, where)
    structure = _structure(d, where)
    mode = _get(d, "mode", where)
    if mode not in _MODES:
        raise _fail(where, f"mode must be 'siso', 'paired' or 'miso'; got {mode!r}.")
    n_inputs, n_outputs = _channels(d, mode, where)
    width = structure.nk + structure.nb + 1
    if n_outputs * n_inputs * width > _MAX_NUM_COEFFICIENTS:
        raise _fail(
            where,
            f"structure.nk = {structure.nk} with nb = {structure.nb} implies {width} numerator "
            f"coefficients per input and output (more than {_MAX_NUM_COEFFICIENTS:.0e} in "
            "all); no record is long enough to fit or use such a delay (the file was edited "
            "or damaged).",
        )
    p = structure.n_params(n_inputs if mode == "miso" else 1)
    theta = _array_field(d["theta"], "theta", (n_outputs, p), where)
    c = _array_field(_get(d, "c", where), "c", (n_outputs,), where)
    dt = _dt_field(_get(d, "dt", where), where)
    input_names = _names_field(_get(d, "input_names", where), "input_names", n_inputs, where)
    output_names = _names_field(_get(d, "output_names", where), "output_names", n_outputs, where)
    info = d.get("info", {})
    if not isinstance(info, dict):
        raise _fail(where, f"info must be an object; got {type(info).__name__}.")
    try:
        info = _info_from_json(info)
    except RecursionError:
        raise _fail(where, "info is nested too deeply; it is not one clpc wrote.") from None
    except ValueError as exc:
        raise _fail(where, f"info holds {exc}; it is not one clpc wrote.") from None
    model = LinearModel(
        theta=theta,
        structure=structure,
        n_inputs=n_inputs,
        mode=mode,
        c=c,
        dt=dt,
        input_names=input_names,
        output_names=output_names,
        info=info,
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
