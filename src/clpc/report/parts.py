"""Report sections about one model: its equations, its fit on data, its responses.

Shared by the track report (:mod:`clpc.report.track`) and the identify report
(:mod:`clpc.report.identify`), so both read alike: results first, settings last.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from clpc.core.rules import MIN_HELDOUT_FIT
from clpc.model import LinearModel, fit_verdict
from clpc.plotting import plot_bode, plot_data, plot_fit, plot_pz, plot_step
from clpc.report.drawing import Drawing
from clpc.report.html import Section
from clpc.report.summaries import model_summary
from clpc.report.text import format_fit, format_model_summary

__all__ = ["draw_model_figures", "model_sections", "model_warnings", "settings_section"]

#: verdict messages that are good news (everything else is shown as a warning)
#: verdict messages that are evidence or good news, not warnings (kept out of the box)
_GOOD = (
    "the data determine",
    "the model is stable",
    "the model is integrating",
    "the model describes the record",
    "held-out fit (",
    "residuals independent",
    "residuals white",
    "no fit statistics",
    "no eigenvalue statistics",
)


def model_warnings(model: LinearModel) -> list[str]:
    """The problems the verdict of each output finds, in plain words (may be empty).

    Uses :func:`clpc.fit_verdict` (excitation, determination, cancelled factors,
    stability); a multi-output model prefixes each message with the output's name.
    """
    out = []
    for j, name in enumerate(model.output_names):
        for msg in fit_verdict(model, j).messages:
            if not msg.startswith(_GOOD):
                out.append(msg if model.n_outputs == 1 else f"{name}: {msg}")
    return out


def fit_warnings(model: LinearModel, summary: Mapping[str, Any]) -> list[str]:
    """Outputs whose free-run fit is below :data:`clpc.core.rules.MIN_HELDOUT_FIT`.

    The same threshold as the verdict's held-out fit: a model that simulates the record this
    poorly does not describe it, whatever its eigenvalue structure says.

    Parameters
    ----------
    model : LinearModel
    summary : mapping
        :func:`model_summary` of ``model`` on the compared record (none without its
        ``"fit"`` entry, i.e. without data).
    """
    fits = summary.get("fit", {}).get("simulation", [])
    out = []
    for name, fit in zip(model.output_names, fits, strict=False):
        if not (isinstance(fit, (int, float)) and fit >= MIN_HELDOUT_FIT):
            shown = f"{fit:.1f} %" if isinstance(fit, (int, float)) and fit == fit else "undefined"
            who = "" if model.n_outputs == 1 else f"{name}: "
            out.append(
                f"{who}the model's free-run fit on the compared samples is {shown} "
                f"(< {MIN_HELDOUT_FIT:g} %): it does not describe the record well - try "
                "another order or input delay (clpc identify --estimator auto --nk auto)"
            )
    return out


def fit_table(summary: Mapping[str, Any]) -> list[list[Any]]:
    """Rows ``[output, simulation fit, k-step fits...]`` of :func:`model_summary` with data."""
    fits = summary.get("fit", {})
    head = ["output", *(k.replace("prediction_", "") + "-step prediction" if k != "simulation"
                        else "free-run simulation" for k in fits)]  # fmt: skip
    rows: list[list[Any]] = [head]
    for j, name in enumerate(summary["outputs"]):
        rows.append([name, *(format_fit(vals[j]) for vals in fits.values())])
    return rows


#: the figures of :func:`model_sections`, in its order
FIT_PNG, DATA_PNG, STEP_PNG = "fit.png", "data.png", "step.png"
BODE_PNG, PZ_PNG = "bode.png", "pz.png"


def draw_model_figures(
    model: LinearModel,
    out: Path,
    *,
    data: Any = None,
    data_t0: float = 0.0,
    draw: Drawing | None = None,
) -> None:
    """Draw the figures of :func:`model_sections`.

    ``fit.png`` and ``data.png`` (with ``data``), ``step.png``, ``bode.png``, ``pz.png`` in
    ``out``. Long records are drawn as min/max envelopes (see
    :data:`clpc.core.figure.MAX_POINTS`), so each figure costs about the same at any length.
    ``draw``: where (:class:`clpc.report.drawing.Drawing`; default one after the other,
    here); the caller waits for it.
    """
    draw = Drawing() if draw is None else draw
    if data is not None:
        title = f"the compared {data.n_samples} samples"
        draw(plot_fit, model, data, out / FIT_PNG, t0=data_t0)
        draw(plot_data, data, out / DATA_PNG, t0=data_t0, title=title)
    draw(plot_step, model, out / STEP_PNG)
    draw(plot_bode, model, out / BODE_PNG)
    draw(plot_pz, model, out / PZ_PNG)


def model_sections(
    model: LinearModel,
    out: Path,
    *,
    data: Any = None,
    data_note: str = "",
    data_t0: float = 0.0,
    summary: Mapping[str, Any] | None = None,
    draw: Drawing | None = None,
) -> tuple[list[Section], list[Path]]:
    """Sections on a model: equations, measured vs model with residuals, step, Bode, poles.

    Parameters
    ----------
    model : LinearModel
    out : Path
        Folder for the figures ``fit.png``, ``data.png``, ``step.png``, ``bode.png``,
        ``pz.png``.
    data : IOData, optional
        Record to compare the model with (the fit figures are left out without it).
    data_note : str
        Where the compared samples come from (shown under the fit figure).
    data_t0 : float
        Time of ``data``'s first sample in the whole record (the fit figure's time axis).
    summary : mapping, optional
        :func:`model_summary` of ``model`` on ``data``, when the caller has it already.
    draw : Drawing, optional
        Where the figures are drawn (default one after the other, here); a caller that
        gives one waits for it (:meth:`clpc.report.drawing.Drawing.wait`).

    Returns
    -------
    sections : list of Section
    files : list of Path
        The figures (written).
    """
    summary = model_summary(model, data) if summary is None else summary
    files: list[Path] = []
    sections = [
        Section(
            "Model",
            html=model._repr_html_(),
            table=fit_table(summary) if data is not None else None,
        )
    ]
    if data is not None:
        fit_png, data_png = out / FIT_PNG, out / DATA_PNG
        files += [fit_png, data_png]
        sections.append(
            Section(
                "Measured data, model output and residuals",
                text=data_note,
                images=[
                    (fit_png, "measured output, free-run simulation and residual"),
                    (data_png, "the compared record, every channel"),
                ],
            )
        )
    step_png, bode_png, pz_png = out / STEP_PNG, out / BODE_PNG, out / PZ_PNG
    files += [step_png, bode_png, pz_png]
    sections.append(
        Section(
            "Step and frequency response",
            text="Unit step of every channel from rest (offset left out); Bode plot on a "
            "log-spaced grid over three decades up to the Nyquist frequency (dashed).",
            images=[
                (step_png, "step response"),
                (bode_png, "Bode plot"),
                (pz_png, "poles and zeros"),
            ],
        )
    )
    sections.append(
        Section(
            "Model as text (as the command line prints it)",
            preformatted=format_model_summary(summary),
            collapsed=True,
        )
    )
    draw_model_figures(model, out, data=data, data_t0=data_t0, draw=draw)
    return sections, files


def settings_section(settings: Mapping[str, Any]) -> Section:
    """The run's settings as a collapsed table (nested mappings flattened as ``a.b``)."""
    flat: dict[str, Any] = {}

    def add(prefix: str, values: Mapping[str, Any]) -> None:
        for k, v in values.items():
            if isinstance(v, Mapping):
                add(f"{prefix}{k}.", v)
            else:
                flat[f"{prefix}{k}"] = v

    add("", settings)
    if not flat:
        return Section("Settings", text="No settings were recorded.", collapsed=True)
    return Section("Settings", table=flat, collapsed=True)
