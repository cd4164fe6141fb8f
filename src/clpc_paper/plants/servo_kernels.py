"""The pieces the servo loop calls once per controller step (one source, two engines).

Every function here is registered with ``numba.extending.register_jitable``: plain
Python in the ``"python"`` engine, compiled with the loop by numba otherwise. They take and
return scalars and NamedTuples of scalars (which numba keeps in registers), so the compiled
loop stays fast and both engines compute the same operations in the same order:
bit-identical numbers.

The drive (:func:`_drive_step`) and the discretised mechanics (:func:`_mechanics_step`:
symplectic Euler with implicit viscous and Coulomb friction) implement the equations of
the "Continuous-time model" and "Discretisation" sections of :mod:`clpc_paper.plants.servo`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba.extending import register_jitable

from clpc_paper.plants.servo_layout import (
    _O_TAU,
    _O_THL,
    _O_THM,
    _O_VCMD,
    _O_WL,
    _O_WM,
    _O_Y,
    _P_BL,
    _P_BM,
    _P_C,
    _P_FL,
    _P_FM,
    _P_JL,
    _P_JM,
    _P_K,
    _P_KP,
    _P_KV,
    _P_KVKI_TC,
    _P_RIGID,
    _P_TC,
    _P_TLIM,
    _P_VLIM,
    _S_INT,
    _S_LP1,
    _S_LP2,
    _S_NO1,
    _S_NO2,
    _S_THL,
    _S_THM,
    _S_VF1,
    _S_VF2,
    _S_WL,
    _S_WM,
    _S_YPREV,
)

__all__ = ["Drive", "Gains", "Mechanics", "Shaft"]


class Shaft(NamedTuple):
    """Mechanical state: motor and load angles [rad] and velocities [rad/s]."""

    th_m: float
    w_m: float
    th_l: float
    w_l: float


class Drive(NamedTuple):
    """Controller state: last reading [rad], integrator [N m], biquad delays (DF2T)."""

    y_prev: float
    integ: float
    lp1: float
    lp2: float
    no1: float
    no2: float
    vf1: float
    vf2: float


class Gains(NamedTuple):
    """Controller constants: ``Kp``, ``Kv``, ``Kv Ki T_c``, limits, ``1 / T_c``."""

    kp: float
    kv: float
    kvki_tc: float
    vlim: float
    tlim: float
    inv_tc: float


class Mechanics(NamedTuple):
    """Constants of one mechanical step ``h`` [s] (implicit friction terms, coupling)."""

    h: float
    h_over_jm: float
    thr_m: float
    inv_div_m: float
    h_over_jl: float
    thr_l: float
    inv_div_l: float
    k_s: float
    c_s: float
    rigid: bool


@register_jitable(error_model="numpy")
def _clip(x: float, limit: float) -> float:
    """``x`` limited to ``[-limit, limit]``."""
    if x > limit:
        return limit
    if x < -limit:
        return -limit
    return x


@register_jitable(error_model="numpy")
def _soft_threshold(x: float, thr: float) -> float:
    """``sign(x) max(|x| - thr, 0)``: the implicit Coulomb friction step."""
    if x > thr:
        return x - thr
    if x < -thr:
        return x + thr
    return 0.0


@register_jitable(error_model="numpy")
def _quantise(x: float, res: float, inv_res: float) -> float:
    """Resolver reading of ``x`` [rad] with step ``res`` (``inv_res = 1 / res``; 0: none)."""
    if res > 0.0:
        return math.floor(x * inv_res + 0.5) * res
    return x


@register_jitable(error_model="numpy")
def _biquad(
    filt: np.ndarray, row: int, x: float, z1: float, z2: float
) -> tuple[float, float, float]:
    """One step of biquad ``filt[row] = [b0, b1, b2, a1, a2]`` (DF2T): ``(out, z1, z2)``."""
    y = filt[row, 0] * x + z1
    return y, filt[row, 1] * x - filt[row, 3] * y + z2, filt[row, 2] * x - filt[row, 4] * y


@register_jitable(error_model="numpy")
def _gains(p: np.ndarray) -> Gains:
    """Controller constants from the packed parameters ``p``, shape ``(_N_P,)``."""
    return Gains(p[_P_KP], p[_P_KV], p[_P_KVKI_TC], p[_P_VLIM], p[_P_TLIM], 1.0 / p[_P_TC])


@register_jitable(error_model="numpy")
def _mechanics(p: np.ndarray, substeps: int) -> Mechanics:
    """Step ``h = T_c / substeps`` and its friction thresholds and viscous divisors."""
    rigid = p[_P_RIGID] != 0.0
    jm = p[_P_JM]
    jl = p[_P_JL]
    h = p[_P_TC] / substeps
    if rigid:
        j_tot = jm + jl
        h_over_jm = h / j_tot
        thr_m = h * (p[_P_FM] + p[_P_FL]) / j_tot
        inv_div_m = 1.0 / (1.0 + h * (p[_P_BM] + p[_P_BL]) / j_tot)
        h_over_jl = 0.0
        thr_l = 0.0
        inv_div_l = 1.0
    else:
        h_over_jm = h / jm
        thr_m = h * p[_P_FM] / jm
        inv_div_m = 1.0 / (1.0 + h * p[_P_BM] / jm)
        h_over_jl = h / jl
        thr_l = h * p[_P_FL] / jl
        inv_div_l = 1.0 / (1.0 + h * p[_P_BL] / jl)
    return Mechanics(
        h, h_over_jm, thr_m, inv_div_m, h_over_jl, thr_l, inv_div_l, p[_P_K], p[_P_C], rigid
    )


@register_jitable(error_model="numpy")
def _drive_step(
    g: Gains, filt: np.ndarray, d: Drive, r: float, y: float
) -> tuple[float, float, Drive]:
    """One controller period: ``(v_cmd [rad/s], tau [N m], new state)``.

    ``r`` is the position command and ``y`` the resolver reading [rad]; ``filt``, shape
    (3, 5), holds the torque low-pass, notch and velocity-filter biquads.
    """
    v_meas, vf1, vf2 = _biquad(filt, 2, (y - d.y_prev) * g.inv_tc, d.vf1, d.vf2)
    v_cmd = _clip(g.kp * (r - y), g.vlim)
    e_v = v_cmd - v_meas
    u = g.kv * e_v + d.integ
    u_lp, lp1, lp2 = _biquad(filt, 0, u, d.lp1, d.lp2)
    u_no, no1, no2 = _biquad(filt, 1, u_lp, d.no1, d.no2)
    # current limit with conditional integration (anti-windup)
    tau = u_no
    pushing = False
    if u_no > g.tlim:
        tau = g.tlim
        pushing = e_v > 0.0
    elif u_no < -g.tlim:
        tau = -g.tlim
        pushing = e_v < 0.0
    integ = d.integ
    if not pushing:
        integ = _clip(integ + g.kvki_tc * e_v, g.tlim)
    return v_cmd, tau, Drive(y, integ, lp1, lp2, no1, no2, vf1, vf2)


@register_jitable(error_model="numpy")
def _mechanics_step(m: Mechanics, s: Shaft, tau: float) -> Shaft:
    """One symplectic Euler step ``m.h`` of the shafts under motor torque ``tau`` [N m]."""
    if m.rigid:
        w = _soft_threshold(s.w_m + m.h_over_jm * tau, m.thr_m) * m.inv_div_m
        th = s.th_m + m.h * w
        return Shaft(th, w, th, w)
    tau_c = m.k_s * (s.th_m - s.th_l) + m.c_s * (s.w_m - s.w_l)
    w_m = _soft_threshold(s.w_m + m.h_over_jm * (tau - tau_c), m.thr_m) * m.inv_div_m
    w_l = _soft_threshold(s.w_l + m.h_over_jl * tau_c, m.thr_l) * m.inv_div_l
    return Shaft(s.th_m + m.h * w_m, w_m, s.th_l + m.h * w_l, w_l)


@register_jitable(error_model="numpy")
def _load_state(state: np.ndarray) -> tuple[Shaft, Drive]:
    """Shafts and controller from the state vector, shape ``(_N_S,)``."""
    shaft = Shaft(state[_S_THM], state[_S_WM], state[_S_THL], state[_S_WL])
    drive = Drive(
        state[_S_YPREV],
        state[_S_INT],
        state[_S_LP1],
        state[_S_LP2],
        state[_S_NO1],
        state[_S_NO2],
        state[_S_VF1],
        state[_S_VF2],
    )
    return shaft, drive


@register_jitable(error_model="numpy")
def _store_state(state: np.ndarray, shaft: Shaft, drive: Drive) -> None:
    """Write shafts and controller back into the state vector, shape ``(_N_S,)``."""
    state[_S_THM], state[_S_WM], state[_S_THL], state[_S_WL] = shaft
    state[_S_YPREV] = drive.y_prev
    state[_S_INT] = drive.integ
    state[_S_LP1] = drive.lp1
    state[_S_LP2] = drive.lp2
    state[_S_NO1] = drive.no1
    state[_S_NO2] = drive.no2
    state[_S_VF1] = drive.vf1
    state[_S_VF2] = drive.vf2


@register_jitable(error_model="numpy")
def _log_sample(out: np.ndarray, i: int, y: float, s: Shaft, v_cmd: float, tau: float) -> None:
    """Row ``i`` of ``out``, shape ``(n, _N_OUT)``: reading, shafts, commands."""
    out[i, _O_Y] = y
    out[i, _O_THL] = s.th_l
    out[i, _O_WL] = s.w_l
    out[i, _O_THM] = s.th_m
    out[i, _O_WM] = s.w_m
    out[i, _O_VCMD] = v_cmd
    out[i, _O_TAU] = tau
