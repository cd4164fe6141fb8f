"""The identify report: an HTML page of one batch fit (``clpc identify --report``).

Read top down: what the record decides (the identifiability findings in a box, the DC gains
+- one sigma, the dominant poles), the estimator comparison when there was one (its table
and reason), the result (the model, its fit, its verdict, warnings in a box), the order
selection when the order was chosen, the model against the measured data with residuals,
its step and Bode responses, the parameters with +- one standard deviation, the residual
analysis (:func:`clpc.residual_analysis`), and last, folded, the settings.
"""

from __future__ import annotations

from collections.abc import Mapping
from os import PathLike
from pathlib import Path
from typing import Any

from clpc.model import LinearModel, ModelError
from clpc.model.identifiability import GAIN_SCALE_FRACTION, GAIN_SIGMAS
from clpc.model.residuals import residual_analysis
from clpc.plotting import plot_residuals
from clpc.report.html import Section, table_html, write_html_report
from clpc.report.identifiability import identifiability_summary
from clpc.report.parts import model_sections, model_warnings, settings_section
from clpc.report.text import format_fit

__all__ = ["write_identify_report"]

#: order selection columns and their headings
_COLUMNS = {
    "bic": "BIC",
    "validation_fit": "held-out score [%]",
    "free_run_fit": "held-out free-run fit [%]",
    "kstep_fit": "held-out k-step fit [%]",
}


def _selection_section(selection: Mapping[str, Any]) -> Section:
    """The order selection of :func:`clpc.workflows.identify_file` as a table."""
    cols = [k for k in _COLUMNS if k in selection]
    rows: list[list[Any]] = [["order", *(_COLUMNS[c] for c in cols), "stability"]]
    stability = selection.get("stability") or [""] * len(selection["orders"])
    for i, order in enumerate(selection["orders"]):
        mark = " (chosen)" if order == selection["best"] else ""
        rows.append([f"{order}{mark}", *(selection[c][i] for c in cols), stability[i]])
    text = f"Criterion: {selection['criterion']}; chosen order N = {selection['best']}."
    if selection.get("reason"):
        text += f"\n\n{selection['reason']}"
    return Section("Order selection", text=text, table=rows)


def _decided_section(model: LinearModel) -> tuple[Section, list[str]]:
    """What the record decides: findings, DC gains +- sigma, dominant poles; the findings."""
    many = model.n_outputs > 1
    findings: list[str] = []
    gains: list[list[Any]] = [["output", "input", "DC gain ± 1 sigma", "determined", "why not"]]
    poles: list[list[Any]] = [["output", "pole", "kind", "wn [rad/s]", "f [Hz]", "damping",
                               "time constant [s]"]]  # fmt: skip
    said = []
    for j, name in enumerate(model.output_names):
        part = identifiability_summary(model, j)
        found = part["identifiability"]
        findings += [f"{name}: {m}" if many else m for m in found["findings"]]
        if found["excitation_order"] is not None and not found["findings"]:
            said.append(
                f"{name + ': ' if many else ''}the input is persistently exciting of order "
                f"{found['needed_order']} = na + nb + 1 (singular-value ratio "
                f"{found['excitation_ratio']:.2g} >= {found['threshold']:g}) and every DC gain "
                "is decided."
            )
        for g in part["dc_gain"]:
            ok = {True: "yes", False: "NO", None: "not judged"}[g["determined"]]
            gains.append([name, g["input"], g["value"], ok, g["note"] or None])
        for p in part["dominant_poles"]:
            poles.append([name, f"{p['re']:.4g}{p['im']:+.4g}j", p["kind"], p["natural_frequency"],
                          p["frequency_hz"], p["damping"], p["time_constant"]])  # fmt: skip
    text = (
        "Identifiability first: the input must be persistently exciting of order na + nb + 1 "
        f"(Ljung 1999, section 13.2), and each DC gain at least {GAIN_SIGMAS:g} standard "
        "deviation (delta method) from 0, unless that deviation is at most "
        f"{GAIN_SCALE_FRACTION:g} std(y)/std(u) (then the gain is decided to be small). "
        + " ".join(x[:1].upper() + x[1:] for x in said)
    )
    html_parts = [
        table_html(gains, "DC gains"),
        table_html(poles, "Dominant poles (slowest first)"),
    ]
    return Section(
        "What the record decides", text=text, warnings=findings, html="".join(html_parts)
    ), findings


