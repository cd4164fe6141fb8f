"""Free run of a fitted multi-model from its input (:meth:`clpc.MultiModel.simulate`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.data.signals import signals
from clpc.model.errors import as_2d
from clpc.model.structure import Structure
from clpc.multimodel.fitting import Fitted, blend_run, monic_arrays
from clpc.multimodel.schedule import Schedule

__all__ = ["free_run"]


def free_run(
    fitted: Fitted,
    schedule: Schedule,
    structure: Structure,
    n_inputs: int,
    u: Any,
    y_init: Any | None,
    u_init: Any | None,
) -> np.ndarray:
    """The blended free run of :meth:`clpc.MultiModel.simulate` (compiled loop), shape (T,)."""
    u2, _ = as_2d(signals(u, what="simulate", needs_y=False)[0], n_inputs, "u")
    s = structure
    pad = max(s.na, s.nk + s.nb, schedule.lag, 1)
    y_ext = np.zeros(pad + u2.shape[0])
    u_ext = np.zeros((pad + u2.shape[0], n_inputs))
    u_ext[pad:] = u2
    if y_init is not None:
        y0 = np.asarray(y_init, dtype=np.float64).ravel()[-pad:]
        y_ext[pad - y0.size : pad] = y0
    if u_init is not None:
        u0, _ = as_2d(u_init, n_inputs, "u_init")
        u0 = u0[-pad:]
        u_ext[pad - u0.shape[0] : pad] = u0
    arrays = monic_arrays(fitted.local_models)
    with np.errstate(all="ignore"):
        blend_run(arrays, fitted.centres, fitted.widths, schedule, u_ext, y_ext, pad)
    return y_ext[pad:]
