""":func:`load_iodata`: an input/output record (:class:`~clpc.data.IOData`) from a data file.

>>> from clpc.io import load_iodata                                   # doctest: +SKIP
>>> data = load_iodata("run1.csv", inputs="u", outputs="y", time_column="t")  # doctest: +SKIP

The sample time comes from ``dt=`` or from a time column, which must be increasing and
uniformly sampled.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from clpc.data import DataError
from clpc.data.iodata import IOData, check_dt
from clpc.io.errors import show
from clpc.io.loading import read_table
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
    time_rtol: float = 1e-6,
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
        Sample time [s]. When ``time_column`` is also given, the time column must agree
        with it (within ``time_rtol``).
    time_column : str or int, optional
        A column of sample times [s]; ``dt`` is its mean step, and the steps must all be
        equal within ``time_rtol`` (relative). Without ``dt`` and ``time_column`` the
        sample time is 1 (per sample).
    delimiter, header
        Text files only, as for :func:`read_table`.
    time_rtol : float
        Relative tolerance of the uniform-sampling check (default 1e-6).

    Returns
    -------
    IOData
        ``u`` of shape (n_samples, n_inputs), ``y`` of shape (n_samples, n_outputs).

    Raises
    ------
    DataError
        Any problem of :func:`read_table`; a time column that is not increasing or not
        uniformly sampled (the message names the first offending line/row); a ``dt``
        that disagrees with the time column.
    """
    in_keys = _keys(inputs, "inputs")
    out_keys = _keys(outputs, "outputs")
    keys = in_keys + out_keys + ([] if time_column is None else [time_column])
    table = read_table(path, columns=keys, delimiter=delimiter, header=header)
    n_in, n_out = len(in_keys), len(out_keys)
    if time_column is not None:
        step = _time_step(table, n_in + n_out, float(time_rtol))
        if dt is None:
            dt = step
        else:
            _check_dt_agrees(dt, step, table, time_rtol)
    return IOData(
        table.data[:, :n_in],
        table.data[:, n_in : n_in + n_out],
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


def _time_step(table: Table, col: int, rtol: float) -> float:
    """The sample time [s] of time column ``col``, after checking it is uniformly sampled."""
    t = table.data[:, col]
    name = table.names[col]
    source = show(table.source)
    if t.size < 2:
        raise DataError(
            f"time column {name!r} of {source} has {t.size} sample(s); at least 2 are needed "
            "to find the sample time (or pass dt=)."
        )
    steps = np.diff(t)
    nonpos = np.flatnonzero(steps <= 0)
    if nonpos.size:
        k = int(nonpos[0]) + 1
        raise DataError(
            f"time column {name!r} of {source} is not increasing at {table.row_label(k)} "
            f"({t[k - 1]:.12g} -> {t[k]:.12g}); sort the record by time and remove repeated "
            "samples."
        )
    typical = float(np.median(steps))
    off = np.flatnonzero(np.abs(steps - typical) > rtol * typical)
    if off.size:
        k = int(off[0]) + 1
        rel = abs(steps[k - 1] - typical) / typical
        raise DataError(
            f"time column {name!r} of {source} is not uniformly sampled: the step from "
            f"{table.row_label(k - 1)} to {table.row_label(k)} is {steps[k - 1]:.12g} s but "
            f"the typical (median) step is {typical:.12g} s (relative deviation {rel:.3g} > "
            f"time_rtol={rtol:g}); resample the record onto a uniform grid (e.g. "
            "numpy.interp), or loosen time_rtol if the times are rounded."
        )
    step = float((t[-1] - t[0]) / (t.size - 1))
    rounded = float(f"{step:.12g}")  # 0.009999999999999998 -> 0.01
    return rounded if abs(rounded - step) <= 1e-9 * step else float(step)
