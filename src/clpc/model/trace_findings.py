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

__all__ = ["Findings", "RunTracker", "describe_trace"]

#: runs named in a finding; more are counted ("and 12 more")
SHOWN_RUNS = 6


class RunTracker:
    """The runs (inclusive index ranges) where a mask fed in parts is true.

    Keeps the first :data:`SHOWN_RUNS` runs and the count of all: bounded memory however
    long the trace.
    """

    def __init__(self) -> None:
        self.shown: list[list[int]] = []
        self.count = 0
        self._open = False  # the last part ended inside a run
        self.n = 0

    def add(self, mask: np.ndarray) -> None:
        """Feed the next ``mask`` values (bool, shape (m,))."""
        m = int(mask.shape[0])
        if m == 0:
            return
        edges = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
        starts = np.flatnonzero(edges == 1)
        ends = np.flatnonzero(edges == -1) - 1
        for a, b in zip(starts.tolist(), ends.tolist(), strict=True):
            if a == 0 and self._open:  # the run of the last part goes on
                if self.count <= SHOWN_RUNS:
                    self.shown[-1][1] = self.n + b
                continue
            self.count += 1
            if self.count <= SHOWN_RUNS:
                self.shown.append([self.n + a, self.n + b])
        self._open = bool(mask[-1])
        self.n += m

    def text(self) -> str:
        """The runs, numbered from 1: ``"3-7, 9 and 4 more"`` ("" when none)."""
        parts = [f"{a + 1}" if a == b else f"{a + 1}-{b + 1}" for a, b in self.shown]
        more = f" and {self.count - SHOWN_RUNS} more" if self.count > SHOWN_RUNS else ""
        return ", ".join(parts) + more


class Findings:
    """The findings of :func:`describe_trace` over a trace fed in parts (in time order)."""

    def __init__(self) -> None:
        self.runs: dict[str, RunTracker] = {}
        self.n = self.determined = 0
        self.trusted: int | None = None
        self.guard = False

    def _track(self, text: str, mask: np.ndarray) -> None:
        self.runs.setdefault(text, RunTracker()).add(np.asarray(mask, dtype=bool))

    def add(self, part: Any) -> None:
        """Feed the next updates (a :class:`clpc.Trace` or a part of one)."""
        arr = part.arrays
        self.guard = bool(part.meta.get("guard"))
        lacking = (arr["n_input_relations"] > 0).any(axis=1)
        degenerate = arr["degenerate"].any(axis=1)
        short = np.asarray(part.not_enough_data, dtype=bool)
        self._track("fewer lag vectors than min_rows", short)
        self._track("nothing varies (degenerate window)", degenerate)
        order = part.structure.nb + 1
        self._track(f"input is not persistently exciting of order {order}", lacking)
        poorly = ~arr["determined"].any(axis=1) & ~degenerate & ~short & ~lacking
        self._track("the window does not determine the parameters", poorly)
        unstable = arr["has_model"].all(axis=1) & ~arr["stable"].all(axis=1)
        self._track("the model is unstable", unstable)
        if "excited" in arr:
            quiet = ~arr["excited"].all(axis=1) & ~degenerate
            self._track("a channel varies by fewer than 3 quantization steps", quiet)
        self.n += len(part)
        self.determined += int(arr["determined"].all(axis=1).sum())
        if "trusted" in arr:
            self.trusted = (self.trusted or 0) + int(arr["trusted"].all(axis=1).sum())

    def lines(self) -> list[str]:
        """The findings in words (see :func:`describe_trace`)."""
        held_note = " (the parameters there are held)" if self.guard else ""
        out = [
            f"{text} in clusters {runs.text()}{held_note}"
            for text, runs in self.runs.items()
            if runs.count
        ]
        out.append(f"{self.determined} of {self.n} clusters determine the parameters")
        if self.trusted is not None:
            guard = "only these are accepted" if self.guard else "the guard is off"
            out.append(f"{self.trusted} of {self.n} clusters are trusted ({guard})")
        return out


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
        parameters there are held"``; the same as :class:`Findings` fed the trace in parts.
    """
    findings = Findings()
    findings.add(trace)
    return findings.lines()