def _comparison_section(comparison: Any) -> Section:
    """The estimator comparison of :func:`clpc.identify`: its table and its reason."""
    table = list(comparison.table)
    n_origins = max((len(r.get("windows") or ()) for r in table), default=0)
    many = len({r["output"] for r in table}) > 1
    rows: list[list[Any]] = [
        [
            "estimator",
            "structure",
            *(["output"] if many else []),
            *(f"free run, origin {k + 1}" for k in range(n_origins)),
            "free run, mean",
            f"{comparison.horizon}-step, mean",
            "stability",
            "chosen",
            "note",
        ]
    ]
    for r in table:
        windows = list(r.get("windows") or ()) + [None] * n_origins
        rows.append(
            [
                str(r["estimator"]).upper(),
                f"na={r['na']} nb={r['nb']} nk={r['nk']}",
                *([r["output"]] if many else []),
                *(format_fit(w) for w in windows[:n_origins]),
                format_fit(r["free_run"]),
                format_fit(r["kstep"]),
                r["stability"],
                "yes" if r["chosen"] else "",
                r.get("note") or None,
            ]
        )
    text = (
        "Each candidate fitted on the record before each rolling origin and scored on all "
        "of it after (free-run fit %, and the mean k-step prediction fit %); higher is "
        f"better.\n\nReason: {comparison.reason}"
    )
    return Section("Estimator comparison", text=text, table=rows)


def _uncertainty_section(model: LinearModel) -> Section:
    """The parameters with +- one standard deviation (:meth:`LinearModel.summary`)."""
    return Section("Parameters and their uncertainty", preformatted=model.summary())


def _residual_section(model: LinearModel, data: Any, out: Path) -> tuple[Section, list[Path]]:
    """The residual tests and their figure (``residuals.png``), or why they are missing."""
    heading = "Residual analysis"
    try:
        res = residual_analysis(model, data.u, data.y)
    except (ValueError, ModelError) as exc:
        return Section(heading, text=f"not computed: {exc}"), []
    png = out / "residuals.png"
    plot_residuals(res, png)
    text = (
        "Autocorrelation of the residuals and their cross-correlation with each input; "
        "shaded: the per-lag band at the tests' level. A model that explains the input's "
        "effect leaves no cross-correlation at positive lags."
    )
    return Section(heading, text=text, preformatted=str(res), images=[png]), [png]


def write_identify_report(
    out_dir: str | PathLike[str],
    model: LinearModel,
    data: Any,
    *,
    title: str = "LPC identification report",
    settings: Mapping[str, Any] | None = None,
    selection: Mapping[str, Any] | None = None,
    comparison: Any = None,
) -> list[Path]:
    """Figures and an HTML report of an identified model on its record.

    Parameters
    ----------
    out_dir : str or path-like
        Folder (created) for ``fit.png``, ``data.png``, ``step.png``, ``bode.png``,
        ``pz.png``, ``residuals.png`` and ``report.html``.
    model : LinearModel
    data : IOData
        The record the model was fitted on (or a validation record).
    title : str
        Report title.
    settings : mapping, optional
        Settings shown, folded, at the end.
    selection : mapping, optional
        ``summary["order_selection"]`` of :func:`clpc.workflows.identify_file`.
    comparison : Identification, optional
        The estimator comparison (:func:`clpc.identify`, ``IdentifyResult.comparison``):
        its ``table`` rows, ``horizon`` and ``reason`` are shown near the top.

    Returns
    -------
    list of Path
        The files written (the report last).
    """
    out = Path(out_dir)
    sections, files = model_sections(
        model,
        out,
        data=data,
        data_note=f"The model against the {data.n_samples} samples of the record: a free-run "
        "simulation that starts from the first measured samples and then uses the input alone.",
    )
    decided, findings = _decided_section(model)
    warnings = [w for w in model_warnings(model) if w not in findings]
    good = [
        m if model.n_outputs == 1 else f"{name}: {m}"
        for j, name in enumerate(model.output_names)
        for m in model.verdict(j).messages
    ]
    sections[0].heading = "Result: the model"
    sections[0].warnings = warnings
    sections[0].text = (
        "\n\n".join(m for m in good if m not in warnings and m not in findings) or None
    )
    if selection is not None:
        sections.insert(1, _selection_section(selection))
    if comparison is not None:
        sections.insert(0, _comparison_section(comparison))
    sections.insert(0, decided)
    sections.append(_uncertainty_section(model))
    residuals, pngs = _residual_section(model, data, out)
    sections.append(residuals)
    files.extend(pngs)
    sections.append(settings_section(settings or {}))
    files.append(write_html_report(out / "report.html", title, sections))
    return files
