"""Plain-language findings over the clusters of a CLPC trace (:func:`describe_trace`).

Each finding names the clusters (numbered from 1) where a condition holds: too few lag
vectors, a degenerate window, an input not persistently exciting of order ``nb + 1``, a
window that does not determine the parameters, an unstable model, a channel varying by
fewer than :data:`clpc.core.rules.EXCITATION_QUANTA` quantization steps; then the counts of
determined and trusted clusters. A fit's verdict is :func:`clpc.model.verdict.fit_verdict`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["describe_trace"]


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

    Parameters
    ----------
    trace : Trace
        The per-cluster record of a CLPC run (:class:`clpc.Trace`).

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
