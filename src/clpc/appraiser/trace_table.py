"""A trace's numbers laid out: the keys of its per-update arrays, and the trace as a table.

:data:`SCALAR_KEYS` and :data:`PER_EQUATION` name a :class:`~clpc.appraiser.trace.Trace`'s
arrays; :func:`trace_columns` / :func:`trace_column_list` lay them out as the columns of a
trace file (:class:`~clpc.appraiser.tracefile.TraceWriter`), :func:`trace_frame` as a pandas
DataFrame (:meth:`Trace.to_frame <clpc.appraiser.trace.Trace.to_frame>`).
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np

from clpc.model.structure import Structure

__all__ = [
    "PER_EQUATION",
    "SCALAR_KEYS",
    "TraceLike",
    "is_integer",
    "theta_labels",
    "trace_column_list",
    "trace_columns",
    "trace_frame",
]

# per-update scalar statistics of each equation: shape (n_updates, n_equations)
SCALAR_KEYS = (
    "D",
    "lambda_min",
    "lambda_max",
    "eig_ratio",
    "separation",
    "a0_weight",
    "noise_variance",
    "J",
    "c",
    "n_null",
    "n_input_relations",
    "degenerate",
    "determined",
    "excited",
    "trusted",
    "accepted",
    "has_model",
    "stable",
)
# every per-update array; axis 1 (when present) is the equation (output) axis
PER_EQUATION = ("theta", "theta_estimate", "den", "num", "eigenvalues", *SCALAR_KEYS)


class TraceLike(Protocol):
    """What the layout reads of a trace (a :class:`clpc.appraiser.trace.Trace`; see there)."""

    @property
    def index(self) -> np.ndarray:
        """Sample index of each update, shape (n,)."""

    @property
    def time(self) -> np.ndarray:
        """Time of each update [s], shape (n,)."""

    @property
    def rows(self) -> np.ndarray:
        """Lag vectors in each update's window, shape (n,)."""

    @property
    def not_enough_data(self) -> np.ndarray:
        """Updates whose window had too few rows, shape (n,)."""

    @property
    def arrays(self) -> dict[str, np.ndarray]:
        """Per-equation arrays by key (:data:`PER_EQUATION`), axis 1 the equation."""

    @property
    def structure(self) -> Structure:
        """Orders and delay of every window's model."""

    @property
    def n_inputs(self) -> int:
        """Inputs of the record."""

    @property
    def mode(self) -> str:
        """How outputs relate to inputs: ``'siso'``, ``'paired'`` or ``'miso'``."""

    @property
    def input_names(self) -> tuple[str, ...]:
        """Input channel names."""

    @property
    def output_names(self) -> tuple[str, ...]:
        """Output channel names."""

    @property
    def n_equations(self) -> int:
        """Equations (outputs)."""

    def __len__(self) -> int:
        """Updates (rows)."""
        ...


def theta_labels(trace: TraceLike) -> list[str]:
    """Names of the entries of ``theta``: ``a0 .. a_na, b0 .. b_nb`` per input block.

    Parameters
    ----------
    trace : Trace or TraceLike
        A CLPC trace (its structure, inputs, mode and input names).
    """
    s = trace.structure
    names = [f"a{i}" for i in range(s.na + 1)]
    n_blocks = trace.n_inputs if trace.mode == "miso" else 1
    for blk in range(n_blocks):
        suffix = f"_{trace.input_names[blk]}" if n_blocks > 1 else ""
        names += [f"b{i}{suffix}" for i in range(s.nb + 1)]
    return names


def trace_column_list(trace: TraceLike) -> tuple[list[str], list[np.ndarray]]:
    """A trace's columns, each in its own type (see :func:`trace_columns` for the layout).

    Returns
    -------
    names : list of str
    columns : list of ndarray, shape (n_updates,)
        ``int64`` for counts and flags (``index``, ``rows``, ``n_null``, ``accepted``, ...),
        ``float64`` for everything else.
    """
    names = ["index", "time", "rows", "not_enough_data"]
    cols = [trace.index, trace.time, trace.rows, trace.not_enough_data]
    labels = theta_labels(trace)
    a = trace.arrays
    s = trace.structure
    for e in range(trace.n_equations):
        pre = f"{trace.output_names[e]}:" if trace.n_equations > 1 else ""
        for i, lab in enumerate(labels):
            names.append(pre + lab)
            cols.append(a["theta"][:, e, i])
        for i in range(s.na + 1):
            names.append(f"{pre}den{i}")
            cols.append(a["den"][:, e, i])
        for u in range(a["num"].shape[2]):
            suffix = f"_{trace.input_names[u]}" if a["num"].shape[2] > 1 else ""
            for i in range(a["num"].shape[3]):
                names.append(f"{pre}num{i}{suffix}")
                cols.append(a["num"][:, e, u, i])
        for key in SCALAR_KEYS:
            names.append(pre + key)
            cols.append(a[key][:, e])
    typed = [
        np.asarray(c, dtype=np.int64 if is_integer(c) else np.float64)
        for c in map(np.asarray, cols)
    ]
    return names, typed


def is_integer(col: np.ndarray) -> bool:
    """Whether a column holds counts or flags (written as ``int64``), not measurements."""
    return bool(np.issubdtype(col.dtype, np.integer) or np.issubdtype(col.dtype, np.bool_))


def trace_columns(trace: TraceLike) -> tuple[list[str], np.ndarray]:
    """A trace as a numeric table: column names and a float array (one row per update).

    Columns: ``index``, ``time``, ``rows``, ``not_enough_data``, then per output (prefixed
    ``"<output>:"`` when there are several) the ``theta`` entries (:meth:`Trace.labels`),
    the monic ``den``/``num`` coefficients and the statistics of :func:`update_records`;
    flags are 0/1.

    Parameters
    ----------
    trace : Trace or TraceLike
        A CLPC trace.

    Returns
    -------
    names : list of str
        Column names.
    table : ndarray, shape (n_updates, n_columns)
    """
    names, cols = trace_column_list(trace)
    table = (
        np.column_stack([c.astype(np.float64) for c in cols])
        if len(trace)
        else np.zeros((0, len(names)))
    )
    return names, table


def trace_frame(trace: TraceLike) -> Any:
    """A trace as a pandas DataFrame (one row per update; needs pandas).

    Columns: ``index``, ``time``, ``rows``, ``not_enough_data``, then per output (prefixed
    ``"<output>:"`` when there are several) the ``theta`` entries and :data:`SCALAR_KEYS`.

    Parameters
    ----------
    trace : Trace or TraceLike
        A CLPC trace.
    """
    import pandas as pd

    cols: dict[str, Any] = {
        "index": trace.index,
        "time": trace.time,
        "rows": trace.rows,
        "not_enough_data": trace.not_enough_data,
    }
    labels = theta_labels(trace)
    for e in range(trace.n_equations):
        pre = f"{trace.output_names[e]}:" if trace.n_equations > 1 else ""
        for i, lab in enumerate(labels):
            cols[pre + lab] = trace.arrays["theta"][:, e, i]
        for key in SCALAR_KEYS:
            cols[pre + key] = trace.arrays[key][:, e]
    return pd.DataFrame(cols)
