"""How a :class:`clpc.LinearModel` shows itself: ``repr``, notebook HTML, scalar statistics.

* :func:`squeeze_info` - per-output statistics of a single-output model as scalars.
* :func:`poly_text` - a polynomial in ``z^-1`` as text (``1 - 1.5 z^-1 + 0.7 z^-2``).
* :func:`model_repr` / :func:`model_html` - the model with its coefficients, as text and as
  an HTML table (``LinearModel.__repr__`` and ``LinearModel._repr_html_``).
"""

from __future__ import annotations

import html
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from clpc.core.polynomials import pole_class, pole_words

__all__ = ["model_html", "model_repr", "poly_text", "squeeze_info"]

_NOWRAP = 'style="white-space:nowrap"'

#: statistics shown beside each equation (when the model has them)
SHOWN_STATS = ("D", "lambda_min", "noise_variance", "determined")


def squeeze_info(info: Mapping[str, Any]) -> dict[str, Any]:
    """Drop the output axis of a single-output model's statistics.

    Parameters
    ----------
    info : mapping
        ``LinearModel.info``: per-output statistics are arrays whose axis 0 is the output.

    Returns
    -------
    dict
        A copy in which every array with an axis 0 of length 1 is replaced by its only
        entry (a Python scalar for 0-d results, e.g. ``info["D"]`` a float,
        ``info["determined"]`` a bool; ``info["eigenvalues"]`` shape (p,)). Other values
        (strings, dicts, already scalar values) are kept.
    """
    out: dict[str, Any] = {}
    for key, value in info.items():
        if isinstance(value, np.ndarray) and value.ndim >= 1 and value.shape[0] == 1:
            first = value[0]
            value = first.item() if np.ndim(first) == 0 else first
        out[key] = value
    return out


def poly_text(coefs: Sequence[float], var: str = "z^-1") -> str:
    """A polynomial in ascending powers of ``var`` as text, zero terms left out.

    >>> poly_text([1.0, -1.5, 0.7])
    '1 - 1.5 z^-1 + 0.7 z^-2'
    """
    terms = []
    for i, c in enumerate(np.asarray(coefs, dtype=float).tolist()):
        if c == 0:
            continue
        power = "" if i == 0 else (f" {var}" if i == 1 else f" {var[:-1]}{i}")
        terms.append((c, f"{abs(c):.6g}{power}"))
    if not terms:
        return "0"
    text = ("-" if terms[0][0] < 0 else "") + terms[0][1]
    for c, t in terms[1:]:
        text += (" - " if c < 0 else " + ") + t
    return text


def _equations(model: Any) -> list[dict[str, Any]]:
    """Per output: name, ``den(z)``, ``{input: num(z)}``, offset, poles, statistics."""
    try:
        dens, nums, icpt = model.denominators, model.numerators, model.intercept
    except ValueError:  # ModelError: a0 about 0, no monic form
        return []
    eqs = []
    for j, out in enumerate(model.output_names):
        stats = {}
        for key in SHOWN_STATS:
            if key in model.info:
                stats[key] = np.atleast_1d(model.info[key])[j].item()
        eqs.append(
            {
                "output": out,
                "den": poly_text(dens[j]),
                "num": {
                    inp: poly_text(nums[j, i])
                    for i, inp in enumerate(model.input_names)
                    if np.any(nums[j, i])
                },
                "offset": float(icpt[j]),
                "poles": np.roots(dens[j]),
                "stats": stats,
            }
        )
    return eqs


def _poly_html(text: str) -> str:
    """A polynomial for HTML: each term kept on one line (no break inside ``z^-1``)."""
    terms = text.replace(" + ", "\0+ ").replace(" - ", "\0- ").split("\0")
    return " ".join(f'<span style="white-space:nowrap">{html.escape(t)}</span>' for t in terms)


