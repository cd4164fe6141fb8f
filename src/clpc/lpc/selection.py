"""``identify``: the best of LPC, least squares and output error for a record, and why.

Every candidate (estimator x order) is scored on data it was not fitted to, forward in time
at three rolling origins: fitted on the first 1/2, 2/3 and ``1 - f`` of the record
(``f = validation_fraction``, default 0.2) and scored on all the rest each time, as the
final model is fitted on the record and used after it. Each origin gives, per output, the
**free-run** fit % (the simulation from the input alone, started from the measured samples
before the scored ones) and the **k-step** prediction fit % (``k``: one dominant time
constant of the least-squares model fitted on the first half,
:func:`clpc.lpc.heldout.horizon`); the table holds their means over the origins
(``windows``: the free runs one by one).

* **Choice**, per output (:mod:`clpc.lpc.choice`): among the candidates whose poles are all
  strictly inside the unit circle at every origin (if there are none: among those within
  :data:`clpc.lpc.heldout.UNIT_CIRCLE_TOL` of it, then among the rest), the highest mean
  free-run fit, except that OE is kept when that candidate leads it by no more than the
  standard error of their differences over the origins. The model is meant to simulate the
  process, and the free run is the stricter test (a prediction re-reads the measured output
  every ``k`` samples); OE minimises that very error and is consistent under output noise.
  So an unstable model is never chosen while a stable candidate exists; OE is stable by
  construction, so one always does when OE can be fitted. A choice whose refit on the whole
  record is unstable gives way to the next candidate
  (:func:`clpc.lpc.comparison.stable_refits`). Outputs are separate equations, so a
  multi-output model may take each output from another estimator (``info["estimators"]``).
* **Order** (``order="auto"``): the lowest order whose mean over the outputs of the chosen
  free-run fits is within :data:`PARSIMONY` points of the best order's.
* **Delay** (``nk="auto"``): every candidate at each ``nk`` in ``0..max_delay``; the ``nk``
  whose chosen candidates have the best mean free run wins (every delay has as many
  parameters, so no parsimony; the closed-form fits alone are misled by their bias: least
  squares and LPC under output noise can fit better with a wrong delay).
* **Errors in variables**: :func:`clpc.lpc.eiv.check_eiv` on the whole record at the chosen
  structure.

The chosen estimators are then refitted on the whole record.

Why this rule: ``benchmarks/selection_rules.py`` measured 20 rules on the real records
split four ways and on simulated ones (``docs/method.md``); scoring forward in time was
better on the real records than the earlier two folds (one fitted on the last two thirds and
scored on the first third), and folds scored backward in time were the worst.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.core.checks import check_choice, check_int
from clpc.core.compact import compact_repr
from clpc.data import DataError, as_iodata
from clpc.lpc import heldout
from clpc.lpc.arx import ARX
from clpc.lpc.choice import choose, oe_lead, tier
from clpc.lpc.comparison import (
    choose_delay,
    final_model,
    grid,
    rolling_origin,
    stable_refits,
)
from clpc.lpc.eiv import EivCheck, check_eiv
from clpc.lpc.oe import OE
from clpc.model import LinearModel, ModelError

__all__ = ["ESTIMATORS", "Identification", "identify", "pct"]

#: Estimator names, as ``identify(estimator=...)`` and ``clpc identify --estimator`` take them.
ESTIMATORS = ("auto", "lpc", "arx", "oe")


@compact_repr
@dataclass(frozen=True)
class Identification:
    """The outcome of :func:`identify`.

    Attributes
    ----------
    model : LinearModel
        The chosen model, refitted on the whole record.
    table : list of dict
        One row per candidate and output: ``estimator``, ``order``, ``nk``, ``output``,
        ``free_run``, ``kstep`` (fit %, mean over the three origins, ``-inf`` when one
        diverges), ``windows`` (the free-run fit % at each origin), ``stability`` (the worst
        of the origins' models), ``chosen`` and ``note`` (why a fit failed or a choice gave
        way). ``pandas.DataFrame(table)`` makes it a frame.
    reason : str
        Why this model, in words (with the delay and the errors-in-variables check).
    estimators : tuple of str
        The chosen estimator per output (``"lpc"``, ``"arx"`` or ``"oe"``).
    order, nk : int
        The chosen structure (``na = nb = order``).
    horizon : int
        The prediction horizon ``k`` [samples].
    delays : list of dict
        ``nk="auto"`` only: ``nk`` and ``free_run`` (best stable closed-form fit %).
    eiv : EivCheck or None
        The errors-in-variables check (``None`` when OE or LPC could not be fitted).
    """

    model: LinearModel
    table: list[dict[str, Any]]
    reason: str
    estimators: tuple[str, ...]
    order: int
    nk: int
    horizon: int
    delays: list[dict[str, Any]]
    eiv: EivCheck | None

    @property
    def estimator(self) -> str:
        """The chosen estimator (``"mixed"`` when the outputs took different ones)."""
        return self.estimators[0] if len(set(self.estimators)) == 1 else "mixed"

    def to_frame(self) -> Any:
        """:attr:`table` as a pandas DataFrame (needs pandas)."""
        import pandas as pd

        return pd.DataFrame(self.table)


def identify(
    u: Any,
    y: Any | None = None,
    dt: float | None = None,
    estimator: str = "auto",
    *,
    order: int | str = 2,
    nk: int | str = 0,
    max_order: int = 6,
    max_delay: int = 4,
    mimo: str | None = None,
    k: int | None = None,
    validation_fraction: float = 0.2,
) -> Identification:
    """Fit LPC, least squares (ARX) and output error (OE); return the best with the evidence.

    Parameters
    ----------
    u, y, dt
        The record (see :meth:`clpc.LPC.fit`).
    estimator : {"auto", "lpc", "arx", "oe"}
        ``"auto"``: per output, the best held-out free run among the stable candidates, OE
        within one standard error (see the module); otherwise that estimator (the table
        still compares all three).
    order : int or "auto"
        Model order ``N`` (``na = nb = N``) or ``"auto"`` (``1..max_order``).
    nk : int or "auto"
        Input delay [samples] or ``"auto"`` (``0..max_delay``).
    max_order, max_delay : int
        Ranges of ``order="auto"`` and ``nk="auto"``.
    mimo : {"siso", "paired", "miso"}, optional
        Multi-channel structure (default as :class:`clpc.LPC`).
    k : int, optional
        Prediction horizon [samples]; default from the data.
    validation_fraction : float
        Share of the record scored from the last origin (0 < f <= 0.25; the other origins
        are at 1/2 and 2/3 of the record).

    Returns
    -------
    Identification
        ``.model``, ``.table``, ``.reason`` and the details.

    Raises
    ------
    ValueError
        Invalid settings.
    DataError
        A record too short for the largest candidate.
    """
    check_choice(estimator, "estimator", ESTIMATORS)
    orders = _range(order, "order", 1, max_order)
    delays = _range(nk, "nk", 0, max_delay)
    if not 0.0 < validation_fraction <= 0.25:
        raise ValueError(
            f"validation_fraction must be in (0, 0.25] (the last origin is at 1 - f, after "
            f"the others at 1/2 and 2/3); got {validation_fraction!r}."
        )
    data = as_iodata(u, y, dt)
    folds = rolling_origin(data, validation_fraction)
    n_fit, n_val = folds[0][0].n_samples, folds[-1][1].n_samples
    need = 4 * (max(orders) + max(delays) + 2) * (data.n_inputs + 1)
    if n_fit < need or n_val < need // 2:
        raise DataError(
            f"identify needs at least {need} samples before the first origin and {need // 2} "
            f"after the last (order {max(orders)}, delay {max(delays)}, {data.n_inputs} "
            f"input(s)); got {n_fit} and {n_val} of {data.n_samples}. Use a longer record, a "
            "lower max order or max delay, or a larger validation_fraction."
        )
    if k is None:
        lowest = ARX(order=orders[0], mimo=mimo, assess=False).fit(folds[0][0])  # type: ignore[arg-type]
        k = heldout.horizon(lowest, folds[0][1].n_samples)
    k = check_int(k, "k", 1)
    delay_rows: list[dict[str, Any]] = []
    if len(delays) > 1:
        chosen_nk, delay_rows, rows = choose_delay(folds, orders, delays, (mimo, k))
    else:
        chosen_nk = delays[0]
        rows = grid(folds, orders, chosen_nk, (mimo, k))
    names = data.output_names
    pick_order, first = choose(rows, estimator, names)
    picks = stable_refits(data, rows, first, mimo) if estimator == "auto" else first
    for i in picks:
        rows[i]["chosen"] = True
    chosen = tuple(rows[i]["estimator"] for i in picks)
    model = final_model(data, chosen, pick_order, chosen_nk, mimo)
    try:
        oe_model = model  # the chosen OE fit, or a new one
        if set(chosen) != {"oe"}:
            oe_model = OE(order=pick_order, nk=chosen_nk, mimo=mimo, assess=False).fit(data)  # type: ignore[arg-type]
        eiv: EivCheck | None = check_eiv(data, oe_model)
    except (ModelError, DataError, np.linalg.LinAlgError):
        eiv = None
    parts = [_why(rows, (first, picks), estimator, (k, validation_fraction), names)]
    if delay_rows:
        scan = ", ".join(f"nk={r['nk']}: {r['free_run']:.1f}" for r in delay_rows)
        parts.append(f"delay nk={chosen_nk}: the best stable held-out free run, per delay: {scan}")
    if eiv is not None:
        parts.append(eiv.reason)
    return Identification(
        model, rows, "; ".join(parts), chosen, pick_order, chosen_nk, k, delay_rows, eiv
    )


def _range(value: Any, name: str, low: int, high: int) -> list[int]:
    """``[value]`` or ``low..high`` for ``"auto"``."""
    if isinstance(value, str):
        if value != "auto":
            raise ValueError(f"{name} must be an int or 'auto'; got {value!r}.")
        high = check_int(high, "max_order" if name == "order" else "max_delay", low)
        return list(range(low, high + 1))
    return [check_int(value, name, low)]


def _why(
    rows: list[dict[str, Any]],
    choice: tuple[list[int], list[int]],
    estimator: str,
    opts: tuple[int, float],
    names: tuple[str, ...],
) -> str:
    """The choice in words.

    ``choice``: the first picks and those kept after the refits; ``opts``: the horizon ``k``
    and ``validation_fraction``.
    """
    k, fraction = opts
    parts = []
    lead = [oe_lead(rows, i) for i in choice[1]]
    for j, (i0, i) in enumerate(zip(*choice, strict=True)):
        r = rows[i]
        what = f"{r['estimator'].upper()} (order {r['order']}, nk {r['nk']})"
        out = f"output {names[j]}: " if len(names) > 1 else ""
        each = ", ".join(pct(v) for v in r["windows"])
        fits = (
            f"held-out free run {pct(r['free_run'])} (mean over the origins 1/2, 2/3, "
            f"{1 - fraction:.3g}: {each}), {k}-step {pct(r['kstep'])}"
        )
        others = [
            f"{x['estimator'].upper()} {_fmt(x)}"
            for x in rows
            if x is not r and x["order"] == r["order"] and x["output"] == r["output"]
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
            how = "the best held-out free run among the stable candidates"
        elif level == 1:
            how = "no candidate is strictly stable; the best of those on the unit circle"
        else:
            how = "every candidate is unstable or diverges; the least bad, not a good model"
        parts.append(f"{out}{what}, {how} ({fits}; {', '.join(others)})")
    unstable = sorted(
        {f"{x['estimator'].upper()} N={x['order']}" for x in rows if x["stability"] == "unstable"}
    )
    text = "; ".join(parts)
    return text + (f"; unstable at an origin: {', '.join(unstable)}" if unstable else "")


def _fmt(row: dict[str, Any]) -> str:
    """A candidate's held-out free run in a few characters."""
    if row["stability"] == "no model":
        return "no model"
    return pct(row["free_run"]) + (" (unstable)" if row["stability"] == "unstable" else "")


def pct(value: float) -> str:
    """A fit % for people: ``84.2 %``, ``-3.1e+05 %`` or ``diverges``."""
    if not math.isfinite(value):
        return "diverges"
    return f"{value:.1f} %" if abs(value) < 1e4 else f"{value:.1e} %"
