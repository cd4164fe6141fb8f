"""The choice among the candidates of :func:`clpc.identify` (rows of its table).

* **Stability first** (:func:`tier`): the candidates whose poles are all strictly inside the
  unit circle at every origin, then those on it, then the unstable ones.
* **Best mean free run**, with one exception: **OE is kept** when the best candidate beats it
  by no more than the standard error of their differences over the origins
  (:func:`oe_margin`; a one-standard-error rule). OE minimises the very free-run error that
  is scored and is consistent under output noise; a lead smaller than its own spread over
  the origins is not evidence against it.
* **Order**: the lowest within :data:`PARSIMONY` points of the best order's mean free run.

Every threshold of these rules lives here.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["PARSIMONY", "best_row", "choose", "oe_lead", "oe_margin", "ranked", "tier"]

#: Points of free-run fit a lower order or a smaller delay may give away.
PARSIMONY = 1.0
_USABLE = ("stable", "integrating")


def tier(row: dict[str, Any]) -> int:
    """0: every pole strictly inside the unit circle (every origin); 1: on it; 2: unstable.

    3: no finite free-run fit.
    """
    if not math.isfinite(row["free_run"]):
        return 3
    if row["max_pole"] < 1.0:
        return 0
    return 1 if row["stability"] in _USABLE else 2


def oe_margin(best: dict[str, Any], oe: dict[str, Any]) -> tuple[float, float]:
    """How far ``best`` leads ``oe``: the mean difference of their free runs and its standard error.

    Over the origins (``row["windows"]``): ``d = best - oe`` per origin, returns
    ``(mean d, std(d, ddof=1) / sqrt(len d))``; ``(nan, nan)`` when a fit diverged.
    """
    d = np.asarray(best["windows"], dtype=float) - np.asarray(oe["windows"], dtype=float)
    if d.size < 2 or not np.all(np.isfinite(d)):
        return math.nan, math.nan
    return float(d.mean()), float(d.std(ddof=1) / math.sqrt(d.size))


def oe_lead(rows: list[dict[str, Any]], i: int) -> tuple[float, float, dict[str, Any]] | None:
    """For a chosen OE row ``i``: the best stable rival's lead, its standard error, the rival.

    (:func:`oe_margin`); ``None`` when no strictly stable rival leads.
    """
    r = rows[i]
    rivals = [
        x
        for x in rows
        if x is not r and x["order"] == r["order"] and x["output"] == r["output"] and tier(x) == 0
    ]
    if r["estimator"] != "oe" or not rivals:
        return None
    top = max(rivals, key=lambda x: x["free_run"])
    if top["free_run"] <= r["free_run"]:
        return None
    return (*oe_margin(top, r), top)


def ranked(rows: list[dict[str, Any]], idx: list[int]) -> list[int]:
    """``idx`` best first (see the module; the first of equals first)."""
    order = sorted(idx, key=lambda i: (tier(rows[i]), -rows[i]["free_run"]))
    oe = [i for i in order if rows[i]["estimator"] == "oe"]
    if not oe or order[0] == oe[0] or tier(rows[oe[0]]) != tier(rows[order[0]]):
        return order
    lead, se = oe_margin(rows[order[0]], rows[oe[0]])
    if lead <= se:  # False for nan
        order.remove(oe[0])
        order.insert(0, oe[0])
    return order


def best_row(rows: list[dict[str, Any]], idx: list[int]) -> tuple[int, bool]:
    """The chosen row among ``idx`` and whether it is strictly stable."""
    top = ranked(rows, idx)[0]
    return top, tier(rows[top]) == 0


def choose(
    rows: list[dict[str, Any]], estimator: str, names: tuple[str, ...]
) -> tuple[int, list[int]]:
    """The chosen order and, per output, the index of the chosen row."""
    orders = sorted({r["order"] for r in rows})
    picks: dict[int, list[int]] = {}
    mean: dict[int, float] = {}
    for n in orders:
        picks[n] = []
        for out in names:
            idx = [
                i
                for i, r in enumerate(rows)
                if r["order"] == n and r["output"] == out and estimator in ("auto", r["estimator"])
            ]
            picks[n].append(best_row(rows, idx)[0])
        mean[n] = float(np.mean([rows[i]["free_run"] for i in picks[n]]))
    finite = [n for n in orders if math.isfinite(mean[n])] or orders
    top = max(mean[n] for n in finite)
    best = (
        min(n for n in finite if not mean[n] < top - PARSIMONY) if math.isfinite(top) else orders[0]
    )
    return best, picks[best]
