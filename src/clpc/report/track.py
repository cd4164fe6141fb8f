"""The track report: figures and an HTML page of one CLPC trace (``clpc track``).

Read top down: the result (converged or not, the model, warnings in a box), the DC gain
and dominant pole of every accepted update over time, the model's fit on the measured data
with residuals, its step and Bode responses, the trace, and last, folded, the latest
updates and the settings.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from os import PathLike
from pathlib import Path
from typing import Any

from clpc.appraiser.convergence import MIN_TRUSTED_FRACTION
from clpc.appraiser.trace import Trace
from clpc.appraiser.tracefile import trace_columns
from clpc.core.rules import RobustRule
from clpc.plotting import plot_trace
from clpc.plotting.track_quantities import (
    BAND_PERCENTILES,
    BAND_WINDOWS,
    MIN_SPAN_FRACTION,
    plot_track_quantities,
)
from clpc.plotting.window_tests import plot_window_tests
from clpc.report.drawing import Drawing
from clpc.report.html import Section, write_html_report
from clpc.report.parts import fit_warnings, model_sections, model_warnings, settings_section
from clpc.report.summaries import model_summary
from clpc.report.trace_summary import steady_state, trace_summary

__all__ = ["trace_warnings", "write_track_report"]

#: a count finding of :func:`clpc.describe_trace`, e.g. "1 of 249 clusters determine ..."
_COUNT = re.compile(r"^(\d+) of (\d+) clusters ")


def trace_warnings(trace: Trace, summary: Mapping[str, Any]) -> list[str]:
    """What a reader must not miss about a trace: no convergence, flagged clusters.

    Parameters
    ----------
    trace : Trace
    summary : mapping
        :func:`trace_summary` of ``trace``.

    Returns
    -------
    list of str
        The findings of :func:`clpc.describe_trace` that report a problem (a count of good
        clusters is one when fewer than
        :data:`~clpc.appraiser.convergence.MIN_TRUSTED_FRACTION` of the clusters qualify; the
        clusters that fail are listed by their own findings) and, when the trace did not
        converge, why.
    """
    out = []
    conv = summary["convergence"]
    if not conv["converged"] and summary["model_source"] == "none":
        out.append("no update was accepted: there is no model")
    elif not conv["converged"]:
        out.append(
            "the trace did not converge: the model shown is the "
            f"{summary['model_source']}, not a steady state"
        )
    for finding in summary["findings"]:
        counted = _COUNT.match(finding)
        if counted and int(counted.group(1)) >= MIN_TRUSTED_FRACTION * int(counted.group(2)):
            continue  # "82 of 83 clusters ...": the clusters that fail are listed on their own
        out.append(finding)
    return out


def _result_table(trace: Trace, summary: Mapping[str, Any]) -> dict[str, Any]:
    conv = summary["convergence"]
    unit = "s" if trace.sample_time != 1.0 else "samples"
    table: dict[str, Any] = {
        "inputs → outputs": f"{', '.join(trace.input_names)} → {', '.join(trace.output_names)}",
        "cluster updates": summary["updates"],
        "accepted": summary["accepted"],
        "determined by their window": summary["determined"],
        "too few rows": summary["not_enough_data"],
        "converged": "yes" if conv["converged"] else "no",
    }
    if conv["converged"]:
        table[f"converged at time [{unit}]"] = conv["time"]
        table["converged at sample"] = conv["index"]
    table["model"] = summary["model_source"]
    return table


def _quantities_section(trace: Trace, png: Path) -> Section:
    unit = "samples" if trace.sample_time == 1.0 else "s"
    return Section(
        "Gain and poles over time",
        text="DC gain B(1)/A(1) of each input and the dominant pole (largest |z|) of every "
        "accepted cluster update; updates not accepted are left out (gaps). The pole is drawn "
        "as natural frequency and damping of s = log(z)/dt, or as the time constant "
        f"-1/Re(s) [{unit}] when it is real in every accepted update. The shaded band is the "
        f"{BAND_PERCENTILES[0]:g}th to {BAND_PERCENTILES[1]:g}th percentile of the estimates "
        f"of the updates within {BAND_WINDOWS:g} window lengths before and after (the trace "
        "holds no per-window parameter covariance; neighbouring windows overlap, so the band "
        "is a lower bound on one window's uncertainty, and it widens where the plant "
        "changes). Axes have no "
        "offset; y-limits hold the 1st to 99th percentile (outliers are clipped) and span at "
        f"least {MIN_SPAN_FRACTION:.0%} of the median level, so noise on a steady value "
        "stays small.",
        images=[(png, "DC gain and dominant pole over time")],
    )


def _tests_section(png: Path, rule: RobustRule) -> Section:
    return Section(
        "Why windows were rejected",
        text="Per cluster update, the guard's tests in the order it applies them: enough rows, "
        "the output excited above its quantization, the model determined; the top panel "
        "names the first test each update failed. A window determines its model when it has "
        "one near-null direction, no relation among the inputs alone, and a separation (the "
        "candidate eigenvalue over the next one outside the near-null subspace) of at most "
        f"{rule.separation:g}. An input that excites too few orders in the window, such as "
        "one sine of a slow sweep, leaves several near-null directions, some of them input "
        "relations. Grey: rejected updates; the dashed line is the threshold.",
        images=[(png, "the guard's tests of every update")],
    )


def write_track_report(
    out_dir: str | PathLike[str],
    trace: Trace,
    *,
    title: str = "CLPC report",
    settings: Mapping[str, Any] | None = None,
    summary: Mapping[str, Any] | None = None,
    data: Any = None,
    data_note: str = "",
    data_t0: float = 0.0,
    steady: tuple[Any, str] | None = None,
    recent: Trace | None = None,
    rule: RobustRule | None = None,
    submit: Callable[..., Any] | None = None,
) -> list[Path]:
    """Figures and an HTML report of a CLPC trace.

    Parameters
    ----------
    out_dir : str or path-like
        Folder (created) for ``quantities.png`` (DC gain and dominant pole over time, the
        first figure), ``trace.png``, ``tests.png`` (see ``rule``), the figures of the
        :func:`steady_state` model (when there is one: ``step.png``, ``bode.png``,
        ``pz.png`` and, with ``data``, ``fit.png`` and ``data.png``) and ``report.html``.
    trace : Trace
        The appraiser's output.
    title : str
        Report title.
    settings : mapping, optional
        Settings shown, folded, at the end (e.g. :meth:`clpc.CLPC.config` and the file).
    summary : mapping, optional
        :func:`trace_summary` of ``trace`` (computed when omitted); its ``advice`` (one
        paragraph on what would help when the data cannot decide, see
        :func:`clpc.workflows.track_advice.excitation_advice`), when present, leads the
        result.
    data : IOData, optional
        Measured record (at the trace's sample time) to compare the model with.
    data_note : str
        Where ``data`` comes from (e.g. "the last 4000 samples of the record").
    data_t0 : float
        Time of ``data``'s first sample in the record (the fit figure's time axis).
    steady : (LinearModel or None, str), optional
        :func:`steady_state` of the whole record when ``trace`` is a thinned copy
        (computed from ``trace`` when omitted).
    recent : Trace, optional
        The last updates, unthinned, for the table of the last 20 (default ``trace``).
    rule : RobustRule, optional
        The appraiser's thresholds (:attr:`clpc.CLPC.rule`, default ``RobustRule()``), drawn
        in ``tests.png`` (:func:`clpc.plotting.window_tests.plot_window_tests`) when fewer
        than :data:`~clpc.appraiser.convergence.MIN_TRUSTED_FRACTION` of the updates were
        accepted.
    submit : callable, optional
        ``submit(function, *args, **kwargs) -> future``: the figures, which are
        independent, are handed to it at once, and the report is written when every one
        is drawn (:class:`clpc.report.drawing.Drawing`; e.g. a Dask cluster's workers, see
        :class:`clpc.distributed.cluster_submit.ClusterSubmit`). Default: drawn one after
        the other in this process. The files are the same either way.

    Returns
    -------
    list of Path
        The files written (the report last).
    """
    out = Path(out_dir)
    draw = Drawing(submit)
    model, source = steady_state(trace) if steady is None else steady
    trace_png = out / "trace.png"
    summary = trace_summary(trace) if summary is None else summary
    warnings = trace_warnings(trace, summary)
    if model is not None:
        warnings += model_warnings(model)
        fitted = model_summary(model, data)
        warnings += fit_warnings(model, fitted)
    findings = [f for f in summary["findings"] if f not in warnings]
    result = Section(
        "Result",
        warnings=warnings,
        text="\n\n".join(findings) if findings else None,
        table=_result_table(trace, summary),
    )
    sections = [result]
    # the trace's figure first: the longest to draw, so with submit it is not left for last
    draw(plot_trace, trace, trace_png, title=f"CLPC trace: {len(trace)} updates")
    quantities_png = out / "quantities.png"
    draw(plot_track_quantities, trace, quantities_png)
    files: list[Path] = [quantities_png]
    sections.append(_quantities_section(trace, quantities_png))
    if model is not None:
        more, model_files = model_sections(
            model,
            out,
            data=data,
            data_note=data_note,
            data_t0=data_t0,
            summary=fitted,
            draw=draw,
        )
        more[0].heading = f"Model: {source}"
        sections += more
        files += model_files
    n = max(int(summary["updates"]), 1)
    if int(summary["accepted"]) < MIN_TRUSTED_FRACTION * n:
        tests_png = out / "tests.png"
        draw(plot_window_tests, trace, tests_png, rule=rule)
        files.append(tests_png)
        sections.append(_tests_section(tests_png, rule or RobustRule()))
        if model is None:
            result.text = "The window tests below show why no estimate was accepted."
    if summary.get("advice"):
        result.text = "\n\n".join(t for t in (summary["advice"], result.text) if t)
    files.append(trace_png)
    sections.append(
        Section(
            "Trace",
            text="Degree of linearity D and each entry of the parameter vector theta (paper "
            "convention, unit norm) per cluster update, each on its own scale. Marked on D: "
            "updates not accepted (the last accepted estimate is held), not determined by "
            "the window, or with too few rows. Long traces are drawn as min/max envelopes.",
            images=[(trace_png, "the trace")],
        )
    )
    names, values = trace_columns(trace if recent is None else recent)
    wanted = {"index", "time", "D", "accepted", "determined", *trace.labels()}
    keep = [i for i, n in enumerate(names) if n.split(":")[-1] in wanted]
    rows: list[list[Any]] = [[names[i] for i in keep]]
    rows += [[row[i] for i in keep] for row in values[-20:]]
    sections.append(Section(f"Last {len(rows) - 1} updates", table=rows, collapsed=True))
    sections.append(settings_section(settings or {}))
    draw.wait()  # the page after its figures
    files.append(write_html_report(out / "report.html", title, sections))
    return files
