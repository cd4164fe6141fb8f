"""A model whose DC gain the data determine, preferred by :func:`clpc.identify`.

A model can fit held-out data and still leave its steady-state gain undetermined: with an
input that does not excite low frequencies (a sine sweep that starts high, a narrow band),
``G(1)`` is an extrapolation, and its standard deviation (delta method on the parameter
covariance, :meth:`clpc.LinearModel.dc_gain_std`) exceeds its magnitude, so not even its sign
is known. An engineer would take a candidate that fits nearly as well and determines its
gain over one that does not: the chosen model gives way to the next usable candidate
(ranked as :mod:`clpc.lpc.choice` ranks them) within :data:`GAIN_POINTS` points of its
mean held-out free run whose refit determines every gain (``sigma <= |gain|``). When none
does, the choice stands and the reason says so.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from clpc.data import DataError, IOData
from clpc.lpc.choice import tier
from clpc.lpc.comparison import final_model, key
from clpc.model import LinearModel, ModelError
from clpc.model.structure import Structure

__all__ = ["GAIN_POINTS", "MAX_TRIES", "gain_spread", "prefer_determined_gain"]

#: Points of mean held-out free run a candidate with a determined gain may give away.
GAIN_POINTS = 5.0
#: Most alternatives refitted when the chosen model's gain is undetermined.
MAX_TRIES = 3


def gain_spread(model: LinearModel) -> float:
    """The largest ``sigma / |gain|`` over the model's input-output pairs.

    ``> 1``: some gain is undetermined (its sign is not known). ``nan`` when the model has
    no covariance (its gain's spread is unknown, not undetermined).
    """
    try:
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.asarray(model.dc_gain_std()) / np.abs(np.asarray(model.dc_gain()))
    except (ModelError, ValueError, np.linalg.LinAlgError):
        return math.nan
    ratio = np.where(np.isnan(ratio), np.inf, ratio)
    return float(np.max(ratio))


def prefer_determined_gain(
    data: IOData,
    rows: list[dict[str, Any]],
    model: LinearModel,
    picks: list[int],
    mimo: str,
) -> tuple[LinearModel, list[int], str]:
    """The chosen model, or the best near alternative whose gain is determined (see module).

    Parameters
    ----------
    data : IOData
        The record.
    rows : list of dict
        The candidate table (``chosen`` is updated when the choice moves).
    model : LinearModel
        The chosen model refitted on the record, with its covariance.
    picks : list of int
        The chosen row per output.
    mimo : str
        The MIMO mode.

    Returns
    -------
    model : LinearModel
    picks : list of int
    note : str
        What happened, in words (empty when the gain is determined or unknown).
    """
    spread = gain_spread(model)
    if not spread > 1.0:
        return model, picks, ""
    outputs = sorted({r["output"] for r in rows}, key=[rows[i]["output"] for i in picks].index)
    mean = float(np.mean([rows[i]["free_run"] for i in picks]))
    chosen = {(rows[i]["estimator"], key(rows[i])) for i in picks}
    options = []
    for name, where in {(r["estimator"], key(r)) for r in rows} - chosen:
        idx = [i for i, r in enumerate(rows) if r["estimator"] == name and key(r) == where]
        if len(idx) != len(outputs) or any(tier(rows[i]) for i in idx):
            continue
        score = float(np.mean([rows[i]["free_run"] for i in idx]))
        if score >= mean - GAIN_POINTS:
            by_output = sorted(idx, key=lambda i: outputs.index(rows[i]["output"]))
            options.append((score, name, where, by_output))
    for score, name, where, idx in sorted(options, reverse=True)[:MAX_TRIES]:
        try:
            other = final_model(data, (name,) * len(outputs), Structure(*where), mimo)
        except (ModelError, DataError, np.linalg.LinAlgError):
            continue
        if gain_spread(other) <= 1.0:
            for i in picks:
                rows[i]["chosen"] = False
            for i in idx:
                rows[i]["chosen"] = True
            return (
                other,
                idx,
                f"the first choice's DC gain is undetermined (sigma {spread:.2g} times "
                f"|gain|); {name.upper()} na={where[0]} nb={where[1]} nk={where[2]} fits "
                f"{score:.1f} % held out (within {GAIN_POINTS:g} points of {mean:.1f} %) "
                "and determines its gain",
            )
    return (
        model,
        picks,
        f"the DC gain is undetermined (sigma {spread:.2g} times |gain|) and no candidate "
        f"within {GAIN_POINTS:g} points determines it: the data do not fix the steady state",
    )
