"""Reading a model back from a decoded model file, with every field checked.

The schema is described in :mod:`clpc.io.model_schema`. Each problem raises a
:class:`~clpc.io.model_schema.ModelFileError` that names the file and the field.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc._schema import Fields, LongNumber, short
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


def _is_null(value: Any) -> bool:
    """JSON ``null``, or a list whose every item is null."""
    if isinstance(value, list):
        return bool(value) and all(item is None for item in value)
    return value is None


def _info_from_json(value: Any) -> Any:
    """Inverse of the writer's JSON conversion: numeric lists become arrays again."""
    if isinstance(value, dict):
        return {k: _info_from_json(v) for k, v in value.items()}
    if isinstance(value, str):
        return NONFINITE.get(value, value)
    if isinstance(value, LongNumber) or (isinstance(value, int) and abs(value) > 2**63):
        raise ValueError(f"a number out of range: {short(value)}")
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


def _check_format(d: dict[str, Any], check: Fields) -> None:
    """A clpc model of a schema version this clpc reads."""
    fmt = d.get("format")
    if fmt != FORMAT:
        raise check.fail(
            f"not a clpc model (format {short(fmt)}, expected {FORMAT!r}); pass a file written by "
            "clpc's save_model.",
        )
    version = d.get("schema_version")
    if isinstance(version, bool) or not isinstance(version, int) or version < 1:
        raise check.fail(f"schema_version must be a positive integer; got {short(version)}.")
    if version > SCHEMA_VERSION:
        raise check.fail(
            f"schema_version {version} is newer than this clpc reads ({SCHEMA_VERSION}); "
            "upgrade clpc (pip install . in a newer clpc source tree) to load it.",
        )


def _structure(d: dict[str, Any], check: Fields) -> Structure:
    st = check.require(d, "structure")
    if not isinstance(st, dict):
        raise check.fail(f"structure must be an object with na, nb, nk; got {short(st)}.")
    return Structure(
        check.integer(check.require(st, "na"), "structure.na", 1),
        check.integer(check.require(st, "nb"), "structure.nb", 0),
        check.integer(check.require(st, "nk"), "structure.nk", 0),
    )


def _channels(d: dict[str, Any], mode: str, check: Fields) -> tuple[int, int]:
    """``(n_inputs, n_outputs)``, consistent with ``mode`` (``n_outputs``: rows of theta)."""
    n_inputs = check.integer(check.require(d, "n_inputs"), "n_inputs", 1)
    theta_raw = check.require(d, "theta")
    n_outputs = len(theta_raw) if isinstance(theta_raw, list) else 0
    if "n_outputs" in d:
        n_outputs = check.integer(d["n_outputs"], "n_outputs", 1)
    if n_outputs < 1:
        raise check.fail(
            f"theta must be a list of one parameter list per output; got {short(theta_raw)}."
        )
    if mode == "siso" and (n_inputs, n_outputs) != (1, 1):
        raise check.fail(f"mode 'siso' needs 1 input and 1 output; got {n_inputs} and {n_outputs}.")
    if mode == "paired" and n_inputs != n_outputs:
        raise check.fail(
            f"mode 'paired' needs as many inputs as outputs; got {n_inputs} and {n_outputs}."
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
    check = Fields(ModelFileError, where)
    if not isinstance(d, dict):
        raise check.fail(f"expected a JSON object; got {type(d).__name__}.")
    _check_format(d, check)
    structure = _structure(d, check)
    mode = check.require(d, "mode")
    if mode not in _MODES:
        raise check.fail(f"mode must be 'siso', 'paired' or 'miso'; got {short(mode)}.")
    n_inputs, n_outputs = _channels(d, mode, check)
    width = structure.nk + structure.nb + 1
    if n_outputs * n_inputs * width > _MAX_NUM_COEFFICIENTS:
        raise check.fail(
            f"structure.nk = {structure.nk} with nb = {structure.nb} implies {width} numerator "
            f"coefficients per input and output (more than {_MAX_NUM_COEFFICIENTS:.0e} in "
            "all); no record is long enough to fit or use such a delay (the file was edited "
            "or damaged).",
        )
    p = structure.n_params(n_inputs if mode == "miso" else 1)
    theta = check.floats(d["theta"], "theta", (n_outputs, p), max_abs=_MAX_VALUE)
    c = check.floats(check.require(d, "c"), "c", (n_outputs,), max_abs=_MAX_VALUE)
    dt = check.positive(check.require(d, "dt"), "dt", "seconds")
    input_names = check.strings(check.require(d, "input_names"), "input_names", n_inputs)
    output_names = check.strings(check.require(d, "output_names"), "output_names", n_outputs)
    info = d.get("info", {})
    if not isinstance(info, dict):
        raise check.fail(f"info must be an object; got {type(info).__name__}.")
    try:
        info = _info_from_json(info)
    except RecursionError:
        raise check.fail("info is nested too deeply; it is not one clpc wrote.") from None
    except ValueError as exc:
        raise check.fail(f"info holds {exc}; it is not one clpc wrote.") from None
    # a null statistic (or a list of nulls) is one the file does not have: left out, so that
    # every reader of ``info`` sees it missing rather than meeting None where a number goes
    info = {key: value for key, value in info.items() if not _is_null(value)}
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
    _check_transfer(model, d, check)
    return model


def _check_transfer(model: LinearModel, d: dict[str, Any], check: Fields) -> None:
    """``num``/``den`` in the file (informative) must match those recomputed from theta."""
    stored = {k: d.get(k) for k in ("den", "num")}
    if all(v is None for v in stored.values()):
        return
    try:
        fresh = {"den": model.denominators, "num": model.numerators}
    except ModelError:
        raise check.fail(
            "num/den are given but theta has a0 about 0 (no monic form); remove num and den "
            "or fix theta.",
        ) from None
    for key, value in stored.items():
        if value is None:
            continue
        try:
            arr = np.array(value, dtype=np.float64)
        except (TypeError, ValueError):
            raise check.fail(f"{key} must be a (nested) list of numbers.") from None
        ref = fresh[key]
        if arr.shape != ref.shape or not np.allclose(arr, ref, rtol=1e-9, atol=1e-12):
            raise check.fail(
                f"{key} does not match the one computed from theta (edited by hand?); {key} "
                "is informative: fix theta, or delete num and den from the file.",
            )
