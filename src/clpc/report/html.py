"""Summaries of identified models and traces, as plain dicts, text and HTML.

The command line prints what these functions compute, so the same numbers are available from
Python:

* :func:`model_summary` - transfer functions, poles, stability, ``D``, fit % of the free-run
  simulation and of k-step predictions, and the identifiability verdict in plain words;
  :func:`format_model_summary` renders it as text.
* :func:`model_response` - simulated or k-step-predicted output and its fit %.
* :func:`update_records` / :func:`trace_columns` - a CLPC trace as JSON-safe records (one per
  cluster update) or as a named numeric table.
* :func:`write_html_report` - one self-contained HTML file with tables and figures.
"""

from __future__ import annotations

import base64
import html
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from clpc.analysis.metrics import fit_percent
from clpc.appraiser.trace import SCALAR_KEYS, Trace
from clpc.appraiser.tracefile import trace_columns
from clpc.data import IOData
from clpc.model import LinearModel
from clpc.model.verdict import describe_trace, fit_verdict

__all__ = [
    "Section",
    "format_fit",
    "format_model_summary",
    "jsonable",
    "model_response",
    "model_summary",
    "steady_state",
    "trace_columns",
    "trace_summary",
    "update_records",
    "verdict_text",
    "write_html_report",
    "write_track_report",
]


# ===================================================================== numbers -> JSON
def jsonable(x: Any) -> Any:
    """Convert numpy values (recursively) to JSON-safe Python; non-finite floats -> None."""
    if isinstance(x, Mapping):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        v = float(x)
        return v if math.isfinite(v) else None
    if isinstance(x, complex):
        return [jsonable(x.real), jsonable(x.imag)]
    return x


# ===================================================================== models
def verdict_text(model: LinearModel, output: int = 0) -> str | None:
    """The identifiability verdict of one output equation in plain words.

    Uses :func:`clpc.verdict.fit_verdict` on the statistics in ``model.info``
    (``determined``, ``n_null``, ``n_input_relations``...); ``None`` for models without
    them (e.g. a CLPC steady-state model or a hand-built one).
    """
    if not all(k in model.info for k in ("n_null", "n_input_relations", "determined")):
        return None
    return str(fit_verdict(model, output))


def model_response(
    model: LinearModel, u: Any, y: Any, k: int | None = None
) -> tuple[np.ndarray, int, np.ndarray]:
    """Simulated (``k=None``) or ``k``-step-predicted output of a model on measured data.

    Parameters
    ----------
    model : LinearModel
    u : array_like, shape (T, n_inputs)
        Measured inputs.
    y : array_like, shape (T, n_outputs)
        Measured outputs.
    k : int, optional
        Prediction horizon in samples; ``None`` for the free-run simulation.

    Returns
    -------
    y_hat : ndarray, shape (T, n_outputs)
        Model output. The first ``max_lag`` samples have no complete past and are copied
        from ``y``; the free-run simulation starts from those measured samples (initial
        conditions) and then uses the input alone.
    start : int
        First compared sample (``max_lag``).
    fit : ndarray, shape (n_outputs,)
        Fit % over samples ``start:`` (NaN when the simulation diverges).
    """
    u2 = np.asarray(u, dtype=np.float64).reshape(len(u), -1)
    y2 = np.asarray(y, dtype=np.float64).reshape(len(y), -1)
    start = model.structure.max_lag
    if y2.shape[0] <= start + 1:
        raise ValueError(
            f"comparing needs more than {start + 1} samples (the model's max lag is {start}); "
            f"got {y2.shape[0]}."
        )
    if k is None:
        y_hat = y2.copy()
        with np.errstate(over="ignore", invalid="ignore"):
            y_hat[start:] = model.simulate(u2[start:], y_init=y2[:start], u_init=u2[:start])
    else:
        y_hat = np.asarray(model.predict(u2, y2, k=k)).reshape(y2.shape)
        start += k - 1  # only true k-step predictions are scored (as clpc.kstep_fit)
    fit = np.full(y2.shape[1], np.nan)
    for j in range(y2.shape[1]):  # per output: one diverging output leaves the others' fit
        if np.all(np.isfinite(y_hat[start:, j])):
            fit[j] = fit_percent(y2[start:, j], y_hat[start:, j])
    return y_hat, start, fit


