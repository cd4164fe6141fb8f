"""k-step prediction of a multi-model, vectorised over samples (a loop over the k steps)."""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.data.signals import signals
from clpc.model.errors import as_2d
from clpc.model.structure import Structure
from clpc.multimodel.fitting import Fitted, monic_arrays
from clpc.multimodel.schedule import Schedule
from clpc.multimodel.validity import validity

__all__ = ["predict_kstep", "predict_measured"]


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
    # step j reads the predictions of steps j - 1 .. j - keep only (output lags, the
    # schedule's lag): older steps are dropped, so memory is O(T) whatever k is
    keep = max(s.na, sched.lag if sched.kind == 0 else 1, 1)
    preds = {0: y1}
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
        preds[step] = cur
        if step - keep > 0:
            del preds[step - keep]
    return preds[k]


def predict_measured(
    fitted: Fitted,
    schedule: Schedule,
    structure: Structure,
    n_inputs: int,
    u: Any,
    y: Any,
    k: int,
) -> np.ndarray:
    """:func:`predict_kstep` on measured data (:meth:`clpc.MultiModel.predict`; ``k`` checked)."""
    u, y = signals(u, y, what="predict")
    u2, _ = as_2d(u, n_inputs, "u")
    y1 = np.asarray(y, dtype=np.float64).ravel()
    if u2.shape[0] != y1.shape[0]:
        raise ValueError(f"u and y must have the same length; got {u2.shape[0]}, {y1.shape[0]}.")
    arrays = monic_arrays(fitted.local_models)
    return predict_kstep(arrays, fitted, schedule, structure, u2, y1, k)
