"""The crank servo's inner loop (one source, plain Python or compiled by numba).

The equations are those of :mod:`clpc_paper.plants.crank_servo`; the loop structure is the one
of :func:`clpc_paper.plants.servo_loop._servo_loop` (the drive runs once per controller period,
the mechanics ``substeps`` times, sample ``i`` is logged at the start of the controller
period that begins at ``t_i``), and the scalar helpers (clip, soft threshold, quantiser)
are the servo's own :mod:`clpc_paper.plants.servo_kernels`.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba.extending import register_jitable

from clpc_paper.plants.servo_kernels import _clip, _quantise, _soft_threshold

__all__ = ["N_OUT", "N_P", "N_STATE"]

# packed parameters p
_J0, _MR2, _MGR, _B, _F, _KP, _VLIM, _KV, _KVKI_TC, _TLIM, _TC, _ALPHA_V, _RES = range(13)
N_P = 13
# state: angle, velocity, last reading, filtered velocity, integrator
_TH, _W, _YPREV, _VF, _INT = range(5)
N_STATE = 5
# logged columns: reading, true angle, true velocity, velocity command, torque
N_OUT = 5


@register_jitable(error_model="numpy")
def _crank_mechanics(p: np.ndarray, th: float, w: float, tau: float, h: float) -> tuple:
    """One semi-implicit Euler step ``h`` [s] of the crank under motor torque ``tau`` [N m].

    ``J(th) w' = tau - m r^2 sin cos w^2 - m g r sin(th) - b w - F sgn(w)`` with the
    viscous and Coulomb terms implicit (exact stick/slip, as the servo's mechanics).
    """
    s = math.sin(th)
    c = math.cos(th)
    j = p[_J0] + p[_MR2] * s * s
    f = tau - p[_MR2] * s * c * w * w - p[_MGR] * s
    w_new = _soft_threshold(w + h * f / j, h * p[_F] / j) / (1.0 + h * p[_B] / j)
    return th + h * w_new, w_new


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _crank_loop(
    p: np.ndarray,
    steps: int,
    substeps: int,
    command: np.ndarray,
    noise: np.ndarray,
    state: np.ndarray,
    out: np.ndarray,
) -> None:
    """Run the drive and the crank over ``command`` (shape (n,)), in place.

    ``noise`` holds the resolver noise of every controller step (shape (n * steps,)),
    ``state`` (shape (N_STATE,)) the start state and receives the final one, ``out``
    (shape (n, N_OUT)) the logged signals.
    """
    th, w = state[_TH], state[_W]
    y_prev, vf, integ = state[_YPREV], state[_VF], state[_INT]
    res = p[_RES]
    inv_res = 1.0 / res if res > 0.0 else 0.0
    h = p[_TC] / substeps
    k = 0
    for i in range(command.shape[0]):
        r = command[i]
        for jj in range(steps):
            y = _quantise(th + noise[k], res, inv_res)
            vf += p[_ALPHA_V] * ((y - y_prev) / p[_TC] - vf)  # 1st-order velocity low-pass
            y_prev = y
            v_cmd = _clip(p[_KP] * (r - y), p[_VLIM])
            e_v = v_cmd - vf
            u = p[_KV] * e_v + integ
            tau = _clip(u, p[_TLIM])
            pushing = (u > p[_TLIM] and e_v > 0.0) or (u < -p[_TLIM] and e_v < 0.0)
            if not pushing:  # conditional integration (anti-windup)
                integ = _clip(integ + p[_KVKI_TC] * e_v, p[_TLIM])
            if jj == 0:
                out[i, 0] = y
                out[i, 1] = th
                out[i, 2] = w
                out[i, 3] = v_cmd
                out[i, 4] = tau
            for _s in range(substeps):
                th, w = _crank_mechanics(p, th, w, tau, h)
            k += 1
    state[_TH], state[_W] = th, w
    state[_YPREV], state[_VF], state[_INT] = y_prev, vf, integ
