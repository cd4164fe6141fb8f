"""The track report: figures and an HTML page of one CLPC trace (``clpc track --report``)."""

from __future__ import annotations

from collections.abc import Mapping
from os import PathLike
from pathlib import Path
from typing import Any

from clpc.appraiser.trace import Trace
from clpc.appraiser.tracefile import trace_columns
from clpc.plotting import plot_bode, plot_pz, plot_trace
from clpc.report.html import Section, write_html_report
from clpc.report.summaries import model_summary, steady_state, trace_summary
from clpc.report.text import format_model_summary

__all__ = ["write_track_report"]


def write_track_report(
    out_dir: str | PathLike[str],
    trace: Trace,
    *,
    title: str = "CLPC report",
    settings: Mapping[str, Any] | None = None,
    summary: Mapping[str, Any] | None = None,
    steady: tuple[Any, str] | None = None,
    recent: Trace | None = None,
) -> list[Path]:
    """Figures and an HTML report of a CLPC trace.

    Parameters
    ----------
    out_dir : str or path-like
        Folder (created) for ``trace.png``, ``pz.png`` and ``bode.png`` (of the
        :func:`steady_state` model, when there is one) and ``report.html``.
    trace : Trace
        The appraiser's output.
    title : str
        Report title.
    settings : mapping, optional
        Settings shown as a table (e.g. :meth:`clpc.CLPC.config` and the file name).
    summary : mapping, optional
        :func:`trace_summary` of ``trace`` (computed when omitted).
    steady : (LinearModel or None, str), optional
        :func:`steady_state` of the whole record when ``trace`` is a thinned copy
        (computed from ``trace`` when omitted).
    recent : Trace, optional
        The last updates, unthinned, for the table of the last 20 (default ``trace``).

    Returns
    -------
    list of Path
        The files written (the report last).
    """
    out = Path(out_dir)
    summary = trace_summary(trace) if summary is None else summary
    files = [plot_trace(trace, out / "trace.png", title=title)]
    table = {"inputs": ", ".join(trace.input_names), "outputs": ", ".join(trace.output_names)}
    table.update({k: v for k, v in (settings or {}).items() if not isinstance(v, Mapping)})
    conv = summary["convergence"]
    counts = {k: summary[k] for k in ("updates", "accepted", "determined", "not_enough_data")}
    counts["converged"] = conv["converged"]
    if conv["converged"]:
        counts["converged at time [s]"] = conv["time"]
        counts["converged at sample"] = conv["index"]
    sections = [
        Section("Settings", table=table),
        Section("Summary", table=counts, text="\n\n".join(summary["findings"])),
        Section(
            "Trace",
            text="Degree of linearity D and parameter vector theta (paper convention, unit "
            "norm) per cluster update; red crosses: estimate not accepted (the last accepted "
            "one is held); orange circles: not determined by the window.",
            images=files[:1],
        ),
    ]
    model, source = steady_state(trace) if steady is None else steady
    if model is not None:
        files += [plot_pz(model, out / "pz.png"), plot_bode(model, out / "bode.png")]
        sections.append(
            Section(
                f"Model ({source})",
                preformatted=format_model_summary(model_summary(model)),
                images=files[-2:],
            )
        )
    names, values = trace_columns(trace if recent is None else recent)
    wanted = {"index", "time", "D", "accepted", "determined", *trace.labels()}
    keep = [i for i, n in enumerate(names) if n.split(":")[-1] in wanted]
    rows: list[list[Any]] = [[names[i] for i in keep]]
    rows += [[row[i] for i in keep] for row in values[-20:]]
    sections.append(Section(f"Last {len(rows) - 1} updates", table=rows))
    files.append(write_html_report(out / "report.html", title, sections))
    return files
