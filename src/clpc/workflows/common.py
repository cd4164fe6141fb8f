"""Settings shared by several workflows: a record's columns, the appraiser's constructor."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

from clpc.appraiser import CLPC
from clpc.core.checks import (
    check_bool,
    check_choice,
    check_int,
    check_positive,
)
from clpc.data import IOData
from clpc.data.time_units import TIME_UNITS
from clpc.data.timebase import DEFAULT_TIME_RTOL
from clpc.io import load_iodata
from clpc.model import LinearModel

__all__ = [
    "AppraiserSettings",
    "ChannelCountError",
    "Method",
    "RecordSpec",
    "SamplingConflictError",
    "SettingsError",
    "column_key",
    "column_keys",
    "model_columns",
]

#: the LPC solutions (see :class:`clpc.LPC`)
Method = Literal["robust", "paper"]
METHODS: tuple[Method, ...] = ("robust", "paper")


class SettingsError(ValueError):
    """Settings that contradict each other or the model (the command line's usage error)."""


class SamplingConflictError(SettingsError):
    """Both a sample time and a time column were given for one record."""

    def __init__(self) -> None:
        super().__init__("give either dt or time_col, not both.")


class ChannelCountError(SettingsError):
    """The number of columns given for a model's inputs or outputs is not the model's."""

    def __init__(self, kind: str, model_names: list[str], given: list[str]) -> None:
        self.kind, self.model_names, self.given = kind, model_names, given
        super().__init__(
            f"the model has {len(model_names)} {kind}(s) {model_names}; {len(given)} {kind} "
            f"column(s) were given: {given}."
        )


def column_keys(columns: Sequence[str]) -> list[str | int]:
    """Column keys: names, or 0-based indices when written as plain digits.

    Parameters
    ----------
    columns : sequence of str
        Column names as typed, e.g. ``["u", "2"]``.

    Returns
    -------
    list of str or int
        ``["u", 2]``: digit strings become indices.
    """
    return [int(c) if c.isdigit() else c for c in columns]


def column_key(column: str | None) -> str | int | None:
    """One column key (see :func:`column_keys`); ``None`` stays ``None``.

    Parameters
    ----------
    column : str or None
        A column name or digit string.

    Returns
    -------
    str, int or None
        The key.
    """
    return None if column is None else column_keys([column])[0]


def _optional_positive(value: float | None, name: str) -> float | None:
    return None if value is None else check_positive(value, name, "s")


@dataclass(frozen=True)
class RecordSpec:
    """Where a record lives and which of its columns are the inputs, outputs and time.

    Parameters
    ----------
    file : str
        Data file (csv, tsv, parquet, npy, npz; see :func:`clpc.io.read_table`).
    inputs, outputs : tuple of str
        Column names, or 0-based indices written as digits. Empty where a model supplies
        the names (:func:`clpc.workflows.compare_file`).
    dt : float, optional
        Sample time [s].
    time_col : str, optional
        Column of sample times (uniform within ``time_rtol``; see
        :mod:`clpc.data.timebase`).
    time_unit : {"s", "ms", "us"}, optional
        Unit of ``time_col``; default the one its name says (``t_ms``), else seconds.
    time_rtol : float
        Largest relative deviation of one time step from the median step.
    resample : bool
        Interpolate onto a uniform grid instead of refusing a jittery time column (whole
        records only: not for ``track``).
    skip_rows : int
        Text files: physical lines to pass over at the top (a metadata line).
    """

    file: str
    inputs: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()
    dt: float | None = None
    time_col: str | None = None
    time_unit: str | None = None
    time_rtol: float = DEFAULT_TIME_RTOL
    resample: bool = False
    skip_rows: int = 0

    def __post_init__(self) -> None:
        _optional_positive(self.dt, "dt")
        check_positive(self.time_rtol, "time_rtol")
        check_int(self.skip_rows, "skip_rows", 0)
        if self.time_unit is not None:
            check_choice(self.time_unit, "time_unit", tuple(TIME_UNITS))
        if self.resample and self.time_col is None:
            raise SettingsError("resample needs a time column (--time COL).")

    def check_sampling(self) -> None:
        """Refuse a record given both ``dt`` and ``time_col``.

        Raises
        ------
        SamplingConflictError
            Both are given.
        """
        if self.dt is not None and self.time_col is not None:
            raise SamplingConflictError

    def columns(self) -> list[str | int]:
        """Keys of the input, output and (if any) time columns, in this order.

        Returns
        -------
        list of str or int
            Column keys (see :func:`column_keys`).
        """
        return column_keys(
            [*self.inputs, *self.outputs, *([self.time_col] if self.time_col else [])]
        )

    def load(self) -> IOData:
        """Read the record (see :func:`clpc.io.load_iodata`).

        Returns
        -------
        IOData
            The input/output record.

        Raises
        ------
        SamplingConflictError
            Both ``dt`` and ``time_col`` are given.
        """
        self.check_sampling()
        return load_iodata(
            self.file,
            column_keys(self.inputs),
            column_keys(self.outputs),
            dt=self.dt,
            time_column=column_key(self.time_col),
            time_rtol=self.time_rtol,
            time_unit=self.time_unit,
            resample=self.resample,
            skip_rows=self.skip_rows,
        )


@dataclass(frozen=True)
class AppraiserSettings:
    """The constructor arguments of :class:`clpc.CLPC` that the workflows expose.

    Parameters
    ----------
    order : int
        Model order ``N`` (``na = nb = N``), at least 1.
    window_size : int
        Lag vectors per LPC window, at least 2.
    cluster_size : int
        Lag vectors between updates, at least 1.
    nk : int
        Input delay in samples.
    na, nb : int, optional
        Orders of A (at least 1) and of each B (at least 0); each overrides ``order`` for
        its own polynomial (``None``: ``order``).
    decimate_to : float, optional
        Sample time [s] the appraiser works at (an integer multiple of the data's; the data
        are low-pass filtered and decimated).
    method : {"robust", "paper"}
        LPC solution.
    guard : bool
        Accept estimates only from trusted windows (the default; ``False`` is the paper's
        appraiser, see :class:`clpc.CLPC`).
    """

    order: int = 2
    window_size: int = 201
    cluster_size: int = 12
    nk: int = 0
    decimate_to: float | None = None
    method: Method = "robust"
    guard: bool = True
    na: int | None = None
    nb: int | None = None

    def __post_init__(self) -> None:
        check_int(self.order, "order", 1)
        check_int(self.window_size, "window_size", 2)
        check_int(self.cluster_size, "cluster_size", 1)
        check_int(self.nk, "nk", 0)
        if self.na is not None:
            check_int(self.na, "na", 1)
        if self.nb is not None:
            check_int(self.nb, "nb", 0)
        _optional_positive(self.decimate_to, "decimate_to")
        check_choice(self.method, "method", METHODS)
        check_bool(self.guard, "guard")

    def build(self, data_dt: float | None) -> CLPC:
        """A new appraiser for data sampled every ``data_dt`` seconds.

        Parameters
        ----------
        data_dt : float, optional
            The data's sample time [s]; ``None`` means 1 (per sample).

        Returns
        -------
        CLPC
            The appraiser, working at ``decimate_to`` (default: ``data_dt``).
        """
        return CLPC(
            order=self.order,
            window_size=self.window_size,
            cluster_size=self.cluster_size,
            dt=data_dt if data_dt is not None else (1.0 if self.decimate_to else None),
            decimate_to=self.decimate_to,
            na=self.na,
            nb=self.nb,
            nk=self.nk,
            method=self.method,
            guard=self.guard,
        )


def model_columns(model: LinearModel, given: Sequence[str], kind: str) -> list[str]:
    """The columns of a model's inputs (``kind="input"``) or outputs.

    Parameters
    ----------
    model : LinearModel
        The model; its channel names are the default.
    given : sequence of str
        Columns named by the user, in the model's order; empty for the default.
    kind : {"input", "output"}
        Which channels.

    Returns
    -------
    list of str
        ``given``, or the model's names.

    Raises
    ------
    ChannelCountError
        ``given`` is not empty and its length is not the model's channel count.
    """
    names = list(model.input_names if kind == "input" else model.output_names)
    if not given:
        return names
    if len(given) != len(names):
        raise ChannelCountError(kind, names, list(given))
    return list(given)
