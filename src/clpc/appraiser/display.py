"""How a :class:`clpc.Trace` shows itself in a notebook (``Trace._repr_html_``)."""

from __future__ import annotations

import html
from typing import Any

import numpy as np

from clpc.model.verdict import describe_trace

__all__ = ["trace_html"]


def trace_html(trace: Any) -> str:
    """An HTML summary of a trace: counts, convergence, findings, the steady-state model.

    Parameters
    ----------
    trace : Trace

    Returns
    -------
    str
        A ``<div>`` with a table (updates, accepted, determined, converged and where),
        the plain-language findings of :func:`clpc.describe_trace` and, when the trace
        converged, the steady-state model's table.
    """
    n = len(trace)
    esc = html.escape
    arr = trace.arrays
    unit = "s" if trace.sample_time != 1.0 else "samples"
    rows: list[tuple[str, Any]] = [
        ("inputs → outputs", f"{', '.join(trace.input_names)} → {', '.join(trace.output_names)}"),
        ("cluster updates", n),
        ("accepted", int(arr["accepted"].all(axis=1).sum())),
        ("determined", int(arr["determined"].all(axis=1).sum())),
    ]
    model_html = ""
    if n:
        conv = trace.convergence()
        rows.append(("converged", "yes" if conv.converged else "no"))
        if conv.converged:
            rows.append((f"converged at [{unit}]", f"{conv.time:.6g}"))
            model_html = trace.steady_state_model(conv)._repr_html_()
    body = "".join(
        f"<tr><th style='text-align:left'>{esc(k)}</th>"
        f"<td style='text-align:right;white-space:nowrap'>{esc(str(v))}</td></tr>"
        for k, v in rows
    )
    findings = "".join(f"<li>{esc(f)}</li>" for f in (describe_trace(trace) if n else []))
    s = trace.structure
    cap = f"CLPC Trace na={s.na} nb={s.nb} nk={s.nk}, mode {esc(str(trace.mode))}"
    span = ""
    if n:
        t0, t1 = np.asarray(trace.time)[[0, -1]]
        span = f"<p>updates from {t0:.6g} to {t1:.6g} {unit}</p>"
    return (
        f"<div><table><caption>{cap}</caption>{body}</table>{span}"
        f"<ul>{findings}</ul>{model_html}</div>"
    )