def _stat_text(key: str, value: Any) -> str:
    return f"{key}={value}" if isinstance(value, bool) else f"{key}={value:.4g}"


def model_repr(model: Any) -> str:
    """``repr`` of a model: its structure, then one line per transfer function.

    The coefficients are those of the engineering transfer function ``G(z) = num(z)/den(z)``
    (``den = A/a0`` monic, ``num = -z^-nk B/a0`` of the paper's ``theta = [a; b]``; ``y =
    num/den u + offset/den``); a model without a monic form (``a0`` about 0) shows ``theta``
    instead.
    """
    s = model.structure
    head = (
        f"LinearModel(na={s.na}, nb={s.nb}, nk={s.nk}, inputs={model.n_inputs}, "
        f"outputs={model.n_outputs}, mode={model.mode!r}, dt={model.dt:g})"
    )
    eqs = _equations(model)
    if not eqs:
        return head + f"\n  theta = {np.round(model.theta_matrix, 6).tolist()} (a0 about 0)"
    lines = [head]
    for eq in eqs:
        out = eq["output"]
        lines.append(f"  {out}: den(z) = {eq['den']}")
        for inp, num in eq["num"].items():
            lines.append(f"  {inp} -> {out}: num(z) = {num}")
        if eq["offset"]:
            lines.append(f"  {out}: offset {eq['offset']:.6g}")
        if eq["stats"]:
            lines.append(f"  {out}: " + "  ".join(_stat_text(k, v) for k, v in eq["stats"].items()))
    words = _stability_words(model)
    lines.append(f"  ({words}; G(z) = num(z)/den(z) = -B(z)/A(z), powers of z^-1)")
    return "\n".join(lines)


def _stability_words(model: Any) -> str:
    """The stability in words (:func:`clpc.core.polynomials.pole_words`)."""
    try:
        return pole_words(model.stability)
    except (ValueError, np.linalg.LinAlgError):  # no poles (a0 = 0)
        return "no poles"


def model_html(model: Any) -> str:
    """An HTML table of a model for notebooks: one row per transfer function."""
    s = model.structure
    esc = html.escape
    cap = (
        f"LinearModel na={s.na} nb={s.nb} nk={s.nk}, mode {esc(str(model.mode))}, "
        f"dt {model.dt:g}" + (" s" if model.dt != 1.0 else " (samples)")
    )
    eqs = _equations(model)
    rows = []
    for eq in eqs:
        poles = ", ".join(
            f'<span style="white-space:nowrap">{p.real:.4g}</span>'
            if p.imag == 0
            else f'<span style="white-space:nowrap">{p:.4g}</span>'
            for p in eq["poles"]
        )
        kind = pole_class(eq["poles"])
        stable = "yes" if kind == "stable" else f"<b>{esc(pole_words(kind))}</b>"
        stats = "<br>".join(
            f"<span {_NOWRAP}>{esc(_stat_text(k, v))}</span>" for k, v in eq["stats"].items()
        )
        for inp, num in eq["num"].items():
            rows.append(
                f"<tr><td>{esc(inp)} &rarr; {esc(eq['output'])}</td><td>{_poly_html(num)}</td>"
                f"<td>{_poly_html(eq['den'])}</td><td {_NOWRAP}>{eq['offset']:.6g}</td>"
                f"<td>{poles}</td><td>{stable}</td>"
                f"<td>{stats or '&ndash;'}</td></tr>"
            )
    head = (
        "<tr><th>channel</th><th>num(z)</th><th>den(z)</th><th>offset</th><th>poles</th>"
        "<th>stable</th><th>statistics</th></tr>"
    )
    if not eqs:
        body = f"<tr><td colspan='7'>theta = {esc(str(model.theta_matrix.tolist()))}</td></tr>"
        return f"<table><caption>{esc(cap)}</caption>{head}{body}</table>"
    return f"<table><caption>{esc(cap)}</caption>{head}{''.join(rows)}</table>"
