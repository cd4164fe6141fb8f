r"""A servo lifting a load through a crank: dynamics that change with the position.

The existing servo (:mod:`clpc_paper.plants.servo`) is linear at the paper's amplitudes: its
velocity integrator cancels the only position-dependent load. Here a motor lifts a mass
``m`` on a crank of radius ``r`` (a scotch yoke), so gravity and the reflected inertia
depend on the angle ``th``::

    J(th) w' = tau - m r^2 sin(th) cos(th) w^2 - m g r sin(th) - b w - F sgn(w)
    J(th)    = J0 + m r^2 sin^2(th)

The drive is the servo's cascade without its filters: a P position loop (``Kp``, velocity
command limited to ``velocity_limit``), a velocity loop (``Kv``; by default *no*
integrator, as a joint without gravity compensation), the torque limit, at
``controller_rate``; the velocity is the backward difference of the resolver reading
through a first-order low-pass (``velocity_filter`` Hz); the resolver adds white noise
and a 16-bit quantiser. The mechanics are integrated like the servo's (semi-implicit Euler,
implicit viscous and Coulomb friction: exact stick/slip) ``mechanical_substeps`` times per
controller period. Sample ``i`` is logged at the start of the controller period that
begins at ``t_i``.

Operating points (closed forms, :func:`crank_operating_point`)
---------------------------------------------------------------
At rest without the integrator, ``Kv Kp (r - y) = m g r sin(y)``, so the command that
holds angle ``y`` is ``r = y + (m g r / (Kv Kp)) sin(y)`` (``0.49 sin y`` by default) and
the local (small-signal) DC gain is ``Kv Kp / (Kv Kp + m g r cos y)``: 0.67 at the bottom
(``y = 0``), 1 at horizontal, about 1.96 at the top. The local continuous poles (filter
and friction neglected) are the roots of ``J(y) s^2 + (Kv + b) s + Kv Kp + m g r cos y``:
4.4 +/- 4.3j Hz at the bottom. With the integrator on (``velocity_integrator > 0``, the
negative control) the static gain is 1 at every angle and only the inertia still varies.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from clpc_paper.checks import check_choice
from clpc_paper.plants.crank_commands import crank_commands
from clpc_paper.plants.crank_kernels import N_OUT, N_P, N_STATE, _crank_loop
from clpc_paper.plants.servo_inputs import _check_signal, _streams
from clpc_paper.plants.servo_records import _readonly

__all__ = [
    "CrankParameters",
    "CrankRecord",
    "crank_commands",
    "crank_operating_point",
    "simulate_crank_servo",
]

GRAVITY = 9.81  #: [m/s^2]


@dataclass(frozen=True)
class CrankParameters:
    """Parameters of the crank servo (defaults: the scenario of issue 18).

    Attributes
    ----------
    inertia : float
        Motor and crank inertia ``J0`` [kg m^2].
    mass, radius : float
        Lifted mass [kg] and crank radius [m].
    viscous_friction : float
        ``b`` [N m s/rad].
    coulomb_friction : float
        ``F`` [N m].
    position_gain : float
        ``Kp`` [1/s].
    velocity_limit : float
        Velocity command limit [rad/s].
    velocity_gain : float
        ``Kv`` [N m s/rad].
    velocity_integrator : float
        ``Ki`` [1/s] of the velocity loop ``Kv (1 + Ki/s)``; 0 (default) switches it off.
        The negative control uses 20 /s.
    torque_limit : float
        [N m].
    controller_rate : float
        [Hz]; a multiple of the logging rate.
    mechanical_substeps : int
        Mechanical integration steps per controller period.
    velocity_filter : float
        Cut-off of the first-order velocity low-pass [Hz].
    position_noise_std : float
        Resolver noise [rad].
    resolution : float
        Quantisation step [rad] (16 bits per turn); 0 disables it.
    """

    inertia: float = 2e-3
    mass: float = 2.0
    radius: float = 0.05
    viscous_friction: float = 0.01
    coulomb_friction: float = 0.05
    position_gain: float = 20.0
    velocity_limit: float = 40.0
    velocity_gain: float = 0.1
    velocity_integrator: float = 0.0
    torque_limit: float = 1.5
    controller_rate: float = 1000.0
    mechanical_substeps: int = 5
    velocity_filter: float = 50.0
    position_noise_std: float = 2e-4
    resolution: float = 2.0 * math.pi / 2**16

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "mechanical_substeps":
                if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                    raise ValueError(f"mechanical_substeps must be an int >= 1; got {value!r}.")
                continue
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"{f.name} must be a finite number; got {value!r}.")
            zero_ok = f.name in (
                "viscous_friction",
                "coulomb_friction",
                "velocity_integrator",
                "position_noise_std",
                "resolution",
                "mass",
            )
            if value < 0 or (value == 0 and not zero_ok):
                need = ">= 0" if zero_ok else "> 0"
                raise ValueError(f"{f.name} must be {need}; got {value!r}.")

    @property
    def gravity_torque(self) -> float:
        """``m g r`` [N m]: the largest gravity torque (crank horizontal)."""
        return self.mass * GRAVITY * self.radius

    def packed(self, sample_time: float) -> np.ndarray:
        """The kernel's parameter vector, shape (N_P,)."""
        tc = 1.0 / self.controller_rate
        p = np.empty(N_P)
        p[:] = (
            self.inertia,
            self.mass * self.radius**2,
            self.gravity_torque,
            self.viscous_friction,
            self.coulomb_friction,
            self.position_gain,
            self.velocity_limit,
            self.velocity_gain,
            self.velocity_gain * self.velocity_integrator * tc,
            self.torque_limit,
            tc,
            1.0 - math.exp(-2.0 * math.pi * self.velocity_filter * tc),
            self.resolution,
        )
        return p


