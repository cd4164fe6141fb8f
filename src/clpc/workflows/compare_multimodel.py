"""``clpc compare`` of a saved multi-model (:class:`clpc.MultiModel`) with measured data.

A multi-model file names no channels (it keeps the number of inputs and one output), so the
record's columns are given: ``-u`` once per input, ``-y`` once. The first
:attr:`clpc.MultiModel.warmup` samples are the initial conditions (outputs and inputs before
the first simulated sample, and the schedule's lag); the fit % is over the rest, as for a
linear model.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from clpc.analysis.metrics import fit_percent
from clpc.multimodel import MultiModel
from clpc.workflows.common import RecordSpec, SettingsError

__all__ = ["MultiModelComparison", "compare_multimodel"]


@dataclasses.dataclass(frozen=True)
class MultiModelComparison:
    """Measured and model output of one record.

    Attributes
    ----------
    record : RecordSpec
        The record with its columns.
    time : ndarray, shape (T,)
        Sample times [s].
    dt : float
        The record's sample time [s].
    y : ndarray, shape (T, 1)
        Measured output.
    y_hat : ndarray, shape (T, 1)
        Simulated or ``k``-step-predicted output (the first ``start`` samples measured).
    start : int
        First compared sample.
    fit : ndarray, shape (1,)
        Fit % over ``start:`` (NaN when the response diverges).
    """

    record: RecordSpec
    time: np.ndarray
    dt: float
    y: np.ndarray
    y_hat: np.ndarray
    start: int
    fit: np.ndarray


def compare_multimodel(
    model: MultiModel, record: RecordSpec, k: int | None
) -> MultiModelComparison:
    """Simulate (``k=None``) or ``k``-step-predict a multi-model on a record and score it.

    Parameters
    ----------
    model : MultiModel
        A fitted multi-model (e.g. :meth:`clpc.MultiModel.load`).
    record : RecordSpec
        The measured record; its ``inputs`` must name ``model.n_inputs`` columns and its
        ``outputs`` one.
    k : int, optional
        Prediction horizon in samples.

    Returns
    -------
    MultiModelComparison

    Raises
    ------
    SettingsError
        The columns are not given, or not as many as the multi-model's channels.
    """
    if len(record.inputs) != model.n_inputs or len(record.outputs) != 1:
        raise SettingsError(
            f"a multi-model file names no columns: give its {model.n_inputs} input column(s) "
            f"with -u and its one output column with -y (given: inputs {list(record.inputs)}, "
            f"outputs {list(record.outputs)})."
        )
    data = record.load()
    u, y = data.u, data.y[:, 0]
    start = model.warmup
    if data.n_samples <= start + (k or 1):
        raise SettingsError(
            f"{record.file} has {data.n_samples} samples; the multi-model needs more than "
            f"{start + (k or 1)} (warm-up {start} and the horizon)."
        )
    with np.errstate(over="ignore", invalid="ignore"):  # a diverging response is NaN
        if k is None:
            y_hat = y.copy()
            y_hat[start:] = model.simulate(u[start:], y_init=y[:start], u_init=u[:start])
        else:
            y_hat = model.predict(u, y, k=k)
            start += k - 1  # only true k-step predictions are scored
        fit = np.atleast_1d(fit_percent(y[start:], y_hat[start:]))
    return MultiModelComparison(record, data.time, data.dt, y[:, None], y_hat[:, None], start, fit)
