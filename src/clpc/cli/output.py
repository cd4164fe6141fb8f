"""Printing: JSON objects, tables as CSV on standard output, and a hint on the time base."""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from typing import Any

import click
import numpy as np

from clpc.core.jsonable import jsonable
from clpc.data.time_units import time_like
from clpc.io import table_columns
from clpc.workflows import RecordSpec

__all__ = ["echo_json", "warn_unnamed_time", "write_csv"]


def echo_json(obj: Any, default: Callable[[Any], Any] | None = None) -> None:
    """Print ``obj`` as one JSON object (numpy values converted, non-finite -> null)."""
    click.echo(json.dumps(jsonable(obj), default=default, allow_nan=False))


def write_csv(names: list[str], array: np.ndarray, rows_per_write: int = 10_000) -> None:
    """Write a table as CSV to standard output (full precision), in blocks, then flush."""
    sys.stdout.write(",".join(names) + "\n")
    for start in range(0, array.shape[0], rows_per_write):
        rows = array[start : start + rows_per_write].tolist()
        sys.stdout.write("".join(",".join(map(repr, row)) + "\n" for row in rows))
    sys.stdout.flush()


def warn_unnamed_time(record: RecordSpec) -> None:
    """One line on stderr when a column is named like sample times but neither dt nor it is given.

    Without ``--time``/``--dt`` the sample time is 1 s; beside a column named ``t``,
    ``t_ms``, ``timestamp``... (:func:`clpc.data.time_units.time_like`) that is rarely meant.
    """
    if record.dt is not None or record.time_col is not None:
        return
    used = {*record.inputs, *record.outputs}
    names = table_columns(record.file, record.skip_rows)
    if any(c not in names and not c.isdigit() for c in used):
        return  # a column is missing: the reader's one-line error says so, alone
    for name in names:
        unit = time_like(name)
        if unit is not None and name not in used:
            click.echo(
                f"warning: column {name!r} looks like sample times [{unit}] but neither --time "
                f"nor --dt was given, so dt = 1 s is used; use --time {name} (or --dt).",
                err=True,
            )
            return
