"""k-step prediction of a multi-model, vectorised over samples (a loop over the k steps)."""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.model.structure import Structure
from clpc.multimodel.schedule import Schedule
from clpc.multimodel.validity import validity

__all__ = ["predict_kstep"]


def predict_kstep(
    arrays: tuple[np.ndarray, np.ndarray, np.ndarray],
    f: Any,
    sched: Schedule,
    structure: Structure,
    u2: np.ndarray,
    y1: np.ndarray,
    k: int,
) -> np.ndarray:
    """``y_hat(n | n-k)``: step ``j`` feeds step ``j - lag``'s predictions into output lags.

    ``arrays`` are the local models' monic ``(den, num, icpt)``, ``f`` holds ``centres`` and
    ``widths``, ``u2`` has shape (T, n_inputs) and ``y1`` (T,). The first
    ``max(max_lag, schedule lag)`` samples are returned as measured.
    """
    den, num, icpt = arrays
    s = structure
    n_inputs = u2.shape[1]
    start = max(s.max_lag, sched.lag)
    n = y1.shape[0]
    forced = np.tile(icpt, (n - start, 1))
    for c in range(n_inputs):
        for lag in range(num.shape[2]):
            forced += u2[start - lag : n - lag, c, None] * num[None, :, c, lag]
    preds = [y1]
    for step in range(1, k + 1):
        local = forced.copy()
        for lag in range(1, s.na + 1):
            src = preds[max(step - lag, 0)]
            local -= src[start - lag : n - lag, None] * den[None, :, lag]
        ysrc = preds[max(step - 1, 0)] if sched.kind != 1 else y1
        if sched.kind == 0:
            ysrc = preds[max(step - sched.lag, 0)]
        psi = sched.values(u2, ysrc)[start:]
        cur = y1.copy()
        cur[start:] = (validity(psi, f.centres, f.widths) * local).sum(axis=1)
        preds.append(cur)
    return preds[k]
