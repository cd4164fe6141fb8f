"""Candidates of :func:`clpc.identify` fitted and scored in two folds, and the choice among them.

See :mod:`clpc.lpc.selection` for the rules; every threshold of them lives here.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from clpc.data import DataError, IOData
from clpc.lpc import heldout
from clpc.lpc.arx import ARX
from clpc.lpc.estimator import LPC
from clpc.lpc.oe import OE
from clpc.model import LinearModel, ModelError

__all__ = [
    "MAKERS",
    "PARSIMONY",
    "best_row",
    "candidate",
    "choose",
    "choose_delay",
    "fold_fits",
    "grid",
    "tier",
]

#: Points of free-run fit a lower order or a smaller delay may give away.
PARSIMONY = 1.0
MAKERS = {"lpc": LPC, "arx": ARX, "oe": OE}
_USABLE = ("stable", "integrating")


def fold_fits(model: LinearModel, seg: IOData, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Free-run and ``k``-step fit % per output of ``model`` on ``seg``."""
    s = model.structure
    start, n_lag = s.max_lag, s.nk + s.nb
    with np.errstate(all="ignore"):
        sim = np.asarray(
            model.simulate(
                seg.u[start:],
                y_init=seg.y[start - s.na : start],
                u_init=seg.u[start - n_lag : start] if n_lag else None,
            )
        ).reshape(-1, model.n_outputs)
        pred = np.asarray(model.predict(seg.u, seg.y, k=k)).reshape(seg.y.shape)
    first = start + k - 1
    free = [heldout.fit_percent(seg.y[start:, j], sim[:, j]) for j in range(seg.n_outputs)]
    kst = [heldout.fit_percent(seg.y[first:, j], pred[first:, j]) for j in range(seg.n_outputs)]
    return np.array(free), np.array(kst)


def candidate(
    name: str, order: int, nk: int, mimo: str | None, where: tuple[list[Any], int]
) -> list[dict[str, Any]]:
    """One candidate fitted and scored in every fold: one row per output."""
    folds, k = where
    n_out = folds[0][0].n_outputs
    base = {"estimator": name, "order": order, "nk": nk}
    free, kst, note = np.zeros(n_out), np.zeros(n_out), ""
    radius = np.zeros(n_out)
    try:
        for est, val in folds:
            model = MAKERS[name](order=order, nk=nk, mimo=mimo).fit(est)
            radius = np.maximum(radius, [np.max(np.abs(model.poles(j))) for j in range(n_out)])
            f, p = fold_fits(model, val, k)
            free, kst = free + f / len(folds), kst + p / len(folds)
    except (ModelError, DataError, np.linalg.LinAlgError) as exc:
        free, kst, note = np.full(n_out, -math.inf), np.full(n_out, -math.inf), str(exc)
        radius = np.full(n_out, math.nan)
    names = folds[0][0].output_names
    return [
        base
        | {"output": names[j], "free_run": float(free[j]), "kstep": float(kst[j])}
        | {"stability": _stability(float(radius[j])), "max_pole": float(radius[j])}
        | {"chosen": False, "note": note}
        for j in range(n_out)
    ]


def _stability(radius: float) -> str:
    """The words of :func:`clpc.lpc.heldout.stability` for a largest pole radius."""
    if math.isnan(radius):
        return "no model"
    if radius > 1.0 + heldout.UNIT_CIRCLE_TOL:
        return "unstable"
    return "integrating" if radius >= 1.0 - heldout.UNIT_CIRCLE_TOL else "stable"


def tier(row: dict[str, Any]) -> int:
    """0: every pole strictly inside the unit circle (both folds); 1: on it; 2: unstable.

    3: no finite free-run fit.
    """
    if not math.isfinite(row["free_run"]):
        return 3
    if row["max_pole"] < 1.0:
        return 0
    return 1 if row["stability"] in _USABLE else 2


def best_row(rows: list[dict[str, Any]], idx: list[int]) -> tuple[int, bool]:
    """The chosen row among ``idx`` (see the module) and whether it is strictly stable."""
    level = min(tier(rows[i]) for i in idx)
    pool = [i for i in idx if tier(rows[i]) == level]
    top = max(pool, key=lambda i: rows[i]["free_run"])  # the first of equals
    return top, level == 0


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


def grid(
    folds: list[Any], orders: list[int], nk: int, opts: tuple[str | None, int]
) -> list[dict[str, Any]]:
    """Rows of every estimator and order at delay ``nk`` (:func:`candidate`)."""
    mimo, k = opts
    return [
        row
        for name in ("lpc", "arx", "oe")
        for n in orders
        for row in candidate(name, n, nk, mimo, (folds, k))
    ]


def choose_delay(
    folds: list[Any], orders: list[int], delays: list[int], opts: tuple[str | None, int]
) -> tuple[int, list[dict[str, Any]], list[dict[str, Any]]]:
    """The delay chosen (see :mod:`clpc.lpc.selection`), the scan and the chosen rows."""
    scan, tables = [], {}
    for nk in delays:
        rows = tables[nk] = grid(folds, orders, nk, opts)
        outs = sorted({r["output"] for r in rows})
        best = [
            best_row(rows, [i for i, r in enumerate(rows) if r["output"] == o])[0] for o in outs
        ]
        scan.append({"nk": nk, "free_run": float(np.mean([rows[i]["free_run"] for i in best]))})
    chosen = int(max(scan, key=lambda r: r["free_run"])["nk"])  # the first of equals
    return chosen, scan, tables[chosen]
