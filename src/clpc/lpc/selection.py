"""``identify``: the structure and the estimator for a record, and why.

Two stages, both scored on data the fits did not see, forward in time at three rolling
origins: fitted on the first 1/2, 2/3 and ``1 - f`` of the record (``f =
validation_fraction``, default 0.2) and scored on all the rest each time, as the final model
is fitted on the record and used after it. Each origin gives, per output, the **free-run**
fit % (the simulation from the input alone, started from the measured samples before the
scored ones) and the **k-step** prediction fit % (``k``: one dominant time constant of the
least-squares model of the screen's choice fitted on the first half,
:func:`clpc.lpc.heldout.horizon`); the table holds their means over the origins
(``windows``: the free runs one by one).

* **Structure screen** (:mod:`clpc.lpc.screen`, :mod:`clpc.lpc.search_space`): every
  ``(na, nb, nk)`` in the ranges (``na`` 1..10, ``nb`` 0..10, ``nk`` 0..5 by default,
  independently) as least squares, in microseconds each; the ``shortlist`` best go on (the
  fewest coefficients within :data:`clpc.lpc.screen.PARSIMONY` of the best first).
* **Candidates** (:mod:`clpc.lpc.comparison`): least squares, LPC and OE at each
  shortlisted structure (OE started at each later origin from the previous optimum), and
  subspace (PO-MOESP) at the state dimension each needs.
* **Choice**, per output (:mod:`clpc.lpc.choice`): among the usable candidates (stable or
  integrating within :data:`clpc.lpc.heldout.UNIT_CIRCLE_TOL`, never more than
  :data:`clpc.lpc.choice.GUARD` points below the screen's least-squares choice at any
  origin), the highest mean free-run fit, except that OE is kept when that candidate leads
  it by no more than the standard error of their differences over the origins; then the
  structure with the fewest coefficients within :data:`clpc.lpc.choice.PARSIMONY` points.
  The model is meant to simulate the process, and the free run is the stricter test (a
  prediction re-reads the measured output every ``k`` samples); OE minimises that very
  error and is consistent under output noise. So an unstable or catastrophic model is
  never chosen while a usable candidate exists. A choice whose refit on the whole record
  is unstable gives way to the next candidate (:func:`clpc.lpc.comparison.stable_refits`).
  Outputs are separate equations, so a multi-output model may take each output from
  another estimator (``info["estimators"]``), at one structure.
* **Errors in variables**: :func:`clpc.lpc.eiv.check_eiv` on the whole record at the chosen
  structure. When OE was not chosen, the check's OE fit starts at the last origin's optimum
  and stops at a relative change of :data:`EIV_CHECK_TOLERANCE`, not 1e-14: the check
  compares parameter vectors at per-cent thresholds, and on 1e6 samples the fit to 1e-14
  took 21 s (45 evaluations of the whole record's simulation error and Jacobian).

The chosen estimators are then refitted on the whole record.

Why rolling origins: ``benchmarks/selection_rules.py`` measured 20 rules on the real
records split four ways and on simulated ones (``docs/method.md``); scoring forward in time
was better on the real records than the earlier two folds (one fitted on the last two
thirds and scored on the first third), and folds scored backward in time were the worst.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from clpc.core.checks import check_choice, check_int
from clpc.core.compact import compact_repr
from clpc.data import DataError, as_iodata
from clpc.lpc import heldout
from clpc.lpc.candidates import candidate_rows
from clpc.lpc.choice import choose, guarded
from clpc.lpc.comparison import (
    final_model,
    key,
    make,
    rolling_origin,
    stable_refits,
)
from clpc.lpc.eiv import EivCheck, check_eiv
from clpc.lpc.gain_choice import prefer_determined_gain
from clpc.lpc.reasons import why
from clpc.lpc.screen import screen
from clpc.lpc.search_space import excited_order, search_space
from clpc.model import LinearModel, ModelError
from clpc.model.structure import Structure, check_mode, default_mode

__all__ = ["ESTIMATORS", "Identification", "identify"]

#: Estimator names, as ``identify(estimator=...)`` and ``clpc identify --estimator`` take them.
ESTIMATORS = ("auto", "lpc", "arx", "oe", "subspace")
#: When the errors-in-variables check's own OE fit stops (:class:`clpc.OE`'s ``tolerance``).
EIV_CHECK_TOLERANCE = 1e-10


@compact_repr
@dataclass(frozen=True)
class Identification:
    """The outcome of :func:`identify`.

    Attributes
    ----------
    model : LinearModel
        The chosen model, refitted on the whole record.
    table : list of dict
        One row per candidate and output: ``estimator``, ``na``, ``nb``, ``nk``, ``order``
        (``na``), ``n_params``, ``output``, ``free_run``, ``kstep`` (fit %, mean over the
        three origins, ``-inf`` when one diverges), ``windows`` (the free-run fit % at each
        origin), ``stability`` (the worst of the origins' models), ``max_pole``, ``guard``
        (within :data:`clpc.lpc.choice.GUARD` points of the reference at every origin),
        ``chosen`` and ``note`` (why a fit failed or a choice gave way).
        ``pandas.DataFrame(table)`` makes it a frame.
    reason : str
        Why this model, in words (the screen, the choice, the errors-in-variables check).
    estimators : tuple of str
        The chosen estimator per output (``"lpc"``, ``"arx"``, ``"oe"`` or ``"subspace"``).
    structure : Structure
        The chosen orders and delay.
    horizon : int
        The prediction horizon ``k`` [samples].
    screen : list of dict
        The structure screen: ``na``, ``nb``, ``nk``, ``n_params`` and ``free_run`` (mean
        least-squares held-out free-run fit %) per structure.
    eiv : EivCheck or None
        The errors-in-variables check (``None`` when OE or LPC could not be fitted).
    """

    model: LinearModel
    table: list[dict[str, Any]]
    reason: str
    estimators: tuple[str, ...]
    structure: Structure
    horizon: int
    screen: list[dict[str, Any]]
    eiv: EivCheck | None

    @property
    def estimator(self) -> str:
        """The chosen estimator (``"mixed"`` when the outputs took different ones)."""
        return self.estimators[0] if len(set(self.estimators)) == 1 else "mixed"

    @property
    def order(self) -> int:
        """The chosen output order ``na``."""
        return self.structure.na

    @property
    def nk(self) -> int:
        """The chosen input delay [samples]."""
        return self.structure.nk

    def to_frame(self) -> Any:
        """:attr:`table` as a pandas DataFrame (needs pandas)."""
        import pandas as pd

        return pd.DataFrame(self.table)


@threadpool_limits.wrap(limits=1, user_api="blas")  # small solves: threads only thrash
def identify(
    u: Any,
    y: Any | None = None,
    dt: float | None = None,
    estimator: str = "auto",
    *,
    order: int | str = "auto",
    na: int | None = None,
    nb: int | None = None,
    nk: int | str = "auto",
    max_order: int = 10,
    max_delay: int = 5,
    mimo: str | None = None,
    k: int | None = None,
    validation_fraction: float = 0.2,
    shortlist: int = 3,
    progress: Callable[[str], None] | None = None,
) -> Identification:
    """Choose structure and estimator for a record; return the model with the evidence.

    Parameters
    ----------
    u, y, dt
        The record (see :meth:`clpc.LPC.fit`).
    estimator : {"auto", "lpc", "arx", "oe"}
        ``"auto"``: per output, the best held-out free run among the usable candidates, OE
        within one standard error (see the module); otherwise that estimator (the table
        still compares all).
    order : int or "auto"
        ``"auto"`` (default): ``na`` in ``1..max_order`` and ``nb`` in ``0..max_order``
        screened independently; an int ``N``: ``na = nb = N``.
    na, nb : int, optional
        Fix the output order or the input order (clpc's ``nb``: ``nb + 1`` coefficients
        per input) and screen the other.
    nk : int or "auto"
        Input delay [samples] or ``"auto"`` (``0..max_delay``, default).
    max_order, max_delay : int
        Ranges of the automatic search (``max_order`` is lowered, with a note in the
        reason, when the record is too short for it).
    mimo : {"siso", "paired", "miso"}, optional
        Multi-channel structure (default as :class:`clpc.LPC`).
    k : int, optional
        Prediction horizon [samples]; default from the data.
    validation_fraction : float
        Share of the record scored from the last origin (0 < f <= 0.25; the other origins
        are at 1/2 and 2/3 of the record).
    shortlist : int
        How many screened structures the estimators are fitted on (>= 1).
    progress : callable, optional
        Called with one line of text at each stage (the screen, each estimator family).

    Returns
    -------
    Identification
        ``.model``, ``.table``, ``.reason`` and the details.

    Raises
    ------
    ValueError
        Invalid settings.
    DataError
        A record too short for the smallest candidate.
    """
    check_choice(estimator, "estimator", ESTIMATORS)
    check_int(shortlist, "shortlist", 1)
    if not 0.0 < validation_fraction <= 0.25:
        raise ValueError(
            f"validation_fraction must be in (0, 0.25] (the last origin is at 1 - f, after "
            f"the others at 1/2 and 2/3); got {validation_fraction!r}."
        )
    say = progress or (lambda line: None)
    data = as_iodata(u, y, dt)
    names = (*data.input_names, *data.output_names)
    columns = (*data.u.T, *data.y.T)
    flat = [n for n, col in zip(names, columns, strict=True) if np.ptp(col) == 0]
    if flat:
        raise DataError(
            f"nothing to identify: constant channel(s) {flat}. identify needs inputs and "
            "outputs that vary over the record."
        )
    mode = mimo or default_mode(data.n_inputs, data.n_outputs)
    check_mode(mode, data.n_inputs, data.n_outputs)
    folds = rolling_origin(data, validation_fraction)
    blocks = data.n_inputs if mode == "miso" else 1
    if isinstance(order, str) and order != "auto":
        raise ValueError(f"order must be an int or 'auto'; got {order!r}.")
    most = max_order if order == "auto" else int(order)
    excited = excited_order(data.u, 2 * max(most, na or 0, nb or 0) + 1, data.experiments)
    space = search_space(folds, (order, na, nb, nk), (max_order, max_delay), blocks, excited)
    say(f"structure screen: {len(space.structures)} structures by least squares")
    scr = screen(folds, space.structures, mode)
    short = [scr.structures[i] for i in scr.shortlist(shortlist)]
    if k is None:
        lowest = make("arx", short[0], mode).fit(folds[0][0])
        k = heldout.horizon(lowest, folds[0][1].n_samples)
    k = check_int(k, "k", 1)
    automatic = order == "auto" and na is None and nb is None
    rows, last_oe = candidate_rows(folds, short, (mode, k, automatic), say)
    # the reference: least squares at the screen's choice (the first shortlisted structure)
    guarded(rows, {r["output"]: r["windows"] for r in rows if _is(r, "arx", short[0])})
    where, first = choose(rows, estimator, data.output_names)
    picks = stable_refits(data, rows, first, mode) if estimator == "auto" else first
    for i in picks:
        rows[i]["chosen"] = True
    chosen = tuple(rows[i]["estimator"] for i in picks)
    structure = Structure(*where)
    model = final_model(data, chosen, structure, mode, initial=last_oe.get(structure))
    gain_note = ""
    if estimator == "auto":
        model, moved, gain_note = prefer_determined_gain(data, rows, model, picks, mode)
        if moved != picks:
            first = picks = moved
            chosen = tuple(rows[i]["estimator"] for i in picks)
            structure = Structure(*key(rows[picks[0]]))
    try:
        oe_model = model  # the chosen OE fit, or a new one
        if set(chosen) != {"oe"}:
            check_fit = make("oe", structure, mode, last_oe.get(structure))
            oe_model = replace(check_fit, tolerance=EIV_CHECK_TOLERANCE).fit(data)
        eiv: EivCheck | None = check_eiv(data, oe_model)
    except (ModelError, DataError, np.linalg.LinAlgError):
        eiv = None
    parts = [why(rows, (first, picks), estimator, (k, validation_fraction), data.output_names)]
    if gain_note:
        parts.append(gain_note)
    parts.append(space.describe(scr, short))
    if eiv is not None:
        parts.append(eiv.reason)
    return Identification(model, rows, "; ".join(parts), chosen, structure, k, scr.rows(), eiv)


def _is(row: dict[str, Any], name: str, structure: Structure) -> bool:
    """Whether ``row`` is estimator ``name`` at ``structure``."""
    return row["estimator"] == name and key(row) == (structure.na, structure.nb, structure.nk)