def model_summary(
    model: LinearModel, data: IOData | None = None, horizons: Sequence[int] = (1, 10)
) -> dict[str, Any]:
    """Everything worth printing about an identified model, JSON-safe.

    Parameters
    ----------
    model : LinearModel
        The model (monic engineering convention is reported: ``den = A(z)/a0`` with
        ``den[0] = 1``, ``num = -B(z)/a0``, ascending powers of ``z^-1``).
    data : IOData, optional
        Record to evaluate on: fit % of the free-run simulation and of the ``k``-step
        predictions for each ``k`` in ``horizons`` (see :func:`model_response`).
    horizons : sequence of int
        Prediction horizons.

    Returns
    -------
    dict
        Keys ``inputs``, ``outputs``, ``dt``, ``structure``, ``mode``, ``method``,
        ``stable``, ``equations`` (one dict per output: ``den``, ``num`` per input,
        ``intercept``, ``poles`` as ``[re, im]`` pairs, ``stable``, ``D``, ``lambda_min``,
        ``eig_ratio``, ``noise_variance``, ``determined``, ``n_input_relations``,
        ``verdict``) and, with data, ``n_samples`` and ``fit`` (``{"simulation": [...],
        "prediction_1": [...], ...}``, one fit % per output, ``None`` if it diverges).
    """
    s = model.structure
    info = model.info
    dens, nums, icpt = model.denominators, model.numerators, model.intercept

    def stat(key: str, j: int) -> Any:
        return jsonable(np.atleast_1d(info[key])[j]) if key in info else None

    equations = []
    for j in range(model.n_outputs):
        poles = model.poles(j)
        equations.append(
            {
                "output": model.output_names[j],
                "den": jsonable(dens[j]),
                "num": {model.input_names[i]: jsonable(nums[j, i]) for i in range(model.n_inputs)},
                "intercept": jsonable(icpt[j]),
                "poles": [[jsonable(p.real), jsonable(p.imag)] for p in poles],
                "stable": bool(np.all(np.abs(poles) < 1.0)),
                "D": stat("D", j),
                "lambda_min": stat("lambda_min", j),
                "eig_ratio": stat("eig_ratio", j),
                "noise_variance": stat("noise_variance", j),
                "determined": stat("determined", j),
                "n_input_relations": stat("n_input_relations", j),
                "verdict": verdict_text(model, j),
            }
        )
    out: dict[str, Any] = {
        "inputs": list(model.input_names),
        "outputs": list(model.output_names),
        "dt": model.dt,
        "structure": {"na": s.na, "nb": s.nb, "nk": s.nk},
        "mode": model.mode,
        "method": info.get("method"),
        "stable": model.is_stable,
        "equations": equations,
    }
    if data is not None:
        fits: dict[str, Any] = {}
        for k in (None, *horizons):
            _, _, fit = model_response(model, data.u, data.y, k)
            fits["simulation" if k is None else f"prediction_{k}"] = jsonable(fit)
        out["n_samples"] = data.n_samples
        out["fit"] = fits
    return out


def _poly(coefs: Sequence[float], var: str = "z^-1") -> str:
    terms = []
    for i, c in enumerate(coefs):
        if c == 0 and len(coefs) > 1:
            continue
        power = "" if i == 0 else (f" {var}" if i == 1 else f" {var[:-1]}{i}")
        terms.append((c, f"{abs(c):.6g}{power}"))
    if not terms:
        return "0"
    text = ("-" if terms[0][0] < 0 else "") + terms[0][1]
    for c, t in terms[1:]:
        text += (" - " if c < 0 else " + ") + t
    return text


def _fit_label(key: str) -> str:
    return key if key == "simulation" else key.replace("prediction_", "") + "-step prediction"


def format_fit(v: float | None) -> str:
    """A fit % for people: ``"87.29 %"``, ``"-1.2e+34 %"`` or ``"n/a (diverges)"``."""
    if v is None or not math.isfinite(v):
        return "n/a (diverges)"
    return f"{v:.2f} %" if abs(v) < 1e5 else f"{v:.3g} %"


def format_model_summary(summary: Mapping[str, Any]) -> str:
    """Render :func:`model_summary` as readable text (one block per output)."""
    st = summary["structure"]
    lines = [
        f"LPC model  na={st['na']} nb={st['nb']} nk={st['nk']}  method={summary['method']}  "
        f"mode={summary['mode']}  dt={summary['dt']:g} s",
        f"inputs: {', '.join(summary['inputs'])}   outputs: {', '.join(summary['outputs'])}"
        + (f"   samples: {summary['n_samples']}" if "n_samples" in summary else ""),
        "transfer functions G(z) = -B(z)/A(z), monic A, powers of z^-1:",
    ]
    for j, eq in enumerate(summary["equations"]):
        out = eq["output"]
        lines.append(f"  [{out}]  A(z) = {_poly(eq['den'])}")
        for inp, num in eq["num"].items():
            lines.append(f"  [{out}]  {inp} -> {out}:  numerator {_poly(num)}")
        if eq["intercept"]:
            lines.append(f"  [{out}]  offset (intercept) {eq['intercept']:.6g}")
        poles = ", ".join(_fmt_complex(re, im) for re, im in eq["poles"])
        lines.append(f"  [{out}]  poles: {poles}  -> {'stable' if eq['stable'] else 'UNSTABLE'}")
        if eq["D"] is not None:
            lines.append(
                f"  [{out}]  D = lambda_max - lambda_min = {eq['D']:.6g}   lambda_min = "
                f"{eq['lambda_min']:.6g}   lambda_min/lambda_max = {eq['eig_ratio']:.3g}"
            )
        if eq["verdict"] is not None:
            lines.append(f"  [{out}]  identifiability: {eq['verdict']}")
        if "fit" in summary:
            fits = "   ".join(
                f"{_fit_label(key)} {format_fit(vals[j])}" for key, vals in summary["fit"].items()
            )
            lines.append(f"  [{out}]  fit: {fits}")
    lines.append(f"model is {'stable' if summary['stable'] else 'UNSTABLE'}")
    return "\n".join(lines)


