"""The choice among the candidates of :func:`clpc.identify` (rows of its table).

* **Usable first** (:func:`tier`): the candidates with a finite held-out free run, no pole
  beyond the integrator tolerance (:data:`clpc.lpc.heldout.UNIT_CIRCLE_TOL`: a pole at
  1.002 and one at 0.998 are the same integrator, ranked by their scores, not by which side
  of 1 they landed) and no origin where the free run falls more than :data:`GUARD` points
  below the **reference** (the least-squares ARX of the structure screen's choice at that
  origin). Then the candidates that fall below the reference somewhere, then the unstable,
  then those without a finite free run. A catastrophic candidate (a good mean made of one
  origin at 90 % and one at -1475 %) is never chosen while a usable one exists.
* **Best mean free run**, with one exception: **OE is kept** when the best candidate beats it
  by no more than the standard error of their differences over the origins
  (:func:`oe_margin`; a one-standard-error rule). OE minimises the very free-run error that
  is scored and is consistent under output noise; a lead smaller than its own spread over
  the origins is not evidence against it.
* **Structure**: among structures (``na, nb, nk``; the outputs' picks averaged) of the best
  tier, the fewest parameters within :data:`PARSIMONY` points of the best mean free run.

Every threshold of these rules lives here.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from clpc.lpc.heldout import UNIT_CIRCLE_TOL

__all__ = [
    "GUARD",
    "PARSIMONY",
    "best_row",
    "choose",
    "guarded",
    "oe_lead",
    "oe_margin",
    "pct",
    "ranked",
    "tier",
]

#: Points of free-run fit a structure with fewer parameters may give away.
PARSIMONY = 1.0
#: Points below the reference's free run, at any one origin, that disqualify a candidate.
GUARD = 50.0


def tier(row: dict[str, Any]) -> int:
    """0: usable; 1: below the reference at some origin; 2: unstable; 3: no finite free run.

    Usable: every origin's free run finite, no pole beyond ``1 + UNIT_CIRCLE_TOL`` and
    ``row["guard"]`` (set by :func:`guarded`) not ``False``.
    """
    if not (math.isfinite(row["free_run"]) and np.all(np.isfinite(row["windows"]))):
        return 3
    if not row["max_pole"] <= 1.0 + UNIT_CIRCLE_TOL:
        return 2
    return 1 if row.get("guard") is False else 0


def guarded(rows: list[dict[str, Any]], reference: dict[str, list[float]]) -> None:
    """Mark each row's ``guard``: within :data:`GUARD` points of the reference at every origin.

    Parameters
    ----------
    rows : list of dict
        Candidate rows (``output``, ``windows``); each gets ``guard`` (bool) and, when it
        fails, a ``note`` with the origin and the two fits.
    reference : dict
        Per output name, the reference's free-run fit % at each origin.
    """
    for row in rows:
        ref = np.asarray(reference[row["output"]], dtype=float)
        own = np.asarray(row["windows"], dtype=float)
        with np.errstate(invalid="ignore"):
            low = own < ref - GUARD
        row["guard"] = not bool(np.any(low))
        if low.any():
            o = int(np.argmax(low))
            row["note"] = (
                f"origin {o + 1}: free run {pct(own[o])}, more than {GUARD:g} points below "
                f"the least-squares reference's {pct(ref[o])}: not chosen"
            )


def pct(value: float) -> str:
    """A fit % for people: ``84.2 %``, ``-3.1e+05 %`` or ``diverges``.

    Parameters
    ----------
    value : float
        Fit [%].

    Returns
    -------
    str
    """
    if not math.isfinite(value):
        return "diverges"
    return f"{value:.1f} %" if abs(value) < 1e4 else f"{value:.1e} %"


def oe_margin(best: dict[str, Any], oe: dict[str, Any]) -> tuple[float, float]:
    """How far ``best`` leads ``oe``: the mean difference of their free runs and its standard error.

    Over the origins (``row["windows"]``): ``d = best - oe`` per origin, returns
    ``(mean d, std(d, ddof=1) / sqrt(len d))``; ``(nan, nan)`` when a fit diverged.
    """
    d = np.asarray(best["windows"], dtype=float) - np.asarray(oe["windows"], dtype=float)
    if d.size < 2 or not np.all(np.isfinite(d)):
        return math.nan, math.nan
    return float(d.mean()), float(d.std(ddof=1) / math.sqrt(d.size))


def _same(a: dict[str, Any], b: dict[str, Any]) -> bool:
    """Same structure and output."""
    return all(a.get(f) == b.get(f) for f in ("na", "nb", "nk", "output"))


def oe_lead(rows: list[dict[str, Any]], i: int) -> tuple[float, float, dict[str, Any]] | None:
    """For a chosen OE row ``i``: the best usable rival's lead, its standard error, the rival.

    (:func:`oe_margin`, same structure and output); ``None`` when no usable rival leads.
    """
    r = rows[i]
    rivals = [x for x in rows if x is not r and _same(x, r) and tier(x) == 0]
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
    """The chosen row among ``idx`` and whether it is usable (tier 0)."""
    top = ranked(rows, idx)[0]
    return top, tier(rows[top]) == 0


def choose(
    rows: list[dict[str, Any]], estimator: str, names: tuple[str, ...]
) -> tuple[tuple[int, int, int], list[int]]:
    """The chosen structure ``(na, nb, nk)`` and, per output, the index of the chosen row.

    Parameters
    ----------
    rows : list of dict
        The candidates (``estimator``, ``na``, ``nb``, ``nk``, ``n_params``, ``output``, ...).
    estimator : str
        ``"auto"`` or the one estimator to keep.
    names : tuple of str
        The output names.

    Returns
    -------
    structure : tuple of int
    picks : list of int
        One row index per output.
    """
    keys = sorted({(r["na"], r["nb"], r["nk"]) for r in rows})
    picks: dict[tuple[int, int, int], list[int]] = {}
    rank: dict[tuple[int, int, int], tuple[int, float, int]] = {}
    for key in keys:
        picks[key] = []
        for out in names:
            idx = [
                i
                for i, r in enumerate(rows)
                if (r["na"], r["nb"], r["nk"]) == key
                and r["output"] == out
                and estimator in ("auto", r["estimator"])
            ]
            if idx:
                picks[key].append(best_row(rows, idx)[0])
        if len(picks[key]) < len(names):
            del picks[key]
            continue
        chosen = [rows[i] for i in picks[key]]
        mean = float(np.mean([r["free_run"] for r in chosen]))
        rank[key] = (max(tier(r) for r in chosen), mean, int(chosen[0]["n_params"]))
    if not rank:
        raise ValueError(f"no candidate of the estimator {estimator!r} in the table.")
    best_tier = min(t for t, _, _ in rank.values())
    pool = [key for key in rank if rank[key][0] == best_tier]
    top = max(rank[key][1] for key in pool)
    if math.isfinite(top):
        pool = [key for key in pool if not rank[key][1] < top - PARSIMONY]
    best = min(pool, key=lambda key: (rank[key][2], -rank[key][1]))
    return best, picks[best]
