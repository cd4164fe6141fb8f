"""The CLPC kernel's FSM output: accept or hold each solved window, in time order.

Plain ``numba.njit(cache=True)`` functions: :func:`fsm_output`, and :func:`update_windows`,
the solve (:func:`clpc.appraiser.window_solve.solve_windows`) and the output in one call.
The rules are :mod:`clpc.core.rules`, the monic form and the stability test
:mod:`clpc.core.polynomials`: nothing here restates them.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from clpc.appraiser.blocks import BlockCache
from clpc.appraiser.kernel_types import FsmOutput, FsmSettings, FsmState, Solved, WindowPlan
from clpc.appraiser.window_solve import solve_windows
from clpc.core.polynomials import monic, schur_stable
from clpc.core.rules import (
    SolveSettings,
    accepts,
    eig_ratio,
    index_j,
    is_determined,
    is_trusted,
    likelihood_variance,
)

__all__ = ["fsm_output", "update_windows"]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def fsm_output(solved: Solved, fs: FsmSettings, state: FsmState, out: FsmOutput) -> None:
    """The FSM output of solved windows, in time order.

    Accepts or holds each estimate (:func:`clpc.core.rules.accepts`), updates the carried
    ``state`` in place, and fills the monic forms, the Schur stability flag and the
    per-window statistics (``D = lambda_max - lambda_min``, ``J`` of eq. 22).
    """
    count, n_eq, p = solved.theta.shape
    work = np.empty(fs.na + 1)
    for w in range(count):
        n_rows = solved.n_rows[w]
        few = n_rows < fs.min_rows
        out.not_enough[w] = few
        for e in range(n_eq):
            lo = solved.eigenvalues[w, e, 0]
            hi = solved.eigenvalues[w, e, p - 1]
            out.lambda_min[w, e] = lo
            out.lambda_max[w, e] = hi
            out.D[w, e] = hi - lo
            out.eig_ratio[w, e] = eig_ratio(lo, hi)
            var = likelihood_variance(solved.noise_variance[w, e], hi, n_rows)
            out.J[w, e] = index_j(var, n_rows)
            det = is_determined(
                solved.n_null[w, e],
                solved.n_input_relations[w, e],
                solved.separation[w, e],
                solved.degenerate[w, e],
                fs.separation_tol,
            )
            out.determined[w, e] = det
            trusted = is_trusted(n_rows, fs.trust_rows, solved.excited[w, e], det)
            out.trusted[w, e] = trusted
            weights = (solved.a0_weight[w, e], fs.min_a0_weight)
            ok = accepts(few, solved.degenerate[w, e], weights, fs.guard, trusted)
            out.accepted[w, e] = ok
            if ok:
                for a in range(p):
                    state.last_theta[e, a] = solved.theta[w, e, a]
                state.last_c[e] = solved.c[w, e]
                state.has_model[e] = True
            for a in range(p):
                out.theta[w, e, a] = state.last_theta[e, a]
            out.c[w, e] = state.last_c[e]
            out.has_model[w, e] = state.has_model[e]
            if state.has_model[e]:
                target = e if fs.paired else -1
                monic(
                    state.last_theta[e], fs.na, fs.nb, fs.nk, target, out.den[w, e], out.num[w, e]
                )
                out.stable[w, e] = schur_stable(out.den[w, e], work)
            else:
                out.den[w, e, 0] = 1.0
                for k in range(1, fs.na + 1):
                    out.den[w, e, k] = 0.0
                for i in range(out.num.shape[2]):
                    for k in range(out.num.shape[3]):
                        out.num[w, e, i, k] = 0.0
                out.stable[w, e] = False


@numba.njit(cache=True, nogil=True, error_model="numpy")
def update_windows(
    samples: np.ndarray,
    first_row: int,
    windows: tuple[int, int],
    settings: tuple[Any, ...],
    state: tuple[Any, ...],
    out: tuple[Any, ...],
    cache: tuple[np.ndarray, ...],
) -> None:
    """:func:`solve_windows` then :func:`fsm_output` in one call (one dispatch per update).

    The containers arrive as plain tuples - ``settings = (plan, solve settings, FSM
    settings)``, ``state``, ``out = (solved, output)``, ``cache`` - in the fields' order of
    :class:`WindowPlan`, :class:`SolveSettings`, :class:`FsmSettings`, :class:`FsmState`,
    :class:`Solved`, :class:`FsmOutput` and :class:`BlockCache`: numba types plain tuples
    of arrays several times faster than named tuples at the call, which is most of the cost
    of one update.
    """
    plan = WindowPlan(*settings[0])
    s = SolveSettings(*settings[1])
    fs = FsmSettings(*settings[2])
    solved = Solved(*out[0])
    solve_windows(samples, first_row, windows, plan, s, solved, BlockCache(*cache))
    fsm_output(solved, fs, FsmState(*state), FsmOutput(*out[1]))
