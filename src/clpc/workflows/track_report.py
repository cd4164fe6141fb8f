"""The end of ``clpc track``: summary, steady-state model, figures and report of a record.

:func:`write_report` turns what an appraisal produced (:class:`Appraised`: the thinned
updates for the figures, every update for the summary, the last updates and samples) into
``report.html`` and its figures, in one process (:func:`clpc.workflows.track.track_file`)
or after a record was appraised on a cluster (:mod:`clpc.distributed.long_track`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from clpc.appraiser.scanned import ScannedTrace
from clpc.appraiser.trace import Trace
from clpc.core.compact import compact_repr
from clpc.core.figure import MAX_POINTS
from clpc.core.rules import RobustRule
from clpc.data import IOData
from clpc.model import LinearModel
from clpc.report import model_response, steady_state, trace_summary, write_track_report
from clpc.workflows.track_advice import excitation_advice

__all__ = ["REPORT_SAMPLES", "Appraised", "TrackResult", "write_report"]

#: the report compares the model with at most this many (decimated) samples at the end
#: (its figure then draws every sample: see :data:`clpc.core.figure.MAX_POINTS`)
REPORT_SAMPLES = MAX_POINTS


@compact_repr
@dataclass(frozen=True)
class TrackResult:
    """The outcome of :func:`track_file`.

    Attributes
    ----------
    summary : dict
        :func:`clpc.report.trace_summary` of every update of the record.
    model : LinearModel or None
        The steady-state model (``None``: no update was accepted).
    model_source : str
        Where ``model`` comes from (see :func:`clpc.report.steady_state`).
    files : list of Path
        Files written: trace, figures, report and the saved model.
    save_refused : str or None
        Why ``--save`` saved nothing although a model exists (one line, see
        :func:`clpc.workflows.save_check.save_refusal`); ``None`` otherwise.
    fit : list of float or None, optional
        Fit % of the model's free-run simulation per output on the samples the report
        compares it with (:func:`clpc.report.model_response`; ``None`` where it diverges),
        ``None`` without a model or without enough samples.
    trace : Trace, optional
        The (thinned) trace the figures draw (see ``figure_updates``).
    samples : int
        Rows read from the record (before any decimation).
    data_dt : float
        The record's sample time [s] (1 when neither ``dt`` nor a time column gives it).
    """

    summary: dict[str, Any]
    model: LinearModel | None
    model_source: str
    files: list[Path]
    save_refused: str | None = None
    fit: list[float | None] | None = None
    trace: Trace | None = None
    samples: int = 0
    data_dt: float = 1.0


@dataclass(frozen=True)
class Appraised:
    """What the report of a tracked record is made of (bounded memory, every update counted).

    Attributes
    ----------
    config : dict
        The appraiser's settings (:meth:`clpc.CLPC.config`).
    n_samples : int
        Samples appraised (after decimation).
    figures : Trace
        The updates the figures show: every ``meta["thinned_stride"]``-th of
        ``meta["updates_total"]`` (:class:`clpc.appraiser.tracefile.ThinnedTrace`).
    whole : Trace or ScannedTrace
        Every update: in memory with at least the arrays :func:`clpc.report.trace_summary`
        reads, or scanned in parts (:class:`clpc.appraiser.scanned.ScannedTrace`).
    recent : Trace or None
        The last updates (the report's table).
    tail : ndarray, shape (n, inputs + outputs)
        The record's last :data:`REPORT_SAMPLES` samples at the appraiser's rate.
    rule : RobustRule, optional
        The appraiser's thresholds, for the report's window tests (default ``RobustRule()``).
    n_raw : int
        Rows read from the record (before any decimation; 0 when not counted).
    data_dt : float
        The record's sample time [s].
    """

    config: dict[str, Any]
    n_samples: int
    figures: Trace
    whole: Trace | ScannedTrace
    recent: Trace | None
    tail: np.ndarray
    rule: RobustRule | None = None
    n_raw: int = 0
    data_dt: float = 1.0


def _report_data(done: Appraised, trace: Any) -> dict[str, Any]:
    """The record's last samples as :class:`IOData` for the report, and where they come from."""
    rows = done.tail
    n_in = trace.n_inputs
    if rows.shape[0] <= trace.structure.max_lag + 1:
        return {}
    data = IOData(
        rows[:, :n_in],
        rows[:, n_in:],
        dt=trace.sample_time,
        input_names=trace.input_names,
        output_names=trace.output_names,
    )
    n = done.n_samples
    where = f"all {n}" if rows.shape[0] >= n else f"the last {rows.shape[0]} of the {n}"
    note = (
        f"The model against {where} samples of the record (at the appraiser's sample time): "
        "a free-run simulation that starts from the first measured samples and then uses "
        "the input alone."
    )
    t0 = (n - rows.shape[0]) * trace.sample_time
    return {"data": data, "data_note": note, "data_t0": t0}


def write_report(
    settings: Any,
    done: Appraised,
    trace_file: Path,
    out: Path,
    submit: Callable[..., Any] | None = None,
) -> TrackResult:
    """Summary, steady-state model, figures and ``report.html`` of a tracked record.

    Parameters
    ----------
    settings : TrackSettings
        The run's settings (record, appraiser, formats).
    done : Appraised
        What the appraisal produced.
    trace_file : Path
        The trace written (listed first among the files).
    out : Path
        Folder for the figures and the report.
    submit : callable, optional
        Where the figures are drawn, all at once (see
        :func:`clpc.report.write_track_report`); default one after the other, here.

    Returns
    -------
    TrackResult
    """
    trace, whole = done.figures, done.whole
    stride = int(trace.meta.get("thinned_stride", 1))
    file = settings.record.file
    report_settings = {
        "file": file,
        "samples (after decimation)": done.n_samples,
        "updates": int(trace.meta.get("updates_total", len(whole))),
        "updates in figures": f"every {stride}" if stride > 1 else "all",
        **done.config,
    }
    summary = trace_summary(whole)
    record = settings.record
    command = {"file": file, "inputs": record.inputs, "outputs": record.outputs}
    u_tail = done.tail[:, : len(record.inputs)]
    summary["advice"] = excitation_advice(whole, u_tail, settings.appraiser.window_size, command)
    model, source = steady_state(whole)
    shown = _report_data(done, trace)
    report = write_track_report(
        out,
        trace,
        title=f"CLPC track report: {Path(file).name}",
        settings=report_settings,
        summary=summary,
        steady=(model, source),
        recent=done.recent,
        rule=done.rule,
        submit=submit,
        **shown,
    )
    fit = None
    if model is not None and "data" in shown:
        data = shown["data"]
        fit = [None if f != f else float(f) for f in model_response(model, data.u, data.y)[2]]
    files = [trace_file, *report]
    return TrackResult(summary, model, source, files, None, fit, trace, done.n_raw, done.data_dt)
