"""What would help when ``clpc track`` accepts few windows because the input excites too little.

A window's input must be persistently exciting of order ``nb + 1`` (a window whose solution
is an input relation, :func:`clpc.core.rules.is_input_relation`, is never accepted). A sine
sweep is, in a short window, one sine: persistently exciting of order 2 only, so with
``nb = 2`` no window is accepted although the whole record excites many orders.
:func:`excitation_advice` says so in one paragraph, with the numbers.
"""

from __future__ import annotations

import shlex
from typing import Any

import numpy as np

from clpc.appraiser.convergence import MIN_TRUSTED_FRACTION
from clpc.appraiser.scanned import ScannedTrace
from clpc.model.excitation import EXCITATION_RTOL, excitation_ratios, needed_order

__all__ = ["excitation_advice"]


def _order(u: np.ndarray, need: int) -> tuple[int, float]:
    """The persistent-excitation order of ``u`` (up to ``need``) and its ratio at ``need``."""
    ratios = excitation_ratios(u, need)
    return int(np.argmin(np.r_[ratios, 0.0] >= EXCITATION_RTOL)), float(ratios[-1])


def _measured(u: np.ndarray, window: int, need: int) -> str:
    """The excitation of the last window of ``u`` and of all of ``u``, in words."""
    if u.shape[0] < max(window, need + 1):
        return ""
    k_win, r_win = _order(u[-window:], need)
    k_all, _ = _order(u, need)
    text = (
        f"; measured, the input of the last window ({window} samples) is persistently "
        f"exciting of order {k_win} of the {need} (na + nb + 1) this structure needs "
        f"(singular-value ratio {r_win:.2g} at order {need}, threshold {EXCITATION_RTOL:g})"
    )
    if u.shape[0] > window:
        reach = f"at least {need}" if k_all >= need else str(k_all)
        text += f", the last {u.shape[0]} samples together of order {reach}"
    return text


def excitation_advice(
    trace: Any, u_tail: np.ndarray, window_size: int, command: dict[str, Any]
) -> str | None:
    """One paragraph on what would help when windows are rejected for want of excitation.

    Parameters
    ----------
    trace : Trace or ScannedTrace
        Every update of the run, in memory or scanned in parts (its ``counts`` of
        ``accepted`` updates and of updates ``lacking`` excitation, and ``structure``).
    u_tail : ndarray, shape (T, n_inputs)
        The record's last input samples at the appraiser's rate (``T`` may be 0).
    window_size : int
        Lag vectors per window (``--window-size``).
    command : dict
        ``file``, ``inputs`` and ``outputs`` (column names) of the record, for the
        ``clpc identify`` command line suggested.

    Returns
    -------
    str or None
        ``None`` when at least :data:`~clpc.appraiser.convergence.MIN_TRUSTED_FRACTION` of
        the updates were accepted, or when fewer than half of the rejected ones lack
        excitation; else the counts (accepted / total, rejected as not persistently
        exciting of order ``nb + 1``), the excitation (of the ``na + nb + 1`` needed,
        :func:`clpc.model.excitation.needed_order`) measured on the last window and the
        tail of the record, and what would help: a richer input, a lower ``--nb``, a
        longer ``--window-size``, or ``clpc identify`` on the whole record.
    """
    scan = trace if hasattr(trace, "counts") else ScannedTrace.of(trace)
    n = len(scan)
    if n == 0:
        return None
    accepted, lacking = scan.counts["accepted"], scan.counts["lacking"]
    if accepted >= MIN_TRUSTED_FRACTION * n or lacking == 0 or 2 * lacking < n - accepted:
        return None
    s = trace.structure
    u = np.asarray(u_tail, dtype=np.float64)
    u = u.reshape(u.shape[0], -1) if u.size else np.empty((0, 1))
    helps = ["a richer input (noise, a PRBS or several sines at once, not one slow sweep)"]
    if s.nb > 0:
        helps.append(f"a lower --nb (--nb {s.nb - 1}: order {s.na + s.nb} needed)")
    helps.append(
        f"a longer --window-size than {window_size} (a sweep passes more frequencies in it)"
    )
    words = ["clpc", "identify", str(command["file"])]
    for flag, key in (("-u", "inputs"), ("-y", "outputs")):
        for name in command[key]:
            words += [flag, str(name)]
    helps.append(f"a model of the whole record: {shlex.join(words)}")
    return (
        f"The data cannot decide the model in a window: {accepted} of {n} windows accepted, "
        f"{lacking} rejected because the input is not persistently exciting of order {s.nb + 1} "
        f"(nb + 1 with nb = {s.nb}) within {window_size} lag vectors"
        f"{_measured(u, window_size + s.max_lag, needed_order(s))}. What would help: "
        + "; ".join(helps)
        + "."
    )