@dataclass(frozen=True)
class CrankRecord:
    """Logged signals of :func:`simulate_crank_servo`, each of shape (n_samples,).

    Attributes
    ----------
    command : position command [rad]; position : resolver reading [rad];
    true_position [rad]; velocity [rad/s]; velocity_command [rad/s]; torque [N m];
    sample_time [s]; params : CrankParameters.
    """

    command: np.ndarray
    position: np.ndarray
    true_position: np.ndarray
    velocity: np.ndarray
    velocity_command: np.ndarray
    torque: np.ndarray
    sample_time: float
    params: CrankParameters


def simulate_crank_servo(
    command: Any,
    *,
    sample_time: float = 0.01,
    params: CrankParameters | None = None,
    seed: int | np.random.Generator | np.random.SeedSequence | None = None,
    engine: str = "auto",
) -> CrankRecord:
    """Simulate the crank servo for a position command (see the module notes).

    Parameters
    ----------
    command : array_like
        Shape (n_samples,): position command [rad] at ``sample_time``, zero-order held.
    sample_time : float, optional
        Logging period [s]; ``params.controller_rate * sample_time`` must be an integer.
    params : CrankParameters, optional
        Default ``CrankParameters()`` (no velocity integrator: the nonlinear case).
    seed : int, SeedSequence or Generator, optional
        Seed of the resolver noise.
    engine : {"auto", "compiled", "python"}
        ``"python"`` runs the same loop uncompiled (slow reference).

    Returns
    -------
    CrankRecord
        Starts at rest at ``command[0]``'s equilibrium.

    Raises
    ------
    ValueError
        Non-finite or non-1-D command, bad sample time, parameters or seed.
    """
    cmd = _check_signal(command, "command", "rad")
    prm = CrankParameters() if params is None else params
    if not isinstance(prm, CrankParameters):
        raise ValueError(f"params must be a CrankParameters; got {type(prm).__name__}.")
    if not isinstance(sample_time, (int, float)) or not sample_time > 0:
        raise ValueError(f"sample_time must be a positive number [s]; got {sample_time!r}.")
    ratio = prm.controller_rate * float(sample_time)
    steps = round(ratio)
    if steps < 1 or abs(ratio - steps) > 1e-9 * max(ratio, 1.0):
        raise ValueError(
            f"controller_rate * sample_time must be a positive integer; got "
            f"{prm.controller_rate:g} Hz * {sample_time:g} s = {ratio:g}."
        )
    (rng,) = _streams(seed, 1)
    noise = prm.position_noise_std * rng.standard_normal(cmd.shape[0] * steps)
    y0 = crank_operating_point(cmd[0], prm)[0] if prm.velocity_integrator == 0 else cmd[0]
    state = np.zeros(N_STATE)
    state[0] = y0
    state[2] = y0  # last reading: at rest
    state[4] = 0.0 if prm.velocity_integrator == 0 else prm.gravity_torque * math.sin(y0)
    out = np.empty((cmd.shape[0], N_OUT))
    python = check_choice(engine, "engine", ("auto", "compiled", "python")) == "python"
    loop = getattr(_crank_loop, "py_func", _crank_loop) if python else _crank_loop
    loop(prm.packed(float(sample_time)), steps, prm.mechanical_substeps, cmd, noise, state, out)
    return CrankRecord(
        command=_readonly(cmd),
        position=_readonly(out[:, 0]),
        true_position=_readonly(out[:, 1]),
        velocity=_readonly(out[:, 2]),
        velocity_command=_readonly(out[:, 3]),
        torque=_readonly(out[:, 4]),
        sample_time=float(sample_time),
        params=prm,
    )


