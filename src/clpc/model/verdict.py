"""Identifiability verdicts in plain words, for a fit and for every cluster of a trace.

The numbers behind them come from the solve (:mod:`clpc.solve`): the dimension of the
near-null subspace the solution was taken from (``n_null``), the near-null relations that
involve almost no output (``n_input_relations``: the input alone satisfies them, so it is not
persistently exciting of the model's order), the separation of the solution's eigenvalue from
the next one, and the stability of the monic model.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["Verdict", "describe_trace", "fit_verdict"]


@dataclass(frozen=True)
class Verdict:
    """Identifiability of one fitted equation.

    Attributes
    ----------
    n_null : int
        Dimension of the near-null subspace (1: the generic, unique solution).
    persistently_exciting : bool
        No input-only relation is as small as the system relation.
    determined : bool
        The data determine the parameter vector (unique and well separated).
    stable : bool
        All poles strictly inside the unit circle.
    order : int
        The input order the excitation was checked for (``nb + 1`` lags).
    messages : tuple of str
        Plain-language findings.
    """

    n_null: int
    persistently_exciting: bool
    determined: bool
    stable: bool
    order: int
    messages: tuple[str, ...]

    def __str__(self) -> str:
        return "; ".join(self.messages)


def fit_verdict(model: Any, output: int = 0) -> Verdict:
    """The verdict of an LPC fit (:meth:`clpc.LPC.fit`) for one output."""
    info = model.info
    if "n_null" not in info:  # e.g. a CLPC steady-state model: no single fit behind it
        try:
            stable = bool(np.all(np.abs(model.poles(output)) < 1.0))
        except ValueError:
            stable = False
        notes = (
            "no fit statistics (an averaged or loaded model)",
            "the model is stable" if stable else "the model is NOT stable",
        )
        return Verdict(0, True, False, stable, model.structure.nb + 1, notes)
    n_null = int(np.atleast_1d(info["n_null"])[output])
    n_input = int(np.atleast_1d(info["n_input_relations"])[output])
    determined = bool(np.atleast_1d(info["determined"])[output])
    sep = float(np.atleast_1d(info["separation"])[output])
    try:
        stable = bool(np.all(np.abs(model.poles(output)) < 1.0))
    except ValueError:
        stable = False
    order = model.structure.nb + 1
    msgs = []
    if n_input:
        msgs.append(
            f"input is not persistently exciting of order {order}: it satisfies {n_input} "
            "linear relation(s) by itself (e.g. a smooth or ramp-like input); the input part "
            "of the model is the minimum-norm choice and may not describe other inputs"
        )
    cancelled = int(info.get("cancelled", 0))
    if cancelled:
        fitted = info.get("fitted_structure", {})
        na, nb = fitted.get("na"), fitted.get("nb")
        msgs.append(
            f"order larger than the data support: {cancelled} pole/zero factor(s) common to "
            f"A and B (closer than 0.02) were cancelled; fitted na={na}, nb={nb}, kept "
            f"na={model.structure.na}, nb={model.structure.nb}"
        )
    elif n_null - n_input > 1:
        msgs.append(
            f"{n_null - n_input} output relations are equally small: the order may be larger "
            "than the system's (common pole-zero factors); consider a lower order"
        )
    if determined:
        msgs.append(f"the data determine the parameters (eigenvalue separation {sep:.2g})")
    elif not n_input and n_null == 1:
        msgs.append(
            f"the parameters are poorly determined (smallest eigenvalue {sep:.2g} of the next):"
            " the data hardly prefer this model to others"
        )
    msgs.append("the model is stable" if stable else "the model is NOT stable")
    return Verdict(n_null, n_input == 0, determined, stable, order, tuple(msgs))


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Inclusive index ranges where ``mask`` is true."""
    if not mask.any():
        return []
    edges = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1) - 1
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


def _ranges(runs: list[tuple[int, int]], limit: int = 6) -> str:
    parts = [f"{a}" if a == b else f"{a}-{b}" for a, b in runs[:limit]]
    more = f" and {len(runs) - limit} more" if len(runs) > limit else ""
    return ", ".join(parts) + more


def describe_trace(trace: Any) -> list[str]:
    """Plain-language findings over the clusters of a CLPC trace (clusters numbered from 1).

    Returns
    -------
    list of str
        E.g. ``"input is not persistently exciting of order 3 in clusters 14-37: the
        parameters there are held"``.
    """
    arr = trace.arrays
    held_note = " (the parameters there are held)" if trace.meta.get("guard") else ""
    order = trace.structure.nb + 1
    out = []
    n = len(trace)

    def add(mask: np.ndarray, text: str) -> None:
        runs = [(a + 1, b + 1) for a, b in _runs(mask)]
        if runs:
            out.append(f"{text} in clusters {_ranges(runs)}{held_note}")

    add(trace.not_enough_data, "fewer lag vectors than min_rows")
    add(arr["degenerate"].any(axis=1), "nothing varies (degenerate window)")
    add(
        (arr["n_input_relations"] > 0).any(axis=1),
        f"input is not persistently exciting of order {order}",
    )
    poorly = ~arr["determined"].any(axis=1) & ~arr["degenerate"].any(axis=1)
    poorly &= ~trace.not_enough_data & ~(arr["n_input_relations"] > 0).any(axis=1)
    add(poorly, "the window does not determine the parameters")
    add(arr["has_model"].all(axis=1) & ~arr["stable"].all(axis=1), "the model is unstable")
    if "excited" in arr:
        add(
            ~arr["excited"].all(axis=1) & ~arr["degenerate"].any(axis=1),
            "a channel varies by fewer than 3 quantization steps",
        )
    good = int((arr["determined"].all(axis=1)).sum())
    out.append(f"{good} of {n} clusters determine the parameters")
    if "trusted" in arr:
        trusted = int(arr["trusted"].all(axis=1).sum())
        guard = "only these are accepted" if trace.meta.get("guard") else "the guard is off"
        out.append(f"{trusted} of {n} clusters are trusted ({guard})")
    return out
