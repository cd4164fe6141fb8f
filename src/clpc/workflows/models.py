"""Saved models on files: simulate one, compare one with measured data."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.core.checks import check_int
from clpc.core.compact import compact_repr
from clpc.core.jsonable import jsonable
from clpc.data import DataError
from clpc.io import load_model, read_table, write_table
from clpc.io.model_files import load_any_model
from clpc.multimodel import MultiModel
from clpc.report import model_response
from clpc.workflows.common import RecordSpec, SettingsError, column_keys, model_columns

__all__ = ["CompareResult", "CompareSettings", "SimulateResult", "compare_file", "simulate_file"]


# =============================================================================== simulate
@compact_repr
@dataclass(frozen=True)
class SimulateResult:
    """The outcome of :func:`simulate_file`.

    Attributes
    ----------
    names : list of str
        Column names: the inputs, then ``OUTPUT_sim`` per model output.
    values : ndarray, shape (n_rows, len(names))
        The inputs and the simulated outputs.
    out : str or None
        The file written, if any.
    """

    names: list[str]
    values: np.ndarray
    out: str | None


def simulate_file(
    model_file: str,
    file: str,
    inputs: tuple[str, ...] = (),
    out: str | None = None,
    time_col: str | None = None,
) -> SimulateResult:
    """Simulate a saved model on the input columns of a file (free run, zero initial state).

    Parameters
    ----------
    model_file : str
        A model saved by :func:`clpc.io.save_model`.
    file : str
        Data file with the input columns.
    inputs : tuple of str
        Input columns in the model's input order (default: the model's input names).
    out : str, optional
        Also write the result to this file (csv, tsv, parquet, npy, npz).
    time_col : str, optional
        A time column to carry into the result (its first column), unchanged.

    Returns
    -------
    SimulateResult
        Column names and values.

    Raises
    ------
    ChannelCountError
        ``inputs`` does not name one column per model input.
    clpc.DataError
        The simulation leaves the range of double precision (an unstable model): nothing
        is written.
    """
    model = load_model(model_file)
    cols = model_columns(model, inputs, "input")
    keys = column_keys(cols) + ([] if time_col is None else column_keys([time_col]))
    table = read_table(file, columns=keys)
    n_in = len(cols)
    u = table.data[:, :n_in]
    with np.errstate(over="ignore", invalid="ignore"):
        y_sim = np.asarray(model.simulate(u)).reshape(table.n_rows, -1)
    _check_bounded(y_sim, model, model_file)
    names = [*table.names[n_in:], *table.names[:n_in], *(f"{n}_sim" for n in model.output_names)]
    values = np.hstack([table.data[:, n_in:], u, y_sim])
    if out:
        write_table(out, names, values)
    return SimulateResult(names, values, out)


def _check_bounded(y_sim: np.ndarray, model: Any, model_file: str) -> None:
    """Refuse a simulation that overflowed (no file of inf/nan is written)."""
    bad = ~np.isfinite(y_sim)
    if not bad.any():
        return
    row, col = (int(i) for i in np.argwhere(bad)[0])
    radius = max(float(np.max(np.abs(model.poles(e)), initial=0.0)) for e in range(bad.shape[1]))
    raise DataError(
        f"the simulation of {model_file} diverges: output {model.output_names[col]!r} leaves "
        f"the range of double precision at sample {row} (the model is unstable: a pole of "
        f"magnitude {radius:.6g} > 1); nothing was written. Simulate fewer samples, or use "
        "a stable model."
    )


# =============================================================================== compare
@dataclass(frozen=True)
class CompareSettings:
    """What :func:`compare_file` compares.

    Parameters
    ----------
    model_file : str
        A model saved by :func:`clpc.io.save_model`.
    record : RecordSpec
        Measured data; empty ``inputs``/``outputs`` mean the model's channel names.
    k : int, optional
        Compare ``k``-step-ahead predictions (default: free-run simulation).
    plot : str, optional
        Also plot measured against model output to this PNG file (needs matplotlib).
    """

    model_file: str
    record: RecordSpec
    k: int | None = None
    plot: str | None = None

    def __post_init__(self) -> None:
        if self.k is not None:
            check_int(self.k, "k", 1)


@compact_repr
@dataclass(frozen=True)
class CompareResult:
    """The outcome of :func:`compare_file`.

    Attributes
    ----------
    file : str
        The measured record.
    compared : str
        ``"simulation"`` or ``"K-step prediction"``.
    first_sample : int
        First sample of the fit (the ones before give the initial conditions).
    n_samples : int
        Samples in the record.
    fit : dict of str to float or None
        Fit % per output (``None``: the response diverges).
    plot : str or None
        The figure written, if any.
    """

    file: str
    compared: str
    first_sample: int
    n_samples: int
    fit: dict[str, float | None]
    plot: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """The result as JSON-safe fields (``plot`` only when a figure was written).

        Returns
        -------
        dict
            ``file``, ``compared``, ``first_sample``, ``n_samples``, ``fit`` [, ``plot``].
        """
        fields = dataclasses.asdict(self)
        if self.plot is None:
            del fields["plot"]
        return fields


def compare_file(settings: CompareSettings) -> CompareResult:
    """Compare a saved model with measured data: fit % of simulation or k-step prediction.

    Parameters
    ----------
    settings : CompareSettings
        Model file, record, horizon, optional figure.

    Returns
    -------
    CompareResult
        Fit % per output (100 = perfect, 0 = as good as the mean).

    Raises
    ------
    ChannelCountError
        The record's columns do not match the model's channels in number.
    SettingsError
        A multi-model file (:class:`clpc.MultiModel`) without ``-u``/``-y`` columns.
    """
    model = load_any_model(settings.model_file)
    if isinstance(model, MultiModel):
        ins, outs = _multimodel_columns(model, settings.record)
    else:
        ins = model_columns(model, settings.record.inputs, "input")
        outs = model_columns(model, settings.record.outputs, "output")
    record = dataclasses.replace(settings.record, inputs=tuple(ins), outputs=tuple(outs))
    data = record.load()
    _check_sample_time(model.dt, data.dt, record)
    first = model.warmup + (settings.k or 1) - 1  # first sample scored
    if settings.k is not None and data.n_samples <= first + 1:
        raise DataError(
            f"--k {settings.k}: a {settings.k}-step prediction is scored from sample {first} "
            f"on (max lag {model.warmup} + k - 1), but {record.file} has "
            f"{data.n_samples} samples; use a k below {data.n_samples - model.warmup}."
        )
    with np.errstate(over="ignore", invalid="ignore"):  # a diverging fit is reported as NaN
        y_hat, start, fit = model_response(model, data.u, data.y, settings.k)
    what = "simulation" if settings.k is None else f"{settings.k}-step prediction"
    fits = dict(zip(outs, jsonable(fit), strict=True))
    if settings.plot:
        from clpc.plotting import plot_compare

        plot_compare(data.time, data.y, y_hat, fit, settings.plot, names=outs, label=what)
    return CompareResult(record.file, what, start, data.n_samples, fits, settings.plot or None)


def _multimodel_columns(model: MultiModel, record: RecordSpec) -> tuple[list[str], list[str]]:
    """A multi-model file names no channels: its columns must be given, as many as it has.

    Raises
    ------
    SettingsError
        Not ``model.n_inputs`` input columns and one output column.
    """
    if len(record.inputs) != model.n_inputs or len(record.outputs) != 1:
        raise SettingsError(
            f"a multi-model file names no columns: give its {model.n_inputs} input column(s) "
            f"with -u and its one output column with -y (given: inputs {list(record.inputs)}, "
            f"outputs {list(record.outputs)})."
        )
    return list(record.inputs), list(record.outputs)


def _check_sample_time(model_dt: float, data_dt: float, record: RecordSpec) -> None:
    """Refuse data sampled at another rate than the model's (when the data's rate is known).

    Raises
    ------
    DataError
        ``--dt``/``--time`` give a sample time that differs from the model's by more than
        0.1 %.
    """
    if record.dt is None and record.time_col is None:
        return  # the record does not say: the samples are taken at the model's rate
    if abs(data_dt - model_dt) > 1e-3 * model_dt:
        source = f"--time {record.time_col}" if record.time_col else f"--dt {record.dt:g}"
        raise DataError(
            f"the model was identified at dt = {model_dt:g} s but the data are sampled at "
            f"dt = {data_dt:g} s ({source}); a discrete-time model only describes data at "
            "its own rate. Resample the data (IOData.resample) or identify a model at "
            "this rate."
        )
