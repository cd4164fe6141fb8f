"""What the record decides about a model, JSON-safe and as the lines that lead a printout.

:func:`identifiability_summary` is the part of :func:`clpc.report.model_summary` that an
engineer reads first: per output the DC gains with their standard deviation
(:func:`clpc.assess_gain`), the dominant poles in rad/s, Hz, damping and time constants
(:func:`clpc.dominant_poles`) and the identifiability findings
(:func:`clpc.model.identifiability.identifiability`). :func:`lead_lines` are the headlines
``clpc identify`` and the reports print before anything else.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from clpc.core.jsonable import jsonable
from clpc.model import LinearModel
from clpc.model.dominant import dominant_poles
from clpc.model.identifiability import identifiability

__all__ = ["identifiability_summary", "lead_lines"]


def identifiability_summary(model: LinearModel, output: int = 0) -> dict[str, Any]:
    """What the record decides about one output, JSON-safe (engineer's quantities first).

    Parameters
    ----------
    model : LinearModel
        A fitted model.
    output : int
        Output index (default 0).

    Returns
    -------
    dict
        ``dc_gain``: one entry per input (``input``, ``gain``, ``std`` [output units per
        input unit; ``None`` when there is no sigma, ``note`` says why], ``determined``,
        ``note``, ``value`` (``"0.891 ± 0.031"``), ``text`` (with the judgement);
        :func:`clpc.assess_gain`); ``dominant_poles``: up to three
        (``re``, ``im``, ``magnitude``, ``kind``, ``natural_frequency`` [rad/s],
        ``frequency_hz``, ``damping``, ``time_constant`` [s], ``text``;
        :func:`clpc.dominant_poles`); ``identifiability``: ``identifiable``,
        ``excitation_order``, ``needed_order``, ``excitation_ratio``, ``threshold`` and the
        ``findings`` that lead the verdict (empty when identifiable).
    """
    ident = identifiability(model, output)
    gains = [
        {"input": g.input, "gain": g.gain, "std": g.std, "determined": g.determined,
         "note": g.note, "value": g.value, "text": g.text}
        for g in ident.gains
    ]  # fmt: skip
    poles = [
        {"re": p.pole.real, "im": p.pole.imag, "magnitude": abs(p.pole), "kind": p.kind,
         "natural_frequency": p.natural_frequency, "frequency_hz": p.frequency_hz,
         "damping": p.damping, "time_constant": p.time_constant, "text": p.text}
        for p in dominant_poles(model, output)
    ]  # fmt: skip
    found = {
        "identifiable": ident.identifiable,
        "excitation_order": ident.excitation_order,
        "needed_order": ident.needed_order,
        "excitation_ratio": ident.excitation_ratio,
        "threshold": ident.threshold,
        "findings": ident.messages(model.structure),
    }
    return jsonable({"dc_gain": gains, "dominant_poles": poles, "identifiability": found})


def lead_lines(summary: Mapping[str, Any]) -> list[str]:
    """The identifiability headline of every output the record does not identify.

    Parameters
    ----------
    summary : mapping
        :func:`clpc.report.model_summary` (a summary without ``identifiability`` entries,
        e.g. of an older file, gives none).

    Returns
    -------
    list of str
        ``"NOT identifiable from this record: ..."`` per such output (prefixed ``[name]``
        when the model has several outputs); empty when every output is identified.
    """
    many = len(summary.get("equations", ())) > 1
    out = []
    for eq in summary.get("equations", ()):
        findings = (eq.get("identifiability") or {}).get("findings") or []
        if findings:
            out.append(f"[{eq['output']}] {findings[0]}" if many else findings[0])
    return out
