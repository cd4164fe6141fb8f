"""The choice of :func:`clpc.identify` in words: per output, what was chosen and why.

Every number the reason gives comes from the candidate table (``Identification.table``),
and every threshold from :mod:`clpc.lpc.choice`: the words match the table.
"""

from __future__ import annotations

from typing import Any

from clpc.lpc.choice import GUARD, oe_lead, pct, tier
from clpc.lpc.comparison import key

__all__ = ["pct", "why"]


def why(
    rows: list[dict[str, Any]],
    choice: tuple[list[int], list[int]],
    estimator: str,
    opts: tuple[int, float],
    names: tuple[str, ...],
) -> str:
    """The choice in words.

    Parameters
    ----------
    rows : list of dict
        The candidate table.
    choice : (list of int, list of int)
        The first picks and those kept after the refits (one row index per output).
    estimator : str
        ``"auto"`` or the estimator asked for.
    opts : (int, float)
        The horizon ``k`` [samples] and ``validation_fraction``.
    names : tuple of str
        The output names.

    Returns
    -------
    str
    """
    k, fraction = opts
    parts = []
    lead = [oe_lead(rows, i) for i in choice[1]]
    for j, (i0, i) in enumerate(zip(*choice, strict=True)):
        r = rows[i]
        what = f"{r['estimator'].upper()} (na {r['na']}, nb {r['nb']}, nk {r['nk']})"
        out = f"output {names[j]}: " if len(names) > 1 else ""
        each = ", ".join(pct(v) for v in r["windows"])
        fits = (
            f"held-out free run {pct(r['free_run'])} (mean over the origins 1/2, 2/3, "
            f"{1 - fraction:.3g}: {each}), {k}-step {pct(r['kstep'])}"
        )
        others = [
            f"{x['estimator'].upper()} {_fmt(x)}"
            for x in rows
            if x is not r and key(x) == key(r) and x["output"] == r["output"]
        ]
        level = tier(r)
        if estimator != "auto":
            how = "as asked"
        elif i != i0:
            how = (
                f"{rows[i0]['estimator'].upper()} did better held out but its refit on the "
                "whole record is unstable; the next best"
            )
        elif level == 0 and (oe := lead[j]) is not None:
            d, se, top = oe
            how = (
                f"OE kept: the best stable held-out free run, {top['estimator'].upper()}'s "
                f"{pct(top['free_run'])}, leads it by {d:.2f} "
                f"points, not more than the standard error of the lead over the origins "
                f"({se:.2f})"
            )
        elif level == 0:
            how = (
                "the best held-out free run among the usable candidates (stable or "
                f"integrating, within {GUARD:g} points of least squares at every origin)"
            )
        elif level == 1:
            how = (
                f"every candidate falls more than {GUARD:g} points below least squares at "
                "some origin; the best of them, not a good model"
            )
        else:
            how = "every candidate is unstable or diverges; the least bad, not a good model"
        rivals = f"; {', '.join(others)}" if others else ""
        parts.append(f"{out}{what}, {how} ({fits}{rivals})")
    unstable = sorted(
        {
            f"{x['estimator'].upper()} na={x['na']} nb={x['nb']} nk={x['nk']}"
            for x in rows
            if x["stability"] == "unstable"
        }
    )
    text = "; ".join(parts)
    return text + (f"; unstable at an origin: {', '.join(unstable)}" if unstable else "")


def _fmt(row: dict[str, Any]) -> str:
    """A candidate's held-out free run in a few characters."""
    if row["stability"] == "no model":
        return "no model"
    return pct(row["free_run"]) + (" (unstable)" if row["stability"] == "unstable" else "")
