"""The fleet table, the ranking against the fleet's median model, and the fleet report.

:func:`finish_fleet` takes the summary rows of :func:`clpc.workflows.fleet_record.track_record`
(one per record), ranks the records by the distance of their model's frequency response
from the fleet median model's over the band the inputs excite
(:mod:`clpc.analysis.fleet`), and writes ``OUT/fleet.parquet``, the figures and
``OUT/fleet.html``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from clpc.analysis.excited_band import BAND_LEVEL
from clpc.analysis.fleet import (
    MIN_SCALE,
    OUTLIER_Z,
    FleetModel,
    band_grid,
    fleet_band,
    median_model,
    outlier_scores,
    response_distance,
)
from clpc.core.atomic import atomic_path
from clpc.core.compact import compact_repr
from clpc.core.jsonable import jsonable
from clpc.plotting.fleet import plot_fleet_bode, plot_fleet_drift
from clpc.report.fleet import write_fleet_report

__all__ = ["TABLE_COLUMNS", "FleetResult", "finish_fleet", "rank_rows"]

#: the fleet table's columns, in order
TABLE_COLUMNS = (
    "name",
    "source",
    "samples",
    "updates",
    "accepted",
    "converged",
    "converged_at_s",
    "model_source",
    "dt",
    "den",
    "num",
    "dc_gain",
    "fit_percent",
    "verdict",
    "gain_drift",
    "drift_figure",
    "band_lo_hz",
    "band_hi_hz",
    "distance",
    "z_score",
    "rank",
    "outlier",
    "error",
    "skipped",
    "seconds",
    "folder",
)


@compact_repr
@dataclass(frozen=True)
class FleetResult:
    """What :func:`clpc.track_many` returns.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per record, in the order of the sources (columns :data:`TABLE_COLUMNS`).
    band_hz : (float, float) or None
        The band [Hz] the distances are computed over (``None``: not ranked).
    reference : FleetModel or None
        The fleet's median model.
    files : list of Path
        ``fleet.parquet``, the figures and ``fleet.html`` (empty without an output folder).
    """

    table: pd.DataFrame
    band_hz: tuple[float, float] | None
    reference: FleetModel | None
    files: list[Path]


def _model(row: dict[str, Any]) -> FleetModel | None:
    if row.get("error") or row.get("den") is None:
        return None
    return FleetModel(np.asarray(row["den"], float), np.asarray(row["num"], float), row["dt"])


def rank_rows(rows: Sequence[dict[str, Any]]) -> tuple[list[dict[str, Any]], Any, Any, str]:
    """Distances from the fleet median model, robust z-scores, outliers and ranks.

    Parameters
    ----------
    rows : sequence of dict
        Summary rows of :func:`clpc.workflows.fleet_record.track_record`.

    Returns
    -------
    rows : list of dict
        Copies with ``distance``, ``z_score``, ``outlier`` and ``rank`` (1 = farthest);
        ``None`` for records without a model or when the fleet cannot be ranked.
    band : (float, float) or None
        The band [Hz] of the distance.
    reference : FleetModel or None
        The median model.
    method : str
        How the records were compared, or why they were not, in plain words.
    """
    out = [{**r, "distance": None, "z_score": None, "outlier": None, "rank": None} for r in rows]
    models = [(r, _model(r)) for r in out]
    have = [(r, m) for r, m in models if m is not None]
    bands = [tuple(r["band_hz"]) for r, _ in have if r.get("band_hz")]
    if not have:
        return out, None, None, "No record has a model: nothing to rank."
    if not bands:
        return out, None, None, "No record's input varies: there is no band to compare over."
    reference = median_model([m for _, m in have])
    try:
        lo, hi = fleet_band(bands)
        hi = min(hi, *(0.5 / m.dt for _, m in have))
        if not lo < hi:
            raise ValueError(f"the band {lo:g} Hz is above the lowest Nyquist frequency {hi:g} Hz")
    except ValueError as exc:
        return out, None, reference, f"The records are not ranked: {exc}."
    grid = band_grid((lo, hi))
    d = [response_distance(m, reference, grid) for _, m in have]
    z, flag = outlier_scores(d)
    order = np.argsort(-np.asarray(d), kind="stable")
    for rank, k in enumerate(order, start=1):
        r = have[k][0]
        r.update(distance=d[k], z_score=float(z[k]), outlier=bool(flag[k]), rank=rank)
    method = (
        f"Each record's model is compared with the fleet's median model (the coefficient-wise "
        f"median of {len(have)} models, sample time {reference.dt:g} s) by the relative RMS "
        "distance of their frequency responses, sqrt(sum |G - M|^2 / sum |M|^2) over every "
        f"output/input pair at {len(grid)} log-spaced frequencies from {lo:.4g} to {hi:.4g} "
        "Hz: the band the inputs excite (per record, the frequencies where an input's power "
        f"is within {-10 * np.log10(BAND_LEVEL):.0f} dB of its peak; the fleet's band is the "
        "median of the records' lower and upper edges, at most the Nyquist frequency). A "
        "record is an outlier when its robust z-score (d - median d) / max(1.4826 MAD, "
        f"{MIN_SCALE:g}) exceeds {OUTLIER_Z:g}."
    )
    return out, (lo, hi), reference, method


def _table(rows: Sequence[dict[str, Any]]) -> pd.DataFrame:
    data: dict[str, list[Any]] = {c: [] for c in TABLE_COLUMNS}
    for r in rows:
        band = r.get("band_hz") or (None, None)
        extra = {
            "band_lo_hz": band[0],
            "band_hi_hz": band[1],
            "drift_figure": f"{r['name']}/quantities.png"
            if "quantities.png" in (r.get("files") or [])
            else None,
        }
        for c in TABLE_COLUMNS:
            data[c].append(extra[c] if c in extra else r.get(c))
    table = pd.DataFrame(data)
    for c in ("samples", "updates", "accepted", "rank"):
        table[c] = pd.array(table[c].tolist(), dtype="Int64")
    for c in ("converged_at_s", "dt", "gain_drift", "band_lo_hz", "band_hi_hz", "distance"):
        table[c] = pd.array(table[c].tolist(), dtype="Float64")
    table["z_score"] = pd.array(table["z_score"].tolist(), dtype="Float64")
    for c in ("converged", "outlier", "skipped"):
        table[c] = pd.array(table[c].tolist(), dtype="boolean")
    return table


def _figures(out: Path, rows: Sequence[dict[str, Any]], band: Any, ref: Any) -> list[Any]:
    have = [(r, m) for r in rows if (m := _model(r)) is not None]
    figs: list[tuple[Path, str]] = []
    if band is not None and ref is not None:
        nyq = min(0.5 / m.dt for _, m in have)
        freqs = np.geomspace(band[0] / 10, nyq, 400)
        responses = [m.response(freqs)[:, 0, 0] for _, m in have]
        names = [r["name"] for r, _ in have]
        marked = [bool(r["outlier"]) for r, _ in have]
        png = out / "fleet_bode.png"
        plot_fleet_bode(freqs, responses, names, marked, ref.response(freqs)[:, 0, 0], band, png)
        figs.append((png, "Bode magnitudes: every record's model, the fleet median (dashed), "
                     "outliers in colour; shaded: the band of the distance"))  # fmt: skip
    series = [(np.asarray(r["drift_time"]), np.asarray(r["drift_gain"])) for r, _ in have]
    if any(len(t) for t, _ in series):
        png = out / "fleet_drift.png"
        names = [r["name"] for r, _ in have]
        plot_fleet_drift(series, names, [r["outlier"] is True for r, _ in have], png)
        figs.append((png, "DC gain over time: first input to first output, accepted cluster "
                     "updates after convergence, every record"))  # fmt: skip
    return figs


def finish_fleet(rows: Sequence[dict[str, Any]], settings: Any, out: str | None) -> FleetResult:
    """Rank the records, build the table, and write ``fleet.parquet`` and ``fleet.html``.

    Parameters
    ----------
    rows : sequence of dict
        One summary row per record, in the order of the sources.
    settings : FleetSettings
        The fleet's settings (shown in the report).
    out : str, optional
        The fleet's output folder; ``None``: nothing is written.

    Returns
    -------
    FleetResult
    """
    ranked, band, ref, method = rank_rows(rows)
    table = _table(ranked)
    if out is None:
        return FleetResult(table, band, ref, [])
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    parquet = folder / "fleet.parquet"
    with atomic_path(parquet) as tmp:
        table.to_parquet(tmp, index=False)
    figures = _figures(folder, ranked, band, ref)
    warnings = [f"{r['name']} failed: {r['error']}" for r in ranked if r.get("error")]
    flat: dict[str, Any] = {}
    for k, v in jsonable(dataclasses.asdict(settings)).items():
        parts = v.items() if isinstance(v, dict) else [("", v)]
        flat.update({f"{k}.{kk}" if kk else k: vv for kk, vv in parts})
    flat.pop("record.file", None)
    report = write_fleet_report(
        folder, ranked, method=method, figures=figures, settings=flat, warnings=warnings
    )
    return FleetResult(table, band, ref, [parquet, *(f for f, _ in figures), report])
