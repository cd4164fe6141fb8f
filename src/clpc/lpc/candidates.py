"""The candidates of :func:`clpc.identify`: every estimator at every shortlisted structure.

Least squares, LPC and OE at each structure of the screen's shortlist; subspace at its own
order choice (with and without feedthrough) and at the state dimension each shortlisted
structure's lags need. Each candidate is fitted and scored at the rolling origins by
:func:`clpc.lpc.comparison.candidate`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from clpc.data import DataError, IOData
from clpc.lpc.comparison import FAMILIES, candidate, make, subspace_structure
from clpc.model import LinearModel, ModelError
from clpc.model.structure import Structure

__all__ = ["candidate_rows", "subspace_structures"]


def subspace_structures(
    data: IOData, short: list[Structure], mode: str, automatic: bool
) -> list[Structure]:
    """The subspace candidates: its own order choice and the shortlist's state dimensions.

    Parameters
    ----------
    data : IOData
        The last origin's fitted part.
    short : list of Structure
        The screen's shortlist.
    mode : {"siso", "paired", "miso"}
        MIMO mode.
    automatic : bool
        Whether the orders are searched: then ``Subspace(order="auto")`` on ``data`` with
        and without feedthrough (its singular values and held-out check,
        :mod:`clpc.lpc.subspace_order`) and the state dimension each shortlisted
        structure's lags need (``max(na, nb + 1)``, with its delay); otherwise (an order
        given) the shortlist's ``na`` only.

    Returns
    -------
    list of Structure
        Each structure once, in the subspace convention
        (:func:`clpc.lpc.comparison.subspace_structure`).
    """
    if not automatic:
        return list(dict.fromkeys(subspace_structure(s.na, s.nk) for s in short))
    own = []
    for nk in (0, max(short[0].nk, 1)):
        try:
            est = make("subspace", subspace_structure(1, nk), mode)
            fitted = replace(est, order="auto").fit(data)
            own.append(subspace_structure(fitted.structure.na, nk))
        except (ModelError, DataError, np.linalg.LinAlgError):
            continue
    shaped = [subspace_structure(max(s.na, s.nb + 1), s.nk) for s in short]
    return list(dict.fromkeys(own + shaped))


def candidate_rows(
    folds: list[Any],
    short: list[Structure],
    opts: tuple[str, int, bool],
    say: Callable[[str], None],
) -> tuple[list[dict[str, Any]], dict[Structure, LinearModel]]:
    """Every estimator at every shortlisted structure, scored at the origins.

    Parameters
    ----------
    folds : list of (IOData, IOData)
        The (fitted, scored) parts at the origins.
    short : list of Structure
        The screen's shortlist.
    opts : (str, int, bool)
        The MIMO mode, the prediction horizon ``k`` [samples] and whether the orders are
        searched (see :func:`subspace_structures`).
    say : callable
        Called with one progress line per estimator family.

    Returns
    -------
    rows : list of dict
        The candidate table (``n_params`` added).
    last_oe : dict
        Each structure's OE fit at the last origin (the final fit starts there).
    """
    mode, k, automatic = opts
    n_in = folds[0][0].n_inputs
    blocks = n_in if mode == "miso" else 1
    rows: list[dict[str, Any]] = []
    last_oe: dict[Structure, LinearModel] = {}
    shapes = ", ".join(f"na={s.na} nb={s.nb} nk={s.nk}" for s in short)
    for name in FAMILIES:
        where = short
        if name == "subspace":
            where = subspace_structures(folds[-1][0], short, mode, automatic)
            shapes = ", ".join(f"order {s.na} nk={s.nk}" for s in where)
        say(f"{name.upper()}: {shapes} at {len(folds)} origins")
        for s in where:
            got, model = candidate(name, s, mode, (folds, k))
            rows += [r | {"n_params": s.na + blocks * (s.nb + 1)} for r in got]
            if name == "oe" and model is not None:
                last_oe[s] = model
    return rows, last_oe
