"""A model whose DC gain the data determine, preferred by :func:`clpc.identify`.

A model can fit held-out data and still leave its steady-state gain undetermined: with an
input that does not excite low frequencies (a sine sweep that starts high, a narrow band),
``G(1)`` is an extrapolation, and its standard deviation (delta method on the parameter
covariance, :meth:`clpc.LinearModel.dc_gain_std`) exceeds its magnitude, so not even its sign
is known (:func:`clpc.model.gain.assess_gain`). An engineer would take a candidate that fits
nearly as well and determines its gain over one that does not: the chosen model gives way
to the best other usable candidate within :data:`GAIN_POINTS` points of its mean held-out
free run whose refit determines every gain. When none does, the choice stands and the
reason says so.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.data import DataError, IOData
from clpc.lpc.choice import tier
from clpc.lpc.comparison import final_model, key
from clpc.model import LinearModel, ModelError
from clpc.model.gain import GainAssessment, assess_gain
from clpc.model.structure import Structure

__all__ = ["GAIN_POINTS", "MAX_TRIES", "prefer_determined_gain", "undetermined"]

#: Points of mean held-out free run a candidate with a determined gain may give away.
GAIN_POINTS = 5.0
#: Most alternatives refitted when the chosen model's gain is undetermined.
MAX_TRIES = 3


def undetermined(model: LinearModel) -> list[GainAssessment]:
    """The model's input-output pairs whose DC gain the data do not determine.

    (:func:`clpc.model.gain.assess_gain`: ``sigma > |gain|``, or an input not persistently
    exciting of the order the structure needs); an integrator's or a gain without sigma is
    not counted (unknown is not undetermined).
    """
    return [g for g in assess_gain(model) if g.determined is False]


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
    lost = undetermined(model)
    if not lost:
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
        if not undetermined(other):
            for i in picks:
                rows[i]["chosen"] = False
            for i in idx:
                rows[i]["chosen"] = True
            return (
                other,
                idx,
                f"the first choice's DC gain is undetermined ({lost[0].finding()}); "
                f"{name.upper()} na={where[0]} nb={where[1]} nk={where[2]} fits "
                f"{score:.1f} % held out (within {GAIN_POINTS:g} points of {mean:.1f} %) "
                "and determines its gain",
            )
    return (
        model,
        picks,
        f"{lost[0].finding()}; no candidate within {GAIN_POINTS:g} points determines it: "
        "the data do not fix the steady state",
    )
