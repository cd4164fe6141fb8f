"""Model files: a :class:`~clpc.model.LinearModel` as versioned, exact JSON.

>>> import numpy as np, clpc                                           # doctest: +SKIP
>>> from clpc.io.model_files import save_model, load_model            # doctest: +SKIP
>>> save_model(model, "servo.json"); same = load_model("servo.json")  # doctest: +SKIP

What a file holds (the schema, ``schema_version`` 1) and how a model is written into it is
:mod:`clpc.io.model_schema`; how a decoded file is checked and turned back into a model is
:mod:`clpc.io.model_validation`. This module reads and writes the files (atomically).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from clpc._schema import bounded_json
from clpc.core.atomic import write_file
from clpc.io.errors import DataFileNotFoundError
from clpc.io.model_schema import (
    FORMAT,
    NONFINITE,
    SCHEMA_VERSION,
    ModelFileError,
    model_to_dict,
)
from clpc.io.model_validation import model_from_dict
from clpc.model import LinearModel
from clpc.multimodel import MultiModel
from clpc.multimodel.store import FORMAT as MULTIMODEL_FORMAT

#: Largest model file read (bytes); a model with its statistics is a few kB.
MAX_MODEL_BYTES = 64 * 2**20
#: Deepest JSON nesting read (a model file nests about 5 levels).
MAX_MODEL_DEPTH = 32

__all__ = [
    "FORMAT",
    "SCHEMA_VERSION",
    "ModelFileError",
    "load_any_model",
    "load_model",
    "model_from_dict",
    "model_to_dict",
    "save_model",
]


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
    clpc.core.atomic.OutputError
        ``path`` is a symbolic link, or writing failed (``path`` is left as it was).
    """
    p = Path(os.fspath(path))
    if p.is_dir():
        raise ModelFileError(
            f"cannot save the model to '{p}': it is a directory; pass a file name such as "
            f"'{p / 'model.json'}'."
        )
    text = _dumps(model_to_dict(model)) + "\n"
    if not p.parent.is_dir():
        raise DataFileNotFoundError(
            f"cannot save the model to '{p}': the directory '{p.parent}' does not exist; "
            "create it first."
        )
    write_file(p, text)  # a temporary file renamed over p; the umask is only read


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
    p, d = _read_model_json(path)
    return model_from_dict(d, source=str(p))


def load_any_model(path: str | os.PathLike[str]) -> LinearModel | MultiModel:
    """Read a model file of either kind: a :class:`LinearModel` or a :class:`MultiModel`.

    Parameters
    ----------
    path : str or os.PathLike
        A file written by :func:`save_model` or :meth:`clpc.MultiModel.save`.

    Returns
    -------
    LinearModel or MultiModel
        Chosen by the file's ``format`` field.

    Raises
    ------
    DataFileNotFoundError, ModelFileError
        As for :func:`load_model`; a damaged multi-model file names the file and the field.
    """
    p, d = _read_model_json(path)
    if d.get("format") == MULTIMODEL_FORMAT:
        try:
            return MultiModel.from_dict(d)
        except (ValueError, TypeError) as exc:
            raise ModelFileError(f"multi-model file '{p}': {exc}") from None
    return model_from_dict(d, source=str(p))


def _read_model_json(path: str | os.PathLike[str]) -> tuple[Path, dict[str, Any]]:
    """The file's path and its JSON object, read within the model files' bounds."""
    p = Path(os.fspath(path))
    if not p.exists():
        raise DataFileNotFoundError(
            f"model file '{p}' does not exist (resolved to '{p.resolve()}'); check the path."
        )
    if p.is_dir():
        raise ModelFileError(f"'{p}' is a directory, not a model file; pass a .json file.")
    try:
        with p.open(encoding="utf-8") as fh:
            text = fh.read(MAX_MODEL_BYTES + 1)
    except UnicodeDecodeError:
        raise ModelFileError(
            f"model file '{p}' is not UTF-8 text; it is corrupted or not a clpc model file."
        ) from None
    d = bounded_json(
        text,
        max_bytes=MAX_MODEL_BYTES,
        max_depth=MAX_MODEL_DEPTH,
        error=ModelFileError,
        what=f"model file '{p}'",
        constants=NONFINITE,
    )
    return p, d
