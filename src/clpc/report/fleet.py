"""The fleet report (``OUT/fleet.html``): records ranked by how far their model is from the median.

Read top down: what was compared and how (the band, the distance, the outlier rule), the
ranking with a link to each record's own report, the Bode magnitudes of all records with
the outliers marked, the DC gain of every record over time, the records that failed and why,
and, folded, the settings.
"""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence
from os import PathLike
from pathlib import Path
from typing import Any

from clpc.report.html import Section, write_html_report

__all__ = ["write_fleet_report"]


def _num(v: Any, fmt: str) -> str:
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "&ndash;"
    return html.escape(format(v, fmt))


def _first(v: Any) -> Any:
    """The first entry of a per-output list (the ranking shows the first channel)."""
    if isinstance(v, (list, tuple)) or hasattr(v, "tolist"):
        seq = list(v)
        return seq[0] if seq else None
    return v


def _ranking_html(rows: Sequence[Mapping[str, Any]]) -> str:
    head = [
        "rank",
        "record",
        "distance",
        "robust z",
        "DC gain",
        "fit %",
        "gain drift",
        "converged",
        "samples",
        "verdict",
    ]
    out = ["<table><tr>" + "".join(f"<th>{h}</th>" for h in head) + "</tr>"]
    for r in rows:
        name = html.escape(str(r["name"]))
        link = f'<a href="{html.escape(str(r["name"]))}/report.html">{name}</a>'
        bad = r.get("outlier") is True
        cls = ' class="bad"' if bad else ""
        cells = [
            f'<td class="num">{_num(r.get("rank"), "d")}</td>',
            f"<td{cls}>{link}{' (outlier)' if bad else ''}</td>",
            f'<td class="num">{_num(r.get("distance"), ".4g")}</td>',
            f'<td class="num">{_num(r.get("z_score"), ".3g")}</td>',
            f'<td class="num">{_num(_first(r.get("dc_gain")), ".5g")}</td>',
            f'<td class="num">{_num(_first(r.get("fit_percent")), ".1f")}</td>',
            f'<td class="num">{_num(r.get("gain_drift"), "+.2%")}</td>',
            f"<td>{'yes' if r.get('converged') else 'no'}</td>",
            f'<td class="num">{_num(r.get("samples"), "d")}</td>',
            f"<td>{html.escape(str(r.get('verdict') or ''))}</td>",
        ]
        out.append("<tr>" + "".join(cells) + "</tr>")
    return "".join(out) + "</table>"


def write_fleet_report(
    out_dir: str | PathLike[str],
    rows: Sequence[Mapping[str, Any]],
    *,
    method: str,
    figures: Sequence[tuple[Path, str]],
    settings: Mapping[str, Any],
    warnings: Sequence[str] = (),
) -> Path:
    """Write ``out_dir/fleet.html``.

    Parameters
    ----------
    out_dir : str or path-like
        The fleet's output folder (the records' reports are in its sub-folders).
    rows : sequence of mapping
        One per record (the fleet table's rows), with ``name``, ``rank`` (``None`` when not
        ranked), ``distance``, ``z_score``, ``outlier``, ``dc_gain``, ``fit_percent``,
        ``gain_drift``, ``converged``, ``samples``, ``verdict`` and ``error``.
    method : str
        How the records were compared (the band, the median model, the distance, the
        outlier rule), in plain words.
    figures : sequence of (Path, str)
        PNG files in ``out_dir`` and their captions.
    settings : mapping
        The fleet's settings (shown folded).
    warnings : sequence of str
        Shown first (e.g. failed records, no ranking possible).

    Returns
    -------
    Path
        The report written.
    """
    out = Path(out_dir)
    ranked = sorted((r for r in rows if r.get("rank") is not None), key=lambda r: int(r["rank"]))
    unranked = [r for r in rows if r.get("rank") is None and not r.get("error")]
    failed = [r for r in rows if r.get("error")]
    n_out = sum(1 for r in rows if r.get("outlier") is True)
    summary = (
        f"{len(rows)} records: {len(ranked)} ranked, {len(unranked)} with no model, "
        f"{len(failed)} failed; {n_out} outlier(s)."
    )
    sections = [Section("Result", warnings=list(warnings), text=f"{summary}\n\n{method}")]
    if ranked or unranked:
        note = (
            "Farthest from the fleet's median model first; each name links to the record's "
            "own report (its trace, model figures and the DC gain and dominant pole over "
            "time). Fit % is the free-run simulation of the record's model on the samples "
            "its report compares it with; gain drift is the change of the DC gain from the "
            "first to the last quarter of the accepted updates after convergence, relative "
            "to its median."
        )
        sections.append(Section("Ranking", text=note, html=_ranking_html([*ranked, *unranked])))
    for png, caption in figures:
        sections.append(Section(caption.split(":")[0], images=[(png, caption)]))
    if failed:
        table: list[list[Any]] = [["record", "source", "error"]]
        table += [[r["name"], r.get("source"), r["error"]] for r in failed]
        sections.append(Section("Failed records", table=table))
    sections.append(Section("Settings", table=dict(settings), collapsed=True))
    return write_html_report(out / "fleet.html", f"Fleet report: {len(rows)} records", sections)
