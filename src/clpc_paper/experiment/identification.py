"""The Table 1 appraiser on a servo log: trace, convergence and the steady-state model."""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc import CLPC, Convergence, Trace
from clpc.appraiser import decimate
from clpc_paper.experiment.results import Identification
from clpc_paper.experiment.settings import (
    CLUSTER_SIZE,
    GUARD,
    LOG_SAMPLE_TIME,
    PARAMETERS_SIZE,
    SAMPLE_TIME,
    TOLERANCES,
    WINDOW_SIZE,
)

__all__ = ["appraise", "find_convergence", "identify"]


def find_convergence(trace: Trace) -> tuple[Convergence, int]:
    """First of :data:`TOLERANCES` under which the trace converges (-1: none)."""
    conv = trace.convergence(*TOLERANCES[0])
    for level, tol in enumerate(TOLERANCES):
        conv = trace.convergence(*tol)
        if conv.converged:
            return conv, level
    return conv, -1


def appraise(u: Any, y: Any, dt: float, method: str) -> Identification:
    """Run the Table 1 appraiser on signals logged every ``dt`` [s] and build its model.

    The steady-state model is the mean theta after convergence under the first of
    :data:`TOLERANCES` that converges, else the last accepted update. ``u`` and ``y`` of the
    result are the signals given (not decimated).
    """
    appraiser = CLPC(
        order=PARAMETERS_SIZE - 1,
        window_size=WINDOW_SIZE,
        cluster_size=CLUSTER_SIZE,
        decimate_to=SAMPLE_TIME,
        method=method,
        guard=GUARD,
    )
    u_arr, y_arr = np.asarray(u), np.asarray(y)
    trace = appraiser.run(u_arr, y_arr, dt=dt)
    conv, level = find_convergence(trace)
    model = trace.steady_state_model(conv, allow_unconverged=level < 0)
    return Identification(trace, conv, level, model, u_arr, y_arr)


def identify(u_log: Any, y_log: Any, method: str) -> Identification:
    """Run the Table 1 appraiser on a 1 ms log and build the steady-state model.

    Parameters
    ----------
    u_log, y_log : array_like, shape (T,)
        Logged input and output at :data:`LOG_SAMPLE_TIME`.
    method : {"robust", "paper"}
        LPC solution (see :class:`clpc.CLPC`).

    Returns
    -------
    Identification
        With ``u`` and ``y`` decimated to :data:`SAMPLE_TIME` exactly as the appraiser does.
    """
    ident = appraise(u_log, y_log, LOG_SAMPLE_TIME, method)
    factor = round(SAMPLE_TIME / LOG_SAMPLE_TIME)
    ident.u, ident.y = decimate(u_log, factor), decimate(y_log, factor)
    return ident
