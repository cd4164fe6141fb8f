"""The roles of a record's columns: each column is one of input, output or time, once.

A column named as both input and output gives a "model" ``G = 1`` that fits its record
perfectly (free run 100 %); a time-stamp column used as a signal feeds the estimator a ramp.
Both read without error, so they are refused here, after the columns are resolved, with a
message that names the column and what to do.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from clpc.data import DataError
from clpc.io.errors import show

__all__ = ["check_column_roles", "time_typed_columns"]

PARQUET_SUFFIXES = (".parquet", ".pq")


def time_typed_columns(path: str | os.PathLike[str]) -> set[str]:
    """Names of the timestamp, date, time and duration columns of a Parquet file (else empty).

    Parameters
    ----------
    path : str or os.PathLike
        A data file; only Parquet files carry column types (text and ``.npy`` do not).

    Returns
    -------
    set of str
    """
    if Path(path).suffix.lower() not in PARQUET_SUFFIXES:
        return set()
    import pyarrow as pa
    import pyarrow.parquet as pq

    kinds = (pa.types.is_timestamp, pa.types.is_duration, pa.types.is_date, pa.types.is_time)
    schema = pq.read_schema(path)
    return {field.name for field in schema if any(kind(field.type) for kind in kinds)}


def check_column_roles(
    path: str | os.PathLike[str], names: Sequence[str], n_inputs: int, n_outputs: int
) -> None:
    """Refuse a column used in two roles, or a time-stamp column used as a signal.

    Parameters
    ----------
    path : str or os.PathLike
        The file the columns were read from (named in the message).
    names : sequence of str
        The resolved column names: the inputs, then the outputs, then (if any) the time
        column.
    n_inputs, n_outputs : int
        How many of ``names`` are inputs and outputs.

    Raises
    ------
    DataError
        A column appears twice in ``names``, or an input or output column holds time
        stamps (Parquet timestamp, date, time or duration type).
    """
    roles = ["input"] * n_inputs + ["output"] * n_outputs
    roles += ["time column"] * (len(names) - len(roles))
    seen: dict[str, str] = {}
    for name, role in zip(names, roles, strict=True):
        if name in seen:
            raise DataError(
                f"column {name!r} of {show(path)} is selected as {seen[name]} and as "
                f"{role}; each column can have one role. Name another column for the {role}."
            )
        seen[name] = role
    stamped = time_typed_columns(path)
    for name, role in zip(names, roles, strict=True):
        if role != "time column" and name in stamped:
            raise DataError(
                f"column {name!r} of {show(path)} holds time stamps, not a signal; it "
                f"cannot be an {role}. Pass it as the time column (--time {name}, "
                f"time_column={name!r}) and name a signal column as the {role}."
            )
