"""A CLPC trace as JSON-safe data: its updates, the model it settles on, its summary.

* :func:`update_records` - a CLPC trace as JSON-safe records (one per cluster update).
* :func:`steady_state` / :func:`trace_summary` - the model a trace settles on, and the
  trace's counts, convergence and findings (the model through
  :func:`clpc.report.summaries.model_summary`).
"""

from __future__ import annotations

from typing import Any

from clpc.appraiser.convergence import Convergence
from clpc.appraiser.scanned import ScannedTrace
from clpc.appraiser.trace import SCALAR_KEYS, Trace
from clpc.core.jsonable import jsonable
from clpc.model import LinearModel
from clpc.report.summaries import model_summary

__all__ = ["steady_state", "trace_summary", "update_records"]


def update_records(trace: Trace) -> list[dict[str, Any]]:
    """One JSON-safe dict per cluster update of a trace.

    Keys: ``index``, ``time``, ``rows``, ``not_enough_data``, ``theta`` (held parameter
    vector, paper convention), ``den``, ``num`` (monic convention of the held ``theta``),
    ``D``, ``lambda_min``, ``lambda_max``, ``eig_ratio``, ``separation``,
    ``noise_variance``, ``J``, ``c``, ``n_null``, ``n_input_relations``, ``degenerate``,
    ``determined``, ``accepted``, ``has_model``, ``stable``. For single-output traces the
    per-equation values are scalars (``theta`` a list); otherwise one entry per output.

    Parameters
    ----------
    trace : Trace
        A CLPC trace (:class:`clpc.Trace`).

    Returns
    -------
    list of dict
        One per update, in order.
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


def steady_state(
    trace: Trace | ScannedTrace, convergence: Convergence | None = None
) -> tuple[LinearModel | None, str]:
    """The model a trace settles on, and where it comes from.

    Parameters
    ----------
    trace : Trace or ScannedTrace
        A CLPC trace (:class:`clpc.Trace`), or one read in parts; convergence is judged
        with the default tolerances of :meth:`Trace.convergence`.
    convergence : Convergence, optional
        That convergence when already known (it is not searched again).

    Returns
    -------
    model : LinearModel or None
        :meth:`Trace.steady_state_model` when the trace converged, else the last accepted
        update, else ``None`` (no update was accepted).
    source : str
        ``"steady state"``, ``"last accepted update (not converged)"`` or ``"none"``.
    """
    conv = trace.convergence() if convergence is None else convergence
    if conv.converged:
        return trace.steady_state_model(conv), "steady state"
    try:
        model = trace.steady_state_model(conv, allow_unconverged=True)
    except ValueError:
        return None, "none"
    return model, "last accepted update (not converged)"


def trace_summary(trace: Trace | ScannedTrace) -> dict[str, Any]:
    """Counts, convergence and plain-language findings of a CLPC trace, JSON-safe.

    Parameters
    ----------
    trace : Trace or ScannedTrace
        A CLPC trace (:class:`clpc.Trace`), or one read in parts
        (:class:`clpc.appraiser.scanned.ScannedTrace`: the same numbers in bounded memory);
        convergence is judged with the default tolerances of :meth:`Trace.convergence`.

    Returns
    -------
    dict
        ``updates``, ``accepted``, ``determined``, ``not_enough_data`` (update counts; an
        update counts when it holds for every output), ``D_last`` (per output),
        ``convergence`` (the fields of :class:`clpc.Convergence`), ``findings``
        (:func:`clpc.describe_trace`) and ``model`` (:func:`model_summary` of
        :func:`steady_state`, or ``None``) with ``model_source``.
    """
    scan = trace if isinstance(trace, ScannedTrace) else ScannedTrace.of(trace)
    conv = scan.convergence()
    model, source = steady_state(trace, conv)
    counts, n = scan.counts, len(scan)
    return {
        "updates": n,
        "accepted": counts["accepted"],
        "determined": counts["determined"],
        "not_enough_data": counts["not_enough_data"],
        "D_last": jsonable(scan.D_last) if n else None,
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
        "findings": scan.findings.lines() if n else [],
        "model_source": source,
        "model": None if model is None else model_summary(model),
    }
