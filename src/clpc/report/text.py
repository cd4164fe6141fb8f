"""Model summaries and fit values as text for people (what the command line prints)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from clpc.core.polynomials import pole_words
from clpc.model.display import poly_text
from clpc.report.identifiability import lead_lines

__all__ = ["estimator_name", "format_fit", "format_model_summary"]

#: The estimator behind each ``info["method"]`` of a fitted model.
_ESTIMATORS = {
    "robust": "LPC",
    "paper": "LPC",
    "least-squares": "ARX (least squares)",
    "output-error": "OE (output error)",
    "subspace": "subspace (PO-MOESP)",
    "clpc-steady-state": "CLPC",
    "multimodel-linearization": "multi-model linearization",
}


def _fit_label(key: str) -> str:
    return key if key == "simulation" else key.replace("prediction_", "") + "-step prediction"


def format_fit(v: float | None) -> str:
    """A fit % for people: ``"87.29 %"``, ``"-1.2e+34 %"`` or ``"n/a (diverges)"``.

    Parameters
    ----------
    v : float or None
        Fit [%]; ``None`` or non-finite when the model diverges.

    Returns
    -------
    str
    """
    if v is None or not math.isfinite(v):
        return "n/a (diverges)"
    return f"{v:.2f} %" if abs(v) < 1e5 else f"{v:.3g} %"


def estimator_name(summary: Mapping[str, Any]) -> str:
    """The estimator that produced the model, from ``summary["method"]`` (and ``estimators``).

    ``"LPC"``, ``"ARX (least squares)"``, ``"OE (output error)"``, ``"subspace (PO-MOESP)"``,
    ``"CLPC"``, ``"identify: OE, ARX"`` (one estimator per output), else ``"linear"``.
    """
    method = summary.get("method")
    if method == "identify":
        names = [str(e).upper() for e in summary.get("estimators") or []]
        return "identify: " + ", ".join(names) if names else "identify"
    return _ESTIMATORS.get(str(method), "linear")


def format_model_summary(summary: Mapping[str, Any], lead: bool = True) -> str:
    """Render :func:`model_summary` as readable text (one block per output).

    What the record cannot decide comes first (the identifiability headline of each output
    it does not identify); each output's block gives its DC gains +- one sigma and its
    dominant poles, and its verdict one finding per line.

    Parameters
    ----------
    summary : mapping
        Output of :func:`clpc.report.model_summary` (with or without data).
    lead : bool
        Open with the identifiability headlines (default); ``False`` when the caller has
        printed them already (``clpc identify`` prints them before its tables).

    Returns
    -------
    str
        Several lines, no trailing newline.
    """
    st = summary["structure"]
    lines = lead_lines(summary) if lead else []
    lines += [
        f"{estimator_name(summary)} model  na={st['na']} nb={st['nb']} nk={st['nk']}  "
        f"method={summary['method']}  "
        f"scaling={summary.get('scaling')}  mode={summary['mode']}  dt={summary['dt']:g} s"
        + (
            f"  ({summary['cancelled']} common pole/zero factor(s) cancelled)"
            if summary.get("cancelled")
            else ""
        ),
        f"inputs: {', '.join(summary['inputs'])}   outputs: {', '.join(summary['outputs'])}"
        + (f"   samples: {summary['n_samples']}" if "n_samples" in summary else ""),
        "transfer functions G(z) = num(z)/den(z) = -B(z)/A(z), den monic, powers of z^-1 "
        "(A, B: the paper's theta = [a; b]):",
    ]
    for j, eq in enumerate(summary["equations"]):
        out = eq["output"]
        lines.append(f"  [{out}]  den(z) = {poly_text(eq['den'])}")
        for inp, num in eq["num"].items():
            lines.append(f"  [{out}]  {inp} -> {out}:  num(z) = {poly_text(num)}")
        if eq["intercept"]:
            lines.append(f"  [{out}]  offset (intercept) {eq['intercept']:.6g}")
        for gain in eq.get("dc_gain", ()):
            lines.append(f"  [{out}]  DC gain {gain['input']} -> {out}: {gain['text']}")
        poles = ", ".join(_fmt_complex(re, im) for re, im in eq["poles"])
        lines.append(f"  [{out}]  poles: {poles}  -> {_stability(eq)}")
        if eq.get("dominant_poles"):
            slow = "; ".join(p["text"] for p in eq["dominant_poles"])
            lines.append(f"  [{out}]  dominant poles: {slow}")
        if eq["D"] is not None:
            lines.append(
                f"  [{out}]  D = lambda_max - lambda_min = {eq['D']:.6g}   lambda_min = "
                f"{eq['lambda_min']:.6g}   lambda_min/lambda_max = {eq['eig_ratio']:.3g}"
            )
        if eq.get("parameters") and eq["parameters"][0]["std"] is not None:
            pars = ", ".join(
                f"{p['name']} {p['value']:.6g} +- {p['std']:.2g}"
                for p in eq["parameters"]
                if p["std"] or p["value"]
            )
            lines.append(f"  [{out}]  parameters (+- 1 sigma): {pars}")
        if eq["verdict"] is not None:
            first, *more = str(eq["verdict"]).split("\n")
            lines.append(f"  [{out}]  verdict: {first}")
            lines.extend(f"  [{out}]           {m}" for m in more)
        if "fit" in summary:
            fits = "   ".join(
                f"{_fit_label(key)} {format_fit(vals[j])}" for key, vals in summary["fit"].items()
            )
            lines.append(f"  [{out}]  fit: {fits}")
    if "residual_test" in summary:
        lines.append(
            "residual tests (whiteness: Ljung-Box Q; independence from the inputs: zeta) "
            + {True: "passed", False: "FAILED", None: "not computed"}[
                summary["residual_test"]["passed"]
            ]
        )
        lines.extend(f"  {t}" for t in summary["residual_test"]["tests"])
    lines.append(f"model is {_stability(summary)}")
    return "\n".join(lines)


def _stability(entry: Mapping[str, Any]) -> str:
    """``stable``, ``integrating (pole at z = 1)``, ... (``UNSTABLE`` for older summaries)."""
    kind = entry.get("stability")
    if kind is None:
        return "stable" if entry["stable"] else "UNSTABLE"
    return pole_words(kind)


def _fmt_complex(re: float, im: float) -> str:
    mag = math.hypot(re, im)
    if abs(im) < 1e-12:
        return f"{re:.5g}"
    return f"{re:.5g}{'+' if im >= 0 else '-'}{abs(im):.5g}j (|p|={mag:.4g})"