def crank_operating_point(command: Any, params: CrankParameters | None = None) -> tuple:
    """Rest angle, local DC gain and local continuous poles for a held command.

    Without the velocity integrator the rest angle ``y`` solves
    ``r = y + (m g r / (Kv Kp)) sin y`` (Newton's method from ``y = r``); with it, ``y = r``.

    Parameters
    ----------
    command : float or array_like
        Held position command(s) [rad].
    params : CrankParameters, optional

    Returns
    -------
    angle : ndarray
        Rest angle(s) [rad], shape of ``command``.
    dc_gain : ndarray
        Small-signal gain ``dy/dr`` there (1 with the integrator).
    poles_hz : ndarray of complex, shape (..., 2)
        Roots of ``J(y) s^2 + (Kv + b) s + Kv Kp + m g r cos y`` divided by ``2 pi`` [Hz]
        (P-P loop; filter, friction and limits neglected). NaN with the velocity
        integrator, whose extra pole and zero this formula does not model.
    """
    prm = CrankParameters() if params is None else params
    r = np.asarray(command, dtype=np.float64)
    kk = prm.velocity_gain * prm.position_gain
    a = prm.gravity_torque / kk
    y = r.copy()
    if prm.velocity_integrator == 0:
        for _ in range(50):  # Newton on a scalar field (converges in a few steps: a < 1)
            y = y - (y + a * np.sin(y) - r) / (1.0 + a * np.cos(y))
        gain = kk / (kk + prm.gravity_torque * np.cos(y))
    else:
        gain = np.ones_like(y)
    j = prm.inertia + prm.mass * prm.radius**2 * np.sin(y) ** 2
    stiff = kk + prm.gravity_torque * np.cos(y)
    damp = prm.velocity_gain + prm.viscous_friction
    disc = np.sqrt((damp**2 - 4.0 * j * stiff).astype(complex))
    poles = np.stack([(-damp + disc) / (2 * j), (-damp - disc) / (2 * j)], axis=-1)
    if prm.velocity_integrator != 0:  # the P-P formula does not hold: not modelled
        poles = np.full_like(poles, complex(np.nan, np.nan))
    return y, gain, poles / (2.0 * math.pi)
