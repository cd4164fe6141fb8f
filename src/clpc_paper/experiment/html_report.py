"""The experiment's report as an HTML page (``report.html``), from the same text as ``report.md``.

:func:`render_html_report` renders the Markdown of
:func:`clpc_paper.experiment.report.render_report` (one source, so the two cannot drift) with
:mod:`.markdown_html` into the sections of :func:`clpc.report.write_html_report`: the verdicts
first, with the claims not (or only partly) reproduced marked in the table and listed with
their reasons in a warnings box under it; each figure beside its claim; the settings last and
folded. Figures are linked relative to the page (they sit beside it).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from clpc.report import Section, warnings_html, write_html_report
from clpc_paper.experiment.claims import NOT_REPRODUCED, PARTLY, REPRODUCED
from clpc_paper.experiment.markdown_html import markdown_to_html, split_sections
from clpc_paper.experiment.report import render_report

__all__ = ["claim_warnings", "render_html_report", "verdict_class"]

VERDICT_SECTION = "Verdicts at a glance"
SETTINGS_SECTION = "Settings"
WARN_TITLE = "Claims not reproduced, or only partly, and why"


def verdict_class(cell: str) -> str | None:
    """CSS class of a verdict cell (``"name: verdict"`` or ``"verdict"``), None for others."""
    verdict = cell.rsplit(": ", 1)[-1]
    return {NOT_REPRODUCED: "bad", PARTLY: "partly", REPRODUCED: "good"}.get(verdict)


def claim_warnings(summary: dict[str, Any]) -> list[str]:
    """One line per claim and record not reproduced (or partly): the verdict, claim and why.

    The reason is the claim check's sentence from the measurements (its numbers when the
    check gives no reason).
    """
    out = []
    for claim in summary["claims"]:
        for name, res in claim.items():
            if not isinstance(res, dict) or res.get("verdict") in (None, REPRODUCED):
                continue
            why = str(res.get("reason") or res.get("numbers") or "").rstrip(".")
            why = why[:1].upper() + why[1:]
            out.append(f"{res['verdict'].upper()} ({name}): {claim['paper']}. Why: {why}.")
    return out


def render_html_report(summary: dict[str, Any], path: str | Path) -> Path:
    """Write ``report.html`` for the experiment's summary (figures linked beside it).

    Parameters
    ----------
    summary : dict
        The JSON-safe summary of :func:`clpc_paper.experiment.run_experiment`.
    path : str or Path
        The HTML file; the figures named in the summary must sit in its folder.

    Returns
    -------
    Path
        The file written.
    """
    title, intro, parts = split_sections(render_report(summary))
    sections = [Section("", html=markdown_to_html(intro))] if intro else []
    for heading, body in parts:
        if heading == VERDICT_SECTION:
            table = markdown_to_html(body, cell_class=verdict_class)
            problems = claim_warnings(summary)
            box = warnings_html(problems, WARN_TITLE) if problems else ""
            sections.append(Section(heading, html=table + box))  # the table first, then why
        else:
            sections.append(
                Section(
                    heading,
                    html=markdown_to_html(body),
                    collapsed=heading == SETTINGS_SECTION,
                )
            )
    return write_html_report(path, title, sections, embed_images=False)
