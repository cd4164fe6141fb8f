"""What the servo loop works on: packed parameters, carried state, logged outputs.

The loop (:mod:`clpc_paper.plants.servo_loop`) takes flat float64 arrays so that numba compiles
it once for every parameter set; this module fixes their layout and fills them:

* ``p``, shape ``(_N_P,)``: the parameters (see the ``_P_*`` indices), from :func:`_pack`;
* ``state``, shape ``(_N_S,)``: mechanics, resolver and controller state carried from one
  chunk of samples to the next (``_S_*``), from :func:`_initial_state`;
* ``out``, shape ``(n_samples, _N_OUT)``: the logged signals (``_O_*``).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from clpc_paper.plants.servo_parameters import ServoParameters

__all__ = ["LoopConfig", "LoopInputs"]

# indices of the packed parameter vector
_P_KP, _P_KV, _P_KVKI_TC, _P_VLIM, _P_TLIM = 0, 1, 2, 3, 4
_P_JM, _P_JL, _P_K, _P_C = 5, 6, 7, 8
_P_BM, _P_BL, _P_FM, _P_FL = 9, 10, 11, 12
_P_RES, _P_TC, _P_LOADFB, _P_RIGID, _P_OPEN = 13, 14, 15, 16, 17
_N_P = 18

# indices of the state vector (carried between chunks)
_S_THM, _S_WM, _S_THL, _S_WL, _S_YPREV, _S_INT = 0, 1, 2, 3, 4, 5
_S_LP1, _S_LP2, _S_NO1, _S_NO2, _S_VF1, _S_VF2 = 6, 7, 8, 9, 10, 11
_N_S = 12

# columns of the output array, shape (n_samples, _N_OUT)
_O_Y, _O_THL, _O_WL, _O_THM, _O_WM, _O_VCMD, _O_TAU = 0, 1, 2, 3, 4, 5, 6
_N_OUT = 7


class LoopConfig(NamedTuple):
    """Fixed settings of one simulation (a NamedTuple: numba compiles it as a tuple)."""

    steps_per_sample: int  #: controller steps per logging period
    substeps: int  #: mechanical integration steps per controller step
    p: np.ndarray  #: shape (_N_P,), packed parameters (see the ``_P_*`` indices)
    filt: np.ndarray  #: shape (3, 5), biquads of the torque low-pass, notch, velocity filter


class LoopInputs(NamedTuple):
    """One chunk of inputs of the loop."""

    command: np.ndarray  #: shape (n,), position command [rad] (open loop: torque [N m])
    position_noise: np.ndarray  #: shape (n * steps_per_sample,) [rad], or (0,) for none
    disturbance: np.ndarray  #: shape (n * steps_per_sample,) [N m], or (0,) for none


def _pack(params: ServoParameters, rate: float, open_loop: bool) -> np.ndarray:
    """Packed parameter vector, shape ``(_N_P,)``, for a controller at ``rate`` [Hz]."""
    p = np.zeros(_N_P)
    p[_P_KP] = params.position_gain
    p[_P_KV] = params.velocity_gain
    p[_P_KVKI_TC] = params.velocity_gain * params.velocity_integrator / rate
    p[_P_VLIM] = params.velocity_limit
    p[_P_TLIM] = params.torque_limit
    p[_P_JM] = params.motor_inertia
    p[_P_JL] = params.load_inertia
    p[_P_K] = 0.0 if params.rigid else params.coupling_stiffness
    p[_P_C] = params.coupling_damping
    p[_P_BM] = params.motor_viscous_friction
    p[_P_BL] = params.load_viscous_friction
    p[_P_FM] = params.motor_coulomb_friction
    p[_P_FL] = params.load_coulomb_friction
    p[_P_RES] = params.resolution
    p[_P_TC] = 1.0 / rate
    p[_P_LOADFB] = float(params.feedback_on_load)
    p[_P_RIGID] = float(params.rigid)
    p[_P_OPEN] = float(open_loop)
    return p


def _initial_state(position: float, velocity: float, resolution: float) -> np.ndarray:
    """State vector, shape ``(_N_S,)``: shafts at ``position`` [rad], ``velocity`` [rad/s].

    The previous resolver reading is the quantised ``position`` (step ``resolution`` [rad],
    0 for none), so the first velocity estimate is not a jump; filters and integrator are 0.
    """
    state = np.zeros(_N_S)
    state[_S_THM] = state[_S_THL] = position
    state[_S_WM] = state[_S_WL] = velocity
    state[_S_YPREV] = (
        math.floor(position * (1.0 / resolution) + 0.5) * resolution if resolution > 0 else position
    )
    return state
