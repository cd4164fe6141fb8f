"""The servo's inner loop (one source) and the choice between its two engines.

:func:`_servo_loop` runs the drive and the mechanics over one chunk of logged samples; the
steps it takes are the kernels of :mod:`clpc_paper.plants.servo_kernels`. The same function runs
as plain Python (``engine="python"``, :data:`_servo_loop_py`) or compiled by numba
(``numba.njit(cache=True)``: :data:`_servo_loop_jit`, compiled on first use).

Sample ``i`` is logged at the start of the controller period that begins at ``t_i``: the
resolver reading the drive uses, the true states and the velocity command computed then.
The torque of sample ``i`` is the mean of the controller's torque over the logging period
that starts at ``t_i`` (the torque the mechanics integrate over it): one controller sample
per period would alias the loop's noise-driven torque, which the motor averages and the
position never shows, into the log.
"""

from __future__ import annotations

from collections.abc import Callable

import numba
import numpy as np

from clpc_paper.checks import check_choice
from clpc_paper.plants.servo_kernels import (
    _clip,
    _drive_step,
    _gains,
    _load_state,
    _log_sample,
    _mechanics,
    _mechanics_step,
    _quantise,
    _store_state,
)
from clpc_paper.plants.servo_layout import (
    _O_TAU,
    _P_LOADFB,
    _P_OPEN,
    _P_RES,
    LoopConfig,
    LoopInputs,
)

__all__ = ["numba_available"]

#: signature of both engines of the loop
Loop = Callable[[LoopConfig, LoopInputs, np.ndarray, np.ndarray], None]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _servo_loop(config: LoopConfig, inputs: LoopInputs, state: np.ndarray, out: np.ndarray) -> None:
    """Run the drive and the mechanics over one chunk of samples, in place.

    Parameters
    ----------
    config : LoopConfig
        Steps per logging period, mechanical substeps per controller step, packed
        parameters ``p`` (shape ``(_N_P,)``) and filters ``filt`` (shape ``(3, 5)``).
    inputs : LoopInputs
        Command, shape ``(n,)`` [rad] (open loop: torque [N m]), held over each logging
        period; resolver noise [rad] and torque disturbance [N m], each of shape
        ``(n * steps_per_sample,)`` or ``(0,)`` for none.
    state : numpy.ndarray
        Shape ``(_N_S,)``: state at the start of the chunk; overwritten with the final state.
    out : numpy.ndarray
        Shape ``(n, _N_OUT)``: filled with the logged signals (see the ``_O_*`` indices).
    """
    command, position_noise, disturbance = inputs
    p, filt = config.p, config.filt
    gains = _gains(p)
    mech = _mechanics(p, config.substeps)
    res = p[_P_RES]
    inv_res = 1.0 / res if res > 0.0 else 0.0
    load_fb = p[_P_LOADFB] != 0.0
    open_loop = p[_P_OPEN] != 0.0
    has_noise = position_noise.shape[0] > 0
    has_dist = disturbance.shape[0] > 0
    shaft, drive = _load_state(state)
    k = 0  # controller step within the chunk
    for i in range(command.shape[0]):
        r = command[i]
        tau_sum = 0.0
        for j in range(config.steps_per_sample):
            th_fb = shaft.th_l if load_fb else shaft.th_m  # resolver: noise, then quantiser
            if has_noise:
                th_fb += position_noise[k]
            y = _quantise(th_fb, res, inv_res)
            if open_loop:
                v_cmd = 0.0
                tau = _clip(r, gains.tlim)
            else:
                v_cmd, tau, drive = _drive_step(gains, filt, drive, r, y)
            if j == 0:
                _log_sample(out, i, y, shaft, v_cmd, tau)
            tau_sum += tau
            tau_app = tau
            if has_dist:
                tau_app += disturbance[k]
            for _s in range(config.substeps):
                shaft = _mechanics_step(mech, shaft, tau_app)
            k += 1
        out[i, _O_TAU] = tau_sum / config.steps_per_sample  # mean torque of the period
    _store_state(state, shaft, drive)


#: The loop as plain Python (the reference; the function itself when ``NUMBA_DISABLE_JIT=1``).
_servo_loop_py: Loop = getattr(_servo_loop, "py_func", _servo_loop)
#: The loop compiled by numba (a dependency of clpc), on its first call.
_servo_loop_jit: Loop = _servo_loop


def numba_available() -> bool:
    """Return whether the compiled loop can be built (the fast simulation path).

    Returns
    -------
    bool
        ``True``: numba is a dependency of clpc, so :func:`clpc_paper.plants.simulate_servo`
        runs compiled code by default.
    """
    return True


def _pick_loop(engine: str) -> Loop:
    """The loop of ``engine``: ``"python"`` plain Python, ``"auto"`` and ``"numba"`` compiled."""
    if check_choice(engine, "engine", ("auto", "numba", "python")) == "python":
        return _servo_loop_py
    return _servo_loop_jit
