"""The HTML report of a batch fit (``clpc identify --report``): model, evidence, figures."""

from __future__ import annotations

import tempfile
from collections.abc import Mapping
from os import PathLike
from pathlib import Path
from typing import Any

from clpc.data import IOData
from clpc.model import LinearModel, ModelError
from clpc.model.residuals import residual_analysis
from clpc.model.verdict import fit_verdict
from clpc.plotting import plot_bode, plot_residuals
from clpc.report.html import Section, write_html_report
from clpc.report.text import format_model_summary

__all__ = ["write_identify_report"]


def write_identify_report(
    path: str | PathLike[str],
    model: LinearModel,
    data: IOData,
    summary: Mapping[str, Any],
    *,
    title: str = "clpc identify",
) -> Path:
    """Write a self-contained HTML report of a fitted model on its record.

    Sections: the model as ``clpc identify`` prints it (with the verdict), the parameters
    with +- one standard deviation (:meth:`LinearModel.summary`), the residual analysis
    (:func:`clpc.residual_analysis`: tests and :func:`clpc.plotting.plot_residuals`) and
    the Bode plot.

    Parameters
    ----------
    path : str or path-like
        HTML file to write (parent folders are created).
    model : LinearModel
    data : IOData
        The record the model was fitted on.
    summary : mapping
        :func:`clpc.report.model_summary` of the model on ``data``.
    title : str

    Returns
    -------
    Path
    """
    verdicts = [
        f"{name}: " + "; ".join(fit_verdict(model, j).messages)
        for j, name in enumerate(model.output_names)
    ]
    sections = [
        Section("Verdict", text="\n\n".join(verdicts)),
        Section("Model", preformatted=format_model_summary(summary)),
    ]
    sections.append(Section("Parameters and their uncertainty", preformatted=model.summary()))
    with tempfile.TemporaryDirectory(prefix="clpc-report-") as tmp:
        try:
            res = residual_analysis(model, data.u, data.y)
        except (ValueError, ModelError) as exc:
            sections.append(Section("Residual analysis", text=f"not computed: {exc}"))
        else:
            fig = plot_residuals(res)
            png = Path(tmp) / "residuals.png"
            fig.savefig(png, dpi=100, format="png")
            sections.append(
                Section(
                    "Residual analysis",
                    text=(
                        "Autocorrelation of the residuals and their cross-correlation with "
                        "each input; shaded: the per-lag band at the tests' level. A model "
                        "that explains the input's effect leaves no cross-correlation at "
                        "positive lags."
                    ),
                    preformatted=str(res),
                    images=[png],
                )
            )
        sections.append(
            Section("Frequency response", images=[plot_bode(model, Path(tmp) / "bode.png")])
        )
        return write_html_report(path, title, sections)
