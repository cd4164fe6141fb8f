"""Printing: JSON objects, and tables as CSV on standard output."""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from typing import Any

import click
import numpy as np

from clpc.core.jsonable import jsonable

__all__ = ["echo_json", "write_csv"]


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