def _fmt_complex(re: float, im: float) -> str:
    mag = math.hypot(re, im)
    if abs(im) < 1e-12:
        return f"{re:.5g}"
    return f"{re:.5g}{'+' if im >= 0 else '-'}{abs(im):.5g}j (|p|={mag:.4g})"


# ===================================================================== traces


def update_records(trace: Trace) -> list[dict[str, Any]]:
    """One JSON-safe dict per cluster update of a trace.

    Keys: ``index``, ``time``, ``rows``, ``not_enough_data``, ``theta`` (held parameter
    vector, paper convention), ``den``, ``num`` (monic convention of the held ``theta``),
    ``D``, ``lambda_min``, ``lambda_max``, ``eig_ratio``, ``separation``,
    ``noise_variance``, ``J``, ``c``, ``n_null``, ``n_input_relations``, ``degenerate``,
    ``determined``, ``accepted``, ``has_model``, ``stable``. For single-output traces the
    per-equation values are scalars (``theta`` a list); otherwise one entry per output.
    """
    a = trace.arrays
    single = trace.n_equations == 1
    records = []
    for i in range(len(trace)):
        rec: dict[str, Any] = {
            "index": int(trace.index[i]),
            "time": float(trace.time[i]),
            "rows": int(trace.rows[i]),
            "not_enough_data": bool(trace.not_enough_data[i]),
        }
        for key in ("theta", "den", "num", *SCALAR_KEYS):
            val = a[key][i]
            if key == "num" and single and trace.n_inputs == 1:
                val = val[:, 0]
            rec[key] = jsonable(val[0] if single else val)
        records.append(rec)
    return records


def steady_state(trace: Trace) -> tuple[LinearModel | None, str]:
    """The model a trace settles on, and where it comes from.

    Returns
    -------
    model : LinearModel or None
        :meth:`Trace.steady_state_model` when the trace converged, else the last accepted
        update, else ``None`` (no update was accepted).
    source : str
        ``"steady state"``, ``"last accepted update (not converged)"`` or ``"none"``.
    """
    conv = trace.convergence()
    if conv.converged:
        return trace.steady_state_model(conv), "steady state"
    try:
        model = trace.steady_state_model(conv, allow_unconverged=True)
    except ValueError:
        return None, "none"
    return model, "last accepted update (not converged)"


def trace_summary(trace: Trace) -> dict[str, Any]:
    """Counts, convergence and plain-language findings of a CLPC trace, JSON-safe.

    Returns
    -------
    dict
        ``updates``, ``accepted``, ``determined``, ``not_enough_data`` (update counts; an
        update counts when it holds for every output), ``D_last`` (per output),
        ``convergence`` (the fields of :class:`clpc.Convergence`), ``findings``
        (:func:`clpc.describe_trace`) and ``model`` (:func:`model_summary` of
        :func:`steady_state`, or ``None``) with ``model_source``.
    """
    a = trace.arrays
    conv = trace.convergence()
    model, source = steady_state(trace)
    n = len(trace)
    return {
        "updates": n,
        "accepted": int(a["accepted"].all(axis=1).sum()),
        "determined": int(a["determined"].all(axis=1).sum()),
        "not_enough_data": int(np.sum(trace.not_enough_data)),
        "D_last": jsonable(a["D"][-1]) if n else None,
        "convergence": jsonable(
            {
                "converged": conv.converged,
                "update": conv.update,
                "index": conv.index,
                "time": conv.time,
                "theta_variation": conv.theta_variation,
                "D_variation": conv.D_variation,
            }
        ),
        "findings": describe_trace(trace) if n else [],
        "model_source": source,
        "model": None if model is None else model_summary(model),
    }


