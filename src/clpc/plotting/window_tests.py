"""The figure of why the appraiser's windows were accepted or rejected: the guard's tests.

Per cluster update and output, on a shared time axis:

* **the first test each update failed** (or "accepted"): too few rows, output not excited
  above its quantization, not determined, or accepted;
* **separation**: the candidate eigenvalue over the next one outside the near-null
  subspace; a window *determines* its model only when it is at most ``rule.separation``;
* **near-null directions and input relations**: a determined window has exactly one
  near-null direction and no relation among the inputs alone (an input that excites too
  few orders in the window, such as one sine of a slow sweep, leaves several, and some of
  them involve the inputs only).

Accepted updates are drawn in colour, the others in grey.
"""

from __future__ import annotations

from os import PathLike
from typing import Any

import numpy as np

from clpc.core.figure import COLORS, new_figure, place_legend, save_figure, time_label
from clpc.core.rules import RobustRule, trust_rows

__all__ = ["REASONS", "first_failure", "plot_window_tests"]

#: values are drawn no lower than this (an exact relation gives 0 on a log axis)
FLOOR = 1e-6


def _panel(
    ax: Any, t: np.ndarray, values: np.ndarray, accepted: np.ndarray, limit: float, side: str
) -> None:
    v = np.clip(np.asarray(values, dtype=float), FLOOR, None)
    ax.semilogy(t[~accepted], v[~accepted], ".", color="0.6", ms=3, label="rejected")
    ax.semilogy(t[accepted], v[accepted], ".", color=COLORS["theta"], ms=3, label="accepted")
    ax.axhline(limit, color=COLORS["model"], lw=1.2, ls="--", label=f"threshold {limit:g}")
    ax.text(
        0.995, 0.04 if side == "below" else 0.93, f"passes {side} the line",
        transform=ax.transAxes, ha="right", va="bottom" if side == "below" else "top",
        fontsize=8, color=COLORS["model"],
    )  # fmt: skip
    ax.grid(True, alpha=0.3, which="both")


#: the tests in the order the guard applies them, as the reason strip's rows
REASONS = ("too few rows", "not excited", "not determined", "accepted")


def first_failure(trace: Any, equation: int) -> np.ndarray:
    """Index into :data:`REASONS` of the first test each update failed (3: accepted).

    Parameters
    ----------
    trace : Trace
    equation : int
        Output index.

    Returns
    -------
    ndarray of int, shape (n_updates,)
        In the guard's order: rows below :func:`clpc.core.rules.trust_rows` of a full
        window (0), the output not excited (1), not determined (2); 3 for an accepted
        update, and for one that passed every test yet was not accepted (none with the
        guard on).
    """
    a = trace.arrays
    rows = np.asarray(trace.rows)
    # the guard's row count (clpc.core.rules.trust_rows) of a full window (the most rows)
    need = trust_rows(int(a["theta"].shape[2]), int(np.max(rows, initial=1)))
    rows_ok = ~np.asarray(trace.not_enough_data, dtype=bool) & (rows >= need)
    reason = np.full(len(trace), 3)
    reason[~np.asarray(a["determined"][:, equation], dtype=bool)] = 2
    reason[~np.asarray(a["excited"][:, equation], dtype=bool)] = 1
    reason[~rows_ok] = 0
    accepted = np.asarray(a["accepted"][:, equation], dtype=bool)
    reason[accepted] = 3
    return reason


def plot_window_tests(
    trace: Any,
    path: str | PathLike[str] | None = None,
    *,
    rule: RobustRule | None = None,
    title: str | None = None,
) -> Any:
    """Plot the guard's tests of every update: which failed first, and the measures behind.

    Parameters
    ----------
    trace : Trace
        Output of :meth:`clpc.CLPC.run` (or a thinned copy).
    path : str or path-like, optional
        Also write the figure as PNG here.
    rule : RobustRule, optional
        The thresholds the appraiser used (:attr:`clpc.CLPC.rule`); default
        ``RobustRule()``.
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
        Three axes per output: the first test failed (:func:`first_failure`), the
        separation against ``rule.separation``, and the near-null directions and input
        relations.
    """
    rule = RobustRule() if rule is None else rule
    n_eq = trace.n_equations
    fig, axes = new_figure(3 * n_eq, 1, height=1.8)
    t = np.asarray(trace.time, dtype=float)
    xlabel = time_label(trace.sample_time)
    for e in range(n_eq):
        name = trace.output_names[e] if e < len(trace.output_names) else f"y{e}"
        accepted = np.asarray(trace.arrays["accepted"][:, e], dtype=bool)
        why_ax, sep_ax, null_ax = axes[3 * e, 0], axes[3 * e + 1, 0], axes[3 * e + 2, 0]
        reason = first_failure(trace, e)
        for k in range(len(REASONS)):
            hit = reason == k
            color = COLORS["theta"] if k == 3 else "0.55"
            why_ax.plot(t[hit], np.full(hit.sum(), k), "|", color=color, ms=8)
        why_ax.set_yticks(range(len(REASONS)), [f"{r} ({(reason == k).sum()})"
                                                for k, r in enumerate(REASONS)])  # fmt: skip
        why_ax.set_ylim(-0.6, len(REASONS) - 0.4)
        why_ax.set_title(f"output {name}: first test failed", fontsize="small")
        _panel(sep_ax, t, trace.arrays["separation"][:, e], accepted, rule.separation, "below")
        sep_ax.set_ylabel("separation")
        place_legend(sep_ax)
        nulls = np.asarray(trace.arrays["n_null"][:, e], dtype=float)
        relations = np.asarray(trace.arrays["n_input_relations"][:, e], dtype=float)
        null_ax.step(t, nulls, where="post", color=COLORS["theta"], label="near-null (need 1)")
        null_ax.step(t, relations, where="post", color=COLORS["model"],
                     label="input relations (need 0)")  # fmt: skip
        null_ax.set_ylabel("directions")
        null_ax.set_ylim(-0.3, max(float(np.max(nulls, initial=1.0)), 2.0) + 0.3)
        null_ax.grid(True, alpha=0.3)
        place_legend(null_ax)
        for ax in (why_ax, sep_ax, null_ax):
            ax.set_xlabel(xlabel)
            if t.size > 1:
                ax.set_xlim(t[0], t[-1])
    n_acc = int(np.asarray(trace.arrays["accepted"]).all(axis=1).sum())
    fig.suptitle(title or f"Window tests: {n_acc} of {len(trace)} updates accepted",
                 fontsize="medium")  # fmt: skip
    save_figure(fig, path)
    return fig
