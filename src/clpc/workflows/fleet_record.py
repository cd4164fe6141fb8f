"""One record of a fleet: ``clpc track`` into ``OUT/<name>/`` and a small summary row back.

:func:`track_record` is what a worker runs for each record of
:func:`clpc.track_many`: it reads the record itself (a file path travels, not its samples),
runs :func:`clpc.workflows.track_file` with the fleet's settings - exactly what
``clpc track FILE --out OUT/<name>`` runs - and returns a JSON-safe row of a few kB. Every
exception becomes the row's ``error``: one bad record never fails the fleet.

The record's folder is written as one transaction by ``track_file``
(:class:`clpc.core.output_folder.OutputFolder`: staged under a temporary name, renamed in
when complete); the row is then written to ``OUT/<name>/fleet-row.json`` (atomically) with a
key of the settings and of the source (path, size, modification time; or a hash of an
:class:`IOData`'s samples). A re-run with the same key finds the row and every file the
folder's run record lists, and returns the row without appraising again; the row file is
removed before a record is run, so a run killed half-way is never taken for a finished one.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from clpc.analysis.excited_band import InputSpectrum, excited_band
from clpc.analysis.fleet import gain_drift
from clpc.core.atomic import write_file
from clpc.core.jsonable import jsonable
from clpc.core.output_folder import RECORD_NAME
from clpc.io import write_table
from clpc.plotting.track_quantities import track_quantities
from clpc.report.parts import fit_warnings, model_warnings
from clpc.report.track import trace_warnings
from clpc.workflows.fleet_settings import FleetSettings, RecordSource
from clpc.workflows.track import Chunk, TrackResult, track_file

__all__ = ["ROW_NAME", "track_record"]

#: the summary row in each record's folder, written last
ROW_NAME = "fleet-row.json"
#: points of each record's DC-gain series sent back for the fleet's drift figure
DRIFT_POINTS = 100


def _complete_row(folder: Path, key: str) -> dict[str, Any] | None:
    """The stored row when the folder holds a finished run with this key, else ``None``."""
    with contextlib.suppress(OSError, ValueError, TypeError, AttributeError):
        row = json.loads((folder / ROW_NAME).read_text(encoding="utf-8"))
        run = json.loads((folder / RECORD_NAME).read_text(encoding="utf-8"))
        listed = run.get("files", [])
        if row.get("key") == key and run.get("complete") is True and listed:
            if all((folder / str(f)).is_file() for f in listed):
                return dict(row)
    return None


def _observe(spectrum: InputSpectrum, n_in: int) -> Any:
    """A chunk filter that feeds the inputs to ``spectrum`` as ``track_file`` reads them."""

    def wrap(chunks: Iterator[Chunk]) -> Iterator[Chunk]:
        for names, values in chunks:
            spectrum.feed(values[:, :n_in])
            yield names, values

    return wrap


def _drift(result: TrackResult) -> dict[str, Any]:
    """DC gain (first input to first output) after convergence: its drift and a short series."""
    trace = result.trace
    if trace is None or len(trace) == 0 or result.model is None:
        return {"gain_drift": None, "drift_time": [], "drift_gain": []}
    q = track_quantities(trace)
    t, g = np.asarray(q["time"], float), np.asarray(q["gain"], float)[:, 0]
    conv = result.summary["convergence"]
    keep = np.isfinite(g) & (t >= (conv["time"] if conv["converged"] else -np.inf))
    t, g = t[keep], g[keep]
    pick = np.unique(np.linspace(0, len(t) - 1, min(len(t), DRIFT_POINTS)).astype(int))
    return {
        "gain_drift": gain_drift(g),
        "drift_time": jsonable(t[pick]) if len(t) else [],
        "drift_gain": jsonable(g[pick]) if len(t) else [],
    }


def _row(source: RecordSource, result: TrackResult, spectrum: InputSpectrum) -> dict[str, Any]:
    """The summary row of a tracked record (JSON-safe, a few kB)."""
    summary, model = result.summary, result.model
    warnings = trace_warnings(result.trace, summary) if result.trace is not None else []
    row: dict[str, Any] = {
        "samples": result.samples,
        "updates": summary["updates"],
        "accepted": summary["accepted"],
        "converged": summary["convergence"]["converged"],
        "converged_at_s": summary["convergence"]["time"],
        "model_source": result.model_source,
        "den": None,
        "num": None,
        "dt": None,
        "dc_gain": None,
        "fit_percent": result.fit,
        **_drift(result),
    }
    if model is not None:
        warnings += model_warnings(model)
        warnings += fit_warnings(model, {"fit": {"simulation": result.fit or []}})
        row.update(
            den=jsonable(model.denominators),
            num=jsonable(model.numerators),
            dt=float(model.dt),
            dc_gain=jsonable(model.dc_gain().ravel()),
        )
    row["verdict"] = "; ".join(warnings) if warnings else "ok"
    freqs, power = spectrum.spectrum()
    band = excited_band(freqs / result.data_dt, power)
    if band is not None and model is not None:  # the model sees nothing above its Nyquist
        band = (band[0], min(band[1], 0.5 / model.dt))
        band = band if band[0] < band[1] else None
    row["band_hz"] = list(band) if band is not None else None
    row["files"] = [Path(f).name for f in result.files]
    return row


def _run(source: RecordSource, settings: FleetSettings, folder: Path) -> dict[str, Any]:
    if source.file is not None:
        return _track(source, settings, source.file, folder)
    data = source.data
    assert data is not None
    own = dataclasses.replace(
        settings,
        record=dataclasses.replace(
            settings.record,
            inputs=tuple(data.input_names),
            outputs=tuple(data.output_names),
            dt=data.dt,
            time_col=None,
        ),
    )
    with tempfile.TemporaryDirectory(prefix="clpc-fleet-") as tmp:
        file = Path(tmp) / f"{source.name}.npz"
        names = [*data.input_names, *data.output_names]
        write_table(file, names, np.column_stack([data.u, data.y]))
        return _track(source, own, str(file), folder)


def _track(
    source: RecordSource, settings: FleetSettings, file: str, folder: Path
) -> dict[str, Any]:
    """``track_file`` on one file, with its input spectrum measured on the way."""
    spectrum = InputSpectrum(1.0)  # per sample; scaled by the record's dt in _row
    observe = _observe(spectrum, len(settings.record.inputs))
    result = track_file(settings.track_settings(file, str(folder)), observe)
    return _row(source, result, spectrum)


def track_record(source: RecordSource, settings: FleetSettings, out: str | None) -> dict[str, Any]:
    """Track one record into ``out/<name>/`` and return its summary row (never raises).

    Parameters
    ----------
    source : RecordSource
        The record.
    settings : FleetSettings
        The fleet's settings.
    out : str, optional
        The fleet's output folder; ``None``: a temporary folder, removed afterwards.

    Returns
    -------
    dict
        JSON-safe: ``name``, ``source``, ``key``, ``error`` (``None``, or what went wrong),
        ``skipped`` (a finished earlier run was reused), ``seconds`` and ``cpu_seconds``
        (wall and CPU time of this call on the worker's process), ``worker_pid``,
        ``folder`` and, without an error, ``samples``, ``updates``, ``accepted``,
        ``converged``, ``converged_at_s``, ``model_source``, ``den``, ``num``, ``dt``,
        ``dc_gain``, ``fit_percent``, ``verdict``, ``gain_drift``, ``drift_time``,
        ``drift_gain``, ``band_hz`` and ``files``.
    """
    start, cpu = time.perf_counter(), time.process_time()
    base: dict[str, Any] = {
        "name": source.name,
        "source": source.file if source.file is not None else "<IOData>",
        "error": None,
        "skipped": False,
        "worker_pid": os.getpid(),
    }
    try:
        key = settings.key(source)
        base["key"] = key
        if out is None:
            with tempfile.TemporaryDirectory(prefix="clpc-fleet-out-") as tmp:
                row = {**base, **_run(source, settings, Path(tmp) / source.name), "folder": None}
        else:
            folder = Path(out) / source.name
            done = _complete_row(folder, key)
            if done is not None:
                row = {**done, "skipped": True, "worker_pid": base["worker_pid"]}
            else:
                (folder / ROW_NAME).unlink(missing_ok=True)
                row = {**base, **_run(source, settings, folder), "folder": str(folder)}
                row["seconds"] = time.perf_counter() - start
                write_file(folder / ROW_NAME, json.dumps(row))
    except Exception as exc:  # one bad record is a row with its error, not a failed fleet
        row = {**base, "error": f"{type(exc).__name__}: {exc}"}
    row["seconds"] = time.perf_counter() - start
    row["cpu_seconds"] = time.process_time() - cpu
    return row