# ===================================================================== HTML
@dataclass
class Section:
    """One section of an HTML report.

    Parameters
    ----------
    heading : str
    text : str, optional
        Paragraph text (escaped; blank lines separate paragraphs).
    table : mapping or sequence of rows, optional
        A mapping ``{name: value}`` (two-column table) or rows whose first row is the header.
    images : sequence of path-like
        PNG files to show (embedded as base64, or linked relative to the report).
    preformatted : str, optional
        Text shown verbatim (e.g. a printed model).
    """

    heading: str
    text: str | None = None
    table: Mapping[str, Any] | Sequence[Sequence[Any]] | None = None
    images: Sequence[str | PathLike[str]] = field(default_factory=list)
    preformatted: str | None = None


_CSS = (
    "body{font-family:sans-serif;max-width:60em;margin:2em auto;color:#222}"
    "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;"
    "padding:.25em .6em;text-align:right}th{background:#f3f3f3}td:first-child{text-align:left}"
    "img{max-width:100%;border:1px solid #eee}pre{background:#f8f8f8;padding:.8em;"
    "overflow-x:auto}"
)


def _cell(v: Any) -> str:
    if isinstance(v, (float, np.floating)):
        return html.escape(f"{float(v):.6g}")
    return html.escape(str(v))


def _table_html(table: Mapping[str, Any] | Sequence[Sequence[Any]]) -> str:
    if isinstance(table, Mapping):
        rows = [f"<tr><td>{_cell(k)}</td><td>{_cell(v)}</td></tr>" for k, v in table.items()]
        return "<table>" + "".join(rows) + "</table>"
    rows_in = [list(r) for r in table]
    if not rows_in:
        return ""
    head = "".join(f"<th>{_cell(c)}</th>" for c in rows_in[0])
    body = "".join(
        "<tr>" + "".join(f"<td>{_cell(c)}</td>" for c in row) + "</tr>" for row in rows_in[1:]
    )
    return f"<table><tr>{head}</tr>{body}</table>"


def _image_html(img: Path, report_dir: Path, embed: bool) -> str:
    alt = html.escape(img.stem)
    if embed:
        data = base64.b64encode(img.read_bytes()).decode("ascii")
        return f'<p><img alt="{alt}" src="data:image/png;base64,{data}"></p>'
    try:
        rel = img.resolve().relative_to(report_dir.resolve()).as_posix()
    except ValueError:
        rel = img.resolve().as_uri()
    return f'<p><img alt="{alt}" src="{html.escape(rel)}"></p>'


def write_html_report(
    path: str | PathLike[str],
    title: str,
    sections: Iterable[Section | Mapping[str, Any]],
    *,
    embed_images: bool = True,
) -> Path:
    """Write a self-contained HTML report.

    Parameters
    ----------
    path : str or path-like
        HTML file to write (parent folders are created).
    title : str
        Page title and top heading.
    sections : iterable of Section or mapping
        Sections in order; a mapping takes the :class:`Section` field names.
    embed_images : bool
        Embed the PNGs as base64 (default: the file stands alone) or link them relative to
        the report's folder.

    Returns
    -------
    Path
        The file written.
    """
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
    ]
    for sec in sections:
        sec = sec if isinstance(sec, Section) else Section(**sec)
        parts.append(f"<h2>{html.escape(sec.heading)}</h2>")
        if sec.text:
            parts += [f"<p>{html.escape(p.strip())}</p>" for p in sec.text.split("\n\n")]
        if sec.preformatted:
            parts.append(f"<pre>{html.escape(sec.preformatted)}</pre>")
        if sec.table is not None:
            parts.append(_table_html(sec.table))
        parts += [_image_html(Path(img), out.parent, embed_images) for img in sec.images]
    parts.append("</body></html>")
    out.write_text("\n".join(parts), encoding="utf-8")
    return out


def write_track_report(
    out_dir: str | PathLike[str],
    trace: Trace,
    *,
    title: str = "CLPC report",
    settings: Mapping[str, Any] | None = None,
    summary: Mapping[str, Any] | None = None,
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

    Returns
    -------
    list of Path
        The files written (the report last).
    """
    from clpc.plotting import plot_bode, plot_pz, plot_trace

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
    model, source = steady_state(trace)
    if model is not None:
        files += [plot_pz(model, out / "pz.png"), plot_bode(model, out / "bode.png")]
        sections.append(
            Section(
                f"Model ({source})",
                preformatted=format_model_summary(model_summary(model)),
                images=files[-2:],
            )
        )
    names, values = trace_columns(trace)
    wanted = {"index", "time", "D", "accepted", "determined", *trace.labels()}
    keep = [i for i, n in enumerate(names) if n.split(":")[-1] in wanted]
    rows: list[list[Any]] = [[names[i] for i in keep]]
    rows += [[row[i] for i in keep] for row in values[-20:]]
    sections.append(Section(f"Last {len(rows) - 1} updates", table=rows))
    files.append(write_html_report(out / "report.html", title, sections))
    return files
