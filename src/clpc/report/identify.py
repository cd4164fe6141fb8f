"""The identify report: an HTML page of one batch LPC fit (``clpc identify --report``).

Read top down: the result (the model, its fit, its verdict, warnings in a box), the order
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
from clpc.model.residuals import residual_analysis
from clpc.plotting import plot_residuals
from clpc.report.html import Section, write_html_report
from clpc.report.parts import model_sections, model_warnings, settings_section

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
    warnings = model_warnings(model)
    good = [
        m if model.n_outputs == 1 else f"{name}: {m}"
        for j, name in enumerate(model.output_names)
        for m in model.verdict(j).messages
    ]
    sections[0].heading = "Result: the model"
    sections[0].warnings = warnings
    sections[0].text = "\n\n".join(m for m in good if m not in warnings) or None
    if selection is not None:
        sections.insert(1, _selection_section(selection))
    sections.append(_uncertainty_section(model))
    residuals, pngs = _residual_section(model, data, out)
    sections.append(residuals)
    files.extend(pngs)
    sections.append(settings_section(settings or {}))
    files.append(write_html_report(out / "report.html", title, sections))
    return files
