r"""Simulated brushless servo drive in position control mode (paper, section VI, Fig. 4).

The drive is the cascade of Fig. 4 of the paper: a proportional position loop
(*position gain*) gives the velocity command, a proportional-integral velocity loop
(*velocity gain*, *velocity integrator*) gives the torque (current) command, which goes
through a low-pass filter and a notch filter ("to reduce mechanical vibrations") and the
current limit of the amplifier before it drives the motor. The motor turns a load through
a compliant coupling (the mechanical resonance the notch filter is there for); the
resolver measures the motor shaft angle.

Block diagram
-------------
::

             .----.  .------.                 .------------.  .-----.  .-------.  .------. tau
    r ->(+)->| Kp |->| vlim |-v_cmd->(+)-e_v->| Kv(1+Ki/s) |->| LPF |->| notch |->| Tlim |--.
         ^-  '----'  '------'         ^-      '------------'  '-----'  '-------'  '------'
         |                            | v_meas    (anti-windup: the integrator is           |
         |                            |            frozen while the limit is active      d->+
         |        .-------.  .------. |            and e_v pushes further into it)          |
         |        | LPF_v |<-| d/dt |<+                                                     |
         |        '-------'  '------' |                                                     |
         |                            |     .-----------.                     .-------------v-.
         '----------------------------+--y--| quantiser |<-(+)<---------------| J_m ~k,c~ J_l |
            measured position               '-----------'   ^                 '---------------'
                                                            n (noise)         motor -- load,
                                                                              friction b, F

``vlim`` and ``Tlim`` clip to ``±velocity_limit`` and ``±torque_limit``, ``d`` is the torque
disturbance, ``n`` the resolver noise, ``y`` the measured position (the logged
``position``).

Continuous-time model
---------------------
Two-mass mechanics (motor angle :math:`\theta_m`, load angle :math:`\theta_l`)::

    J_m dω_m/dt = τ + d − τ_c − b_m ω_m − F_m sgn(ω_m)
    J_l dω_l/dt =         τ_c − b_l ω_l − F_l sgn(ω_l)
    τ_c         = k (θ_m − θ_l) + c (ω_m − ω_l)        (coupling torque)

with the mechanical resonance at :math:`f_r = \sqrt{k (J_m + J_l) / (J_m J_l)} / 2\pi` and
the anti-resonance at :math:`f_a = \sqrt{k / J_l} / 2\pi`. With
``coupling_stiffness=math.inf`` the coupling is rigid: one inertia :math:`J_m + J_l` with
the summed friction. ``sgn`` is the set-valued sign (any value in [-1, 1] at zero
velocity): Coulomb friction sticks the shaft when the other torques are smaller than
:math:`F`.

Drive (all executed once per controller period :math:`T_c` = ``1 / inner_rate``)::

    y     = Q(θ_fb + n)                    resolver: noise n, then quantiser Q (step q)
    v_meas= LPF_v[(y − y_prev) / T_c]      velocity estimate (backward difference)
    v_cmd = sat_vmax(Kp (r − y))           position loop (P)
    e_v   = v_cmd − v_meas
    u     = Kv e_v + I                     velocity loop (PI), I = integrator [N m]
    τ     = sat_Tmax(notch(LPF(u)))        torque (current) command
    I    += Kv Ki T_c e_v                  unless |notch(LPF(u))| > Tmax and e_v pushes
                                           further into the limit (conditional
                                           integration); I is also clamped to ±Tmax

``θ_fb`` is the motor angle (resolver on the motor shaft, the default) or the load angle
(``feedback_on_load=True``).

Discretisation
--------------
* The controller runs at ``inner_rate`` (default ``params.controller_rate`` = 5 kHz); its
  torque is held constant (zero-order hold) over the controller period.
* The low-pass, notch and velocity filters are the bilinear (Tustin) transforms of their
  continuous prototypes, pre-warped at their characteristic frequency (the cut-off
  frequency, the notch centre), implemented as biquads in transposed direct form II.
* The mechanics are integrated with ``mechanical_substeps`` steps of the semi-implicit
  (symplectic) Euler method per controller period (default 2, i.e. 10 kHz): velocities
  first, then angles from the new velocities. Symplectic Euler keeps the undamped
  resonance's energy bounded (no numerical damping or growth) for ``2πf_r h < 2``.
  Viscous friction and Coulomb friction are treated implicitly: with the other torques
  :math:`f` frozen over the step :math:`h`, the backward-Euler solution of
  :math:`J (ω^+ − ω)/h = f − b ω^+ − F\,\mathrm{sgn}(ω^+)` is
  :math:`ω^+ = S(ω + h f / J,\; h F / J) / (1 + h b / J)` with the soft threshold
  :math:`S(x, t) = \mathrm{sign}(x) \max(|x| − t, 0)`. This is an exact stick/slip
  model for the set-valued Coulomb law: the shaft stops exactly and stays at rest while
  :math:`|f| \le F`, with no regularisation constant, no chattering and no stiffness
  limit on the step. Static friction above the Coulomb level (Stribeck effect) is not
  modelled.
* Logging: sample ``i`` is taken at :math:`t_i = i\,T_s` (``sample_time``), at the start of
  the controller period that begins at that instant: the command held over
  :math:`[t_i, t_{i+1})`, the resolver reading the drive uses at :math:`t_i`, the true
  states at :math:`t_i` and the torque command computed at :math:`t_i`.

Noise
-----
Every random sequence comes from ``numpy.random.default_rng`` seeded from ``seed``, with
one independent stream per source (resolver noise, torque disturbance, logged-command
noise, logged-torque noise), generated vectorised outside the loop (the inner-rate
sources in chunks). Switching one source on or off does not change the others.
``position_noise_std`` acts inside the loop (the drive sees it); ``command_noise_std``
and ``torque_noise_std`` only corrupt the logged signals (errors in variables);
``disturbance_torque_std`` is a white torque disturbance held over each controller period.

Speed
-----
The loop is compiled with numba (a dependency of clpc): :math:`10^6` logged samples at 10 ms
(:math:`5 \cdot 10^7` controller steps) take a few seconds. ``engine="python"`` runs the same
function as plain Python (correct but slow).
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from clpc_paper.checks import check_real as real
from clpc_paper.plants.servo_inputs import _check_params, _check_rates, _check_signal, _streams
from clpc_paper.plants.servo_layout import _O_TAU, _O_VCMD
from clpc_paper.plants.servo_loop import numba_available
from clpc_paper.plants.servo_parameters import ServoParameters
from clpc_paper.plants.servo_records import MotorRecord, ServoRecord, _readonly, _shaft_log
from clpc_paper.plants.servo_run import RunSetup, _run

__all__ = [
    "MotorRecord",
    "ServoParameters",
    "ServoRecord",
    "numba_available",
    "simulate_motor_open_loop",
    "simulate_servo",
]

Engine = Literal["auto", "numba", "python"]


def simulate_servo(
    command: Any,
    *,
    sample_time: float = 0.01,
    params: ServoParameters | None = None,
    seed: int | np.random.Generator | np.random.SeedSequence | None = None,
    inner_rate: float | None = None,
    initial_position: float | None = None,
    engine: Engine = "auto",
) -> ServoRecord:
    """Simulate the position-controlled servo of Fig. 4 for a position command.

    Parameters
    ----------
    command : array_like
        Shape ``(n_samples,)``: position command [rad] at ``sample_time``, held constant
        (zero-order hold) between samples. Must be finite.
    sample_time : float, optional
        Logging (and command) period [s]; default 0.01 s (Table 1 of the paper).
    params : ServoParameters, optional
        Servo parameters; default ``ServoParameters()``.
    seed : int, numpy.random.SeedSequence or numpy.random.Generator, optional
        Seed of the noise sources (see the module notes). ``None`` draws fresh entropy.
        The result is deterministic for a given integer seed.
    inner_rate : float, optional
        Controller rate [Hz]; an integer multiple of ``1 / sample_time`` and at least
        1 kHz. Default ``params.controller_rate`` (5 kHz). The mechanics are integrated at
        ``inner_rate * params.mechanical_substeps``.
    initial_position : float, optional
        Initial motor and load angle [rad], at rest; default ``command[0]``.
    engine : {"auto", "numba", "python"}, optional
        ``"auto"`` and ``"numba"`` use the numba-compiled loop; ``"python"`` forces the
        (slow) plain-Python reference.

    Returns
    -------
    ServoRecord
        Logged signals, each of shape ``(n_samples,)``.

    Raises
    ------
    ValueError
        If the command is not a finite 1-D array, the sample time is not positive, the
        inner rate is not an integer multiple of ``1 / sample_time`` (or below 1 kHz), a
        filter frequency is above the controller's Nyquist frequency, or an argument has
        the wrong type.

    Examples
    --------
    >>> import numpy as np
    >>> from clpc_paper.plants import simulate_servo
    >>> rec = simulate_servo(np.r_[np.zeros(10), np.ones(90)], seed=0)
    >>> bool(abs(rec.true_position[-1] - 1.0) < 1e-3)
    True
    """
    cmd = _check_signal(command, "command", "rad")
    params = _check_params(params)
    sample_time, steps = _check_rates(sample_time, inner_rate, params)
    init = float(cmd[0]) if initial_position is None else real(initial_position, "initial_position")
    streams = _streams(seed, 4)
    setup = RunSetup(
        params, sample_time, steps, open_loop=False, engine=engine, initial_position=init
    )
    out = _run(cmd, setup, streams)
    tau = out[:, _O_TAU]
    return ServoRecord(
        **_shaft_log(out, sample_time),
        position_command=_readonly(_logged(cmd, params.command_noise_std, streams[2])),
        true_position_command=_readonly(cmd),
        velocity_command=_readonly(out[:, _O_VCMD]),
        torque_command=_readonly(_logged(tau, params.torque_noise_std, streams[3])),
        true_torque_command=_readonly(tau),
        sample_time=sample_time,
        inner_rate=setup.rate,
        params=params,
    )


def simulate_motor_open_loop(
    torque: Any,
    *,
    sample_time: float = 0.01,
    params: ServoParameters | None = None,
    seed: int | np.random.Generator | np.random.SeedSequence | None = None,
    inner_rate: float | None = None,
    initial_position: float = 0.0,
    initial_velocity: float = 0.0,
    engine: Engine = "auto",
) -> MotorRecord:
    """Drive the mechanics with a torque, without the controller (a physics check).

    The torque bypasses the position/velocity loops and the filters; it is only limited
    to ``±params.torque_limit`` and gets the optional disturbance. The same code integrates
    the mechanics as in :func:`simulate_servo`.

    Parameters
    ----------
    torque : array_like
        Shape ``(n_samples,)``: motor torque [N m] at ``sample_time``, zero-order held.
    sample_time : float, optional
        Logging period [s]; default 0.01 s.
    params : ServoParameters, optional
        Parameters (inertias, coupling, friction, resolver); default ``ServoParameters()``.
    seed : int, numpy.random.SeedSequence or numpy.random.Generator, optional
        Seed of the resolver noise and the disturbance.
    inner_rate : float, optional
        Torque update rate [Hz], an integer multiple of ``1 / sample_time``; default
        ``params.controller_rate``.
    initial_position : float, optional
        Initial motor and load angle [rad]; default 0.
    initial_velocity : float, optional
        Initial motor and load velocity [rad/s]; default 0.
    engine : {"auto", "numba", "python"}, optional
        As in :func:`simulate_servo`.

    Returns
    -------
    MotorRecord
        Logged signals, each of shape ``(n_samples,)``.

    Raises
    ------
    ValueError
        As :func:`simulate_servo`.
    """
    tq = _check_signal(torque, "torque", "N m")
    params = _check_params(params)
    sample_time, steps = _check_rates(sample_time, inner_rate, params)
    init = real(initial_position, "initial_position")
    vel = real(initial_velocity, "initial_velocity")
    setup = RunSetup(
        params,
        sample_time,
        steps,
        open_loop=True,
        engine=engine,
        initial_position=init,
        initial_velocity=vel,
    )
    out = _run(tq, setup, _streams(seed, 4))
    return MotorRecord(
        **_shaft_log(out, sample_time),
        torque=_readonly(out[:, _O_TAU]),
        sample_time=sample_time,
        inner_rate=setup.rate,
        params=params,
    )


def _logged(signal: np.ndarray, std: float, rng: np.random.Generator) -> np.ndarray:
    """``signal`` plus logging noise of standard deviation ``std`` (drawn only if > 0)."""
    logged = signal.copy()
    if std > 0:
        logged += std * rng.standard_normal(signal.shape[0])
    return logged
