""":func:`load_iodata`: an input/output record (:class:`~clpc.data.IOData`) from a data file.

>>> from clpc.io import load_iodata                                   # doctest: +SKIP
>>> data = load_iodata("run1.csv", inputs="u", outputs="y", time_column="t")  # doctest: +SKIP

The sample time comes from ``dt=`` or from a time column (in s, ms or us), which must be
increasing and uniform within a tolerance (:mod:`clpc.data.timebase`), or is resampled onto a
uniform grid on request.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from clpc.data import DataError
from clpc.data.iodata import IOData, check_dt
from clpc.data.time_units import TIME_UNITS
from clpc.data.time_units import time_unit as time_unit_of
from clpc.data.timebase import (
    DEFAULT_TIME_RTOL,
    check_time_base,
    resample_to_grid,
)
from clpc.io.errors import show
from clpc.io.loading import read_table
from clpc.io.roles import check_column_roles
from clpc.io.table import ColumnKey, Columns, PathLike, Table

__all__ = ["load_iodata"]


def _keys(value: Columns, label: str) -> list[ColumnKey]:
    if isinstance(value, (str, int, np.integer)):
        return [value if isinstance(value, (str, int)) else int(value)]
    if value is None:
        raise DataError(f"{label} is missing: name at least one column.")
    keys = list(value)
    if not keys:
        raise DataError(f"{label} is empty: name at least one column.")
    return keys


def load_iodata(
    path: PathLike,
    inputs: Sequence[ColumnKey] | ColumnKey,
    outputs: Sequence[ColumnKey] | ColumnKey,
    *,
    dt: float | None = None,
    time_column: ColumnKey | None = None,
    delimiter: str | None = None,
    header: bool | None = None,
    time_rtol: float = DEFAULT_TIME_RTOL,
    time_unit: str | None = None,
    resample: bool = False,
    skip_rows: int = 0,
) -> IOData:
    """Read an input/output record from a data file.

    Parameters
    ----------
    path : str or os.PathLike
        A data file (see :func:`read_table`).
    inputs, outputs : str, int or sequence of them
        Input and output columns, by name or 0-based index; the names become the
        record's channel names.
    dt : float, optional
        Sample time [s]. With ``time_column`` it must agree with the column's mean step
        (within ``time_rtol``); with ``resample`` it is the grid step.
    time_column : str or int, optional
        A column of sample times; ``dt`` is its mean step, and the steps must be uniform
        (:func:`clpc.data.timebase.check_time_base`). Without ``dt`` and ``time_column``
        the sample time is 1 (per sample).
    delimiter, header, skip_rows
        Text files only, as for :func:`read_table`.
    time_rtol : float
        Largest relative deviation of one step from the median step (default 1e-2: a
        jittery acquisition clock passes, a missing sample does not).
    time_unit : {"s", "ms", "us"}, optional
        Unit of the time column; default: the one its name says (``t_ms`` is in
        milliseconds), else seconds.
    resample : bool
        Interpolate the record onto the uniform grid ``t0 + k dt`` (linear) instead of
        refusing a time column that is not uniform (needs ``time_column``).

    Returns
    -------
    IOData
        ``u`` of shape (n_samples, n_inputs), ``y`` of shape (n_samples, n_outputs).

    Raises
    ------
    DataError
        Any problem of :func:`read_table`; a column in two roles or a time-stamp column
        used as a signal (:func:`clpc.io.roles.check_column_roles`); a time column that
        is not increasing or not uniformly sampled (the message names the first offending
        line/row and what was measured); a ``dt`` that disagrees with the time column;
        ``resample`` without a time column.
    """
    in_keys = _keys(inputs, "inputs")
    out_keys = _keys(outputs, "outputs")
    keys = in_keys + out_keys + ([] if time_column is None else [time_column])
    table = read_table(path, columns=keys, delimiter=delimiter, header=header, skip_rows=skip_rows)
    n_in, n_out = len(in_keys), len(out_keys)
    check_column_roles(path, table.names, n_in, n_out)
    values = table.data[:, : n_in + n_out]
    if resample and time_column is None:
        raise DataError("resample needs a time column (time_column=, --time COL).")
    if time_column is not None:
        name = table.names[-1]
        t = table.data[:, -1] * TIME_UNITS[time_unit_of(time_unit, name)]
        if resample:
            step, values = resample_to_grid(t, values, None if dt is None else check_dt(dt))
            dt = step
        else:
            step = check_time_base(
                t, f"{name!r} of {show(table.source)}", float(time_rtol), table.row_label
            ).dt
            if dt is None:
                dt = step
            else:
                _check_dt_agrees(dt, step, table, time_rtol)
    return IOData(
        values[:, :n_in],
        values[:, n_in : n_in + n_out],
        1.0 if dt is None else dt,
        input_names=table.names[:n_in],
        output_names=table.names[n_in : n_in + n_out],
    )


def _check_dt_agrees(dt: float, step: float, table: Table, time_rtol: float) -> None:
    """``dt`` must be positive and agree with the step of the time column (the last one)."""
    given = check_dt(dt)
    if abs(step - given) > time_rtol * given:
        raise DataError(
            f"dt={given:g} s disagrees with time column {table.names[-1]!r} of "
            f"{show(table.source)}, whose step is {step:.12g} s; pass only one of "
            "dt and time_column, or fix the time column."
        )
