"""The order of :mod:`clpc.lpc.subspace` (``order="auto"``): singular-value gaps, held-out fit.

The gaps ``s_n / s_(n+1)`` of the singular values of ``L32`` rank the orders; the orders
around the :data:`GAPS` largest (every order when none reaches :data:`CLEAR_GAP`) are each
fitted on the first part of the record and scored by the free-run fit % on the rest; the
lowest within :data:`PARSIMONY` points of the best is the order.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from clpc.lpc.subspace_bd import BDFit, fit_bd, free_run, initial_state
from clpc.lpc.subspace_dynamics import StateDynamics
from clpc.lpc.subspace_projection import Projections
from clpc.lpc.subspace_record import ScaledRecord

__all__ = ["CLEAR_GAP", "GAPS", "PARSIMONY", "choose_order"]

#: Points of held-out free-run fit a higher order must gain over a lower one (as
#: :data:`clpc.lpc.reduction.KEEP_FIT_POINTS` and ``identify``'s parsimony).
PARSIMONY = 1.0
#: How many of the largest singular-value gaps have their orders checked on held-out data.
GAPS = 2
#: A gap ``s_n / s_(n+1)`` at least this large is clear; without one every order is checked.
CLEAR_GAP = 10.0


def choose_order(
    rec: ScaledRecord,
    first: list[tuple[int, int]],
    projections: Projections,
    s_full: np.ndarray,
    n_max: int,
    horizon: Callable[[int], int],
    stable: bool,
    feedthrough: bool,
    split: int,
) -> tuple[int, str, dict[str, float]]:
    """The order by the singular-value gaps, checked on held-out data (see the module).

    ``projections`` are of the first part; each candidate ``n`` is fitted there at its own
    horizon ``horizon(n)`` (what ``Subspace(order=n)`` would use).

    Parameters
    ----------
    rec : ScaledRecord
        The whole record.
    first : list of (int, int)
        Its first part, the candidates' fit (:meth:`ScaledRecord.segments` before ``split``).
    projections : Projections
        The projections of ``first``.
    s_full : numpy.ndarray, shape (i l,)
        Singular values of ``L32`` over the whole record, descending.
    n_max : int
        Largest order considered.
    horizon : callable
        Block rows of a candidate order on ``first``.
    stable, feedthrough : bool
        The settings of :class:`clpc.lpc.subspace.Subspace`.
    split : int
        First held-out sample (index into the whole record).

    Returns
    -------
    order : int
        The order chosen.
    reason : str
        Why, in words.
    scores : dict of str to float
        Held-out free-run fit % of each candidate order (``-inf``: diverged or failed).
    """
    top = min(n_max, s_full.size - 1)
    floor = s_full[0] * np.finfo(float).eps if s_full.size and s_full[0] > 0 else 1e-300
    s = np.maximum(s_full[: top + 1], floor)
    gaps = np.log(s[:-1] / s[1:])  # gaps[n-1]: s_n / s_(n+1)
    ranked = [int(g) + 1 for g in np.argsort(-gaps, kind="stable")[:GAPS]]
    clear = bool(gaps[ranked[0] - 1] >= math.log(CLEAR_GAP))
    candidates = sorted({o for n in ranked for o in (n - 1, n, n + 1) if 1 <= o <= top})
    if not clear:
        candidates = list(range(1, top + 1))
    scores: dict[str, float] = {}
    for order in candidates:
        try:
            model = StateDynamics(*projections.a_c(horizon(order), order, stable))
            bd = fit_bd(rec, first, model, feedthrough)
            score = _heldout_fit(rec, model, bd, split)
        except (np.linalg.LinAlgError, ValueError):
            score = -math.inf
        scores[str(order)] = score if math.isfinite(score) else -math.inf
    best = max(scores.values())
    gap_text = ", ".join(f"s{n}/s{n + 1} = {math.exp(gaps[n - 1]):.3g}" for n in ranked)
    where = (
        f"around the largest singular-value gaps, {gap_text}"
        if clear
        else f"every order: no gap reaches {CLEAR_GAP:g} ({gap_text})"
    )
    if not math.isfinite(best):
        order = ranked[0]
        why = (
            f"order {order}: the largest singular-value gap ({gap_text}); every candidate "
            f"{candidates} diverged on the held-out third, so the gap alone decides"
        )
        return order, why, scores
    order = min(int(o) for o, v in scores.items() if v >= best - PARSIMONY)
    best_order = max(scores, key=lambda o: scores[o])
    why = (
        f"order {order}: the lowest of the candidates {candidates} ({where}) whose free-run "
        f"fit on the held-out last third ({scores[str(order)]:.2f} %) is within "
        f"{PARSIMONY:g} point(s) of the best (order {best_order}: {best:.2f} %), each fitted "
        "on the first two thirds"
    )
    return order, why, scores


def _heldout_fit(rec: ScaledRecord, model: StateDynamics, bd: BDFit, split: int) -> float:
    """Free-run fit % on the samples from ``split`` on (mean over the outputs).

    An experiment in the fit runs on from its fitted initial state; one that starts after
    ``split`` from the initial state fitted to its own samples (``B``, ``D`` fixed). The
    sums are accumulated chunk by chunk (no copy of the record).
    """
    if not model.simulated(max(rec.lengths)):
        return -math.inf
    sse, total, sq, count = np.zeros(rec.ny), np.zeros(rec.ny), np.zeros(rec.ny), 0
    for e, length in rec.segments():
        lo = max(0, split - int(rec.starts[e]) - rec.nk)
        if lo >= length:
            continue
        x0 = bd.x0[e] if e in bd.fitted else initial_state(rec, e, length, model, bd)
        for at, sim, _ in free_run(rec, e, length, model, bd, x0):
            first = max(lo, at)
            if first >= at + sim.shape[0]:
                continue
            y = rec.outputs(e, first, at + sim.shape[0])
            with np.errstate(all="ignore"):
                sse += np.sum((y - sim[first - at :]) ** 2, axis=0)
            total += y.sum(axis=0)
            sq += np.einsum("ij,ij->j", y, y)
            count += y.shape[0]
    if count == 0:
        return -math.inf
    spread = sq - total**2 / count
    with np.errstate(all="ignore"):
        fits = 100.0 * (1.0 - np.sqrt(sse) / np.sqrt(spread))
    fits[~np.isfinite(fits) | (spread <= 0)] = -math.inf
    return float(np.mean(fits))
