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
The loop is compiled with numba (optional dependency, extra ``sim``) when available:
:math:`10^6` logged samples at 10 ms (:math:`5 \cdot 10^7` controller steps) take a few
seconds. Without numba the same function runs as plain Python (correct but slow).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

__all__ = [
    "MotorRecord",
    "ServoParameters",
    "ServoRecord",
    "numba_available",
    "simulate_motor_open_loop",
    "simulate_servo",
]

#: Types accepted as real scalars (``bool`` is rejected separately).
_REAL = (int, float, np.integer, np.floating)

# --------------------------------------------------------------------------------------
# Parameters
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ServoParameters:
    """Physical and controller parameters of the simulated servo (SI units).

    The defaults describe a small industrial brushless servo (about 400 W, 3 N m peak,
    16-bit resolver) with a load of three times the rotor inertia on a compliant coupling
    (resonance about 260 Hz, anti-resonance about 130 Hz, damping ratio about 0.03), and
    a drive running at 5 kHz tuned for (linearised loop, notch centred on the resonance):

    * velocity loop: crossover about 50 Hz, phase margin about 63 deg, gain margin about
      8 dB, closed-loop bandwidth (-3 dB) about 70 Hz;
    * position loop: crossover about 8.6 Hz, phase margin about 87 deg, closed-loop
      bandwidth (-3 dB) about 9.5 Hz without resonance peak;
    * a 1 rad step is torque-limited for about 25 ms and settles to 2 % in about 0.1 s
      (to 1 mrad in about 0.17 s) with negligible overshoot.

    Parameters
    ----------
    position_gain : float
        Position loop proportional gain ``Kp`` [(rad/s)/rad = 1/s]. Roughly the position
        loop crossover in rad/s.
    velocity_gain : float
        Velocity loop proportional gain ``Kv`` [N m/(rad/s)]. The velocity loop crossover
        is about ``Kv / (J_m + J_l)`` rad/s.
    velocity_integrator : float
        Velocity loop integral gain ``Ki`` [1/s]: the PI is ``Kv (1 + Ki/s)`` and its zero
        sits at ``Ki`` rad/s. ``0`` gives a pure proportional velocity loop.
    velocity_limit : float
        Limit on the velocity command [rad/s] (maximum motor speed).
    torque_constant : float
        Motor torque constant ``Kt`` [N m/A]; only used to express torque as current.
    current_limit : float
        Peak current of the amplifier [A]; the torque limit is ``Kt * current_limit``.
    motor_inertia : float
        Rotor inertia ``J_m`` [kg m^2].
    load_inertia : float
        Load inertia ``J_l`` [kg m^2] (may be 0 only with a rigid coupling).
    coupling_stiffness : float
        Torsional stiffness ``k`` of the motor-load coupling [N m/rad]; ``math.inf`` makes
        the coupling rigid (one inertia ``J_m + J_l``).
    coupling_damping : float
        Torsional damping ``c`` of the coupling [N m/(rad/s)].
    motor_viscous_friction, load_viscous_friction : float
        Viscous friction coefficients ``b_m``, ``b_l`` [N m/(rad/s)].
    motor_coulomb_friction, load_coulomb_friction : float
        Coulomb friction torques ``F_m``, ``F_l`` [N m] (stick/slip, see the module notes).
    torque_lowpass_frequency : float or None
        Cut-off frequency of the torque command low-pass filter [Hz]; ``None`` disables it.
    torque_lowpass_order : int
        1 (first-order) or 2 (second-order) low-pass filter [-].
    torque_lowpass_damping : float
        Damping ratio of the second-order low-pass filter [-] (0.707: Butterworth).
    notch_enabled : bool
        Whether the notch filter is in the torque path.
    notch_frequency : float or None
        Notch centre frequency [Hz]; ``None`` centres it on the mechanical resonance
        (:attr:`resonance_frequency`); with a rigid coupling and ``None`` there is no notch.
    notch_damping : float
        Damping ratio of the notch poles [-]; sets the notch width (the -3 dB width is
        about ``2 * notch_damping * notch_frequency``).
    notch_depth : float
        Gain of the notch at its centre [-], in [0, 1); 0 is a perfect notch.
    velocity_filter_frequency : float or None
        Cut-off frequency of the first-order filter on the velocity estimate [Hz];
        ``None`` uses the raw backward difference.
    resolution : float
        Quantisation step of the resolver reading [rad]; 0 disables quantisation.
        Default: 16 bits per revolution (2 pi / 65536 rad).
    position_noise_std : float
        Standard deviation of the white resolver noise [rad], added before quantisation
        at every controller step (the drive feeds it back).
    command_noise_std : float
        Standard deviation of the noise added to the *logged* position command [rad].
    torque_noise_std : float
        Standard deviation of the noise added to the *logged* torque command [N m].
    disturbance_torque_std : float
        Standard deviation of a white torque disturbance acting on the motor [N m],
        held over each controller period.
    controller_rate : float
        Default rate of the drive's control loop [Hz] (the ``inner_rate`` of
        :func:`simulate_servo`).
    mechanical_substeps : int
        Number of symplectic Euler steps of the mechanics per controller period [-].
    feedback_on_load : bool
        If true the resolver measures the load angle instead of the motor angle.
    """

    position_gain: float = 50.0
    velocity_gain: float = 0.28
    velocity_integrator: float = 60.0
    velocity_limit: float = 600.0
    torque_constant: float = 0.5
    current_limit: float = 6.0
    motor_inertia: float = 2.0e-4
    load_inertia: float = 6.0e-4
    coupling_stiffness: float = 400.0
    coupling_damping: float = 0.015
    motor_viscous_friction: float = 1.0e-4
    load_viscous_friction: float = 2.0e-4
    motor_coulomb_friction: float = 0.01
    load_coulomb_friction: float = 0.02
    torque_lowpass_frequency: float | None = 1000.0
    torque_lowpass_order: int = 2
    torque_lowpass_damping: float = 0.707
    notch_enabled: bool = True
    notch_frequency: float | None = None
    notch_damping: float = 0.3
    notch_depth: float = 0.05
    velocity_filter_frequency: float | None = 1000.0
    resolution: float = 2.0 * math.pi / 65536.0
    position_noise_std: float = 2.0e-5
    command_noise_std: float = 0.0
    torque_noise_std: float = 0.0
    disturbance_torque_std: float = 0.0
    controller_rate: float = 5000.0
    mechanical_substeps: int = 2
    feedback_on_load: bool = False

    def __post_init__(self) -> None:
        positive = (
            "position_gain",
            "velocity_gain",
            "velocity_limit",
            "torque_constant",
            "current_limit",
            "motor_inertia",
            "controller_rate",
            "torque_lowpass_damping",
            "notch_damping",
        )
        nonnegative = (
            "velocity_integrator",
            "load_inertia",
            "coupling_damping",
            "motor_viscous_friction",
            "load_viscous_friction",
            "motor_coulomb_friction",
            "load_coulomb_friction",
            "resolution",
            "position_noise_std",
            "command_noise_std",
            "torque_noise_std",
            "disturbance_torque_std",
        )
        for name in positive + nonnegative:
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, _REAL):
                raise ValueError(
                    f"ServoParameters.{name} must be a real number; got {value!r}. Pass a float."
                )
            if not math.isfinite(value):
                raise ValueError(
                    f"ServoParameters.{name} must be finite; got {value!r}. Pass a finite float."
                )
        for name in positive:
            if getattr(self, name) <= 0:
                raise ValueError(
                    f"ServoParameters.{name} must be > 0; got {getattr(self, name)!r}. "
                    "Pass a positive value."
                )
        for name in nonnegative:
            if getattr(self, name) < 0:
                raise ValueError(
                    f"ServoParameters.{name} must be >= 0; got {getattr(self, name)!r}. "
                    "Pass zero or a positive value."
                )
        k = self.coupling_stiffness
        if isinstance(k, bool) or not isinstance(k, _REAL) or math.isnan(k) or k <= 0:
            raise ValueError(
                f"ServoParameters.coupling_stiffness must be > 0 (math.inf = rigid); got {k!r}. "
                "Pass a positive stiffness in N m/rad or math.inf for a rigid coupling."
            )
        if not self.rigid and self.load_inertia <= 0:
            raise ValueError(
                "ServoParameters.load_inertia must be > 0 with a compliant coupling; got "
                f"{self.load_inertia!r}. Pass a positive load inertia or "
                "coupling_stiffness=math.inf."
            )
        for name in ("torque_lowpass_frequency", "velocity_filter_frequency", "notch_frequency"):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and value > 0):
                raise ValueError(
                    f"ServoParameters.{name} must be None or a finite frequency > 0 [Hz]; "
                    f"got {value!r}. Pass a positive frequency (or None)."
                )
        if self.torque_lowpass_order not in (1, 2) or isinstance(self.torque_lowpass_order, bool):
            raise ValueError(
                "ServoParameters.torque_lowpass_order must be 1 or 2; got "
                f"{self.torque_lowpass_order!r}. Pass 1 or 2."
            )
        if not 0 <= self.notch_depth < 1:
            raise ValueError(
                f"ServoParameters.notch_depth must be in [0, 1); got {self.notch_depth!r}. "
                "Pass the notch's centre gain, e.g. 0.05 (-26 dB)."
            )
        n_sub = self.mechanical_substeps
        if isinstance(n_sub, bool) or not isinstance(n_sub, (int, np.integer)) or n_sub < 1:
            raise ValueError(
                f"ServoParameters.mechanical_substeps must be an integer >= 1; got {n_sub!r}. "
                "Pass e.g. 2."
            )

    def replace(self, **changes: Any) -> ServoParameters:
        """Return a copy with some fields changed (``dataclasses.replace``).

        Parameters
        ----------
        **changes
            Field names and their new values.

        Returns
        -------
        ServoParameters
            The new, validated parameter set.
        """
        return dataclasses.replace(self, **changes)

    @property
    def rigid(self) -> bool:
        """Whether the coupling is rigid (``coupling_stiffness`` is infinite)."""
        return math.isinf(self.coupling_stiffness)

    @property
    def total_inertia(self) -> float:
        """Motor plus load inertia ``J_m + J_l`` [kg m^2]."""
        return self.motor_inertia + self.load_inertia

    @property
    def torque_limit(self) -> float:
        """Peak torque ``Kt * current_limit`` [N m]."""
        return self.torque_constant * self.current_limit

    @property
    def resonance_frequency(self) -> float | None:
        """Undamped two-mass resonance frequency [Hz] (``None`` with a rigid coupling)."""
        if self.rigid:
            return None
        j_m, j_l = self.motor_inertia, self.load_inertia
        return math.sqrt(self.coupling_stiffness * (j_m + j_l) / (j_m * j_l)) / (2 * math.pi)

    @property
    def antiresonance_frequency(self) -> float | None:
        """Undamped anti-resonance frequency ``sqrt(k/J_l)/2pi`` [Hz] (``None`` if rigid)."""
        if self.rigid:
            return None
        return math.sqrt(self.coupling_stiffness / self.load_inertia) / (2 * math.pi)

    @property
    def effective_notch_frequency(self) -> float | None:
        """Notch centre actually used [Hz], or ``None`` when there is no notch."""
        if not self.notch_enabled:
            return None
        if self.notch_frequency is not None:
            return self.notch_frequency
        return self.resonance_frequency


# --------------------------------------------------------------------------------------
# Records
# --------------------------------------------------------------------------------------


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a, dtype=np.float64)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class ServoRecord:
    """Logged signals of a closed-loop servo simulation.

    Every array is 1-D float64 of shape ``(n_samples,)``, sampled at ``time = i *
    sample_time`` and read-only.

    Attributes
    ----------
    time : numpy.ndarray
        Sample instants [s].
    position_command : numpy.ndarray
        Logged position command [rad] (with ``command_noise_std`` noise, if any).
    true_position_command : numpy.ndarray
        Position command applied to the drive [rad] (noise-free; the input).
    position : numpy.ndarray
        Measured position [rad]: the resolver reading used by the drive (noise, then
        quantisation).
    true_position : numpy.ndarray
        Load angle [rad], noise-free.
    velocity : numpy.ndarray
        Load angular velocity [rad/s], noise-free.
    motor_position : numpy.ndarray
        Motor angle [rad], noise-free.
    motor_velocity : numpy.ndarray
        Motor angular velocity [rad/s], noise-free.
    velocity_command : numpy.ndarray
        Output of the position loop [rad/s].
    torque_command : numpy.ndarray
        Logged torque command [N m]: the controller output after the filters and the
        current limit, plus ``torque_noise_std`` logging noise, if any.
    true_torque_command : numpy.ndarray
        Torque command without logging noise [N m] (without the disturbance too).
    sample_time : float
        Logging period [s].
    inner_rate : float
        Controller rate used [Hz].
    params : ServoParameters
        Parameters of the simulation.
    """

    time: np.ndarray
    position_command: np.ndarray
    true_position_command: np.ndarray
    position: np.ndarray
    true_position: np.ndarray
    velocity: np.ndarray
    motor_position: np.ndarray
    motor_velocity: np.ndarray
    velocity_command: np.ndarray
    torque_command: np.ndarray
    true_torque_command: np.ndarray
    sample_time: float
    inner_rate: float
    params: ServoParameters = field(repr=False)

    _ARRAYS = (
        "time",
        "position_command",
        "true_position_command",
        "position",
        "true_position",
        "velocity",
        "motor_position",
        "motor_velocity",
        "velocity_command",
        "torque_command",
        "true_torque_command",
    )

    def __len__(self) -> int:
        return int(self.time.shape[0])

    @property
    def current_command(self) -> np.ndarray:
        """Logged torque command expressed as current [A], shape ``(n_samples,)``."""
        return self.torque_command / self.params.torque_constant

    def to_dict(self) -> dict[str, np.ndarray]:
        """Return the logged signals as a dict of 1-D arrays (e.g. for ``pandas.DataFrame``).

        Returns
        -------
        dict of str to numpy.ndarray
            One entry per signal, each of shape ``(n_samples,)``.
        """
        return {name: getattr(self, name) for name in self._ARRAYS}


@dataclass(frozen=True, eq=False)
class MotorRecord:
    """Logged signals of an open-loop (torque-driven) simulation of the mechanics.

    Every array is 1-D float64 of shape ``(n_samples,)`` and read-only.

    Attributes
    ----------
    time : numpy.ndarray
        Sample instants [s].
    torque : numpy.ndarray
        Torque applied over each sample period, after the current limit [N m].
    position : numpy.ndarray
        Resolver reading (noise, then quantisation) [rad].
    true_position, velocity : numpy.ndarray
        Load angle [rad] and velocity [rad/s].
    motor_position, motor_velocity : numpy.ndarray
        Motor angle [rad] and velocity [rad/s].
    sample_time : float
        Logging period [s].
    inner_rate : float
        Controller (torque update) rate used [Hz].
    params : ServoParameters
        Parameters of the simulation.
    """

    time: np.ndarray
    torque: np.ndarray
    position: np.ndarray
    true_position: np.ndarray
    velocity: np.ndarray
    motor_position: np.ndarray
    motor_velocity: np.ndarray
    sample_time: float
    inner_rate: float
    params: ServoParameters = field(repr=False)

    def __len__(self) -> int:
        return int(self.time.shape[0])


# --------------------------------------------------------------------------------------
# Filter design (Tustin with pre-warping)
# --------------------------------------------------------------------------------------


def _tustin(num: list[float], den: list[float], rate: float, f_warp: float) -> np.ndarray:
    """Bilinear transform of ``num(s)/den(s)`` (descending powers, order <= 2).

    Pre-warped at ``f_warp`` [Hz]. Returns ``[b0, b1, b2, a1, a2]`` of
    ``(b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2)``.
    """
    order = len(den) - 1
    w = 2.0 * math.pi * f_warp
    k = w / math.tan(w / (2.0 * rate))
    pnum = np.zeros(order + 1)
    pden = np.zeros(order + 1)
    minus = np.array([1.0, -1.0])  # 1 - q, ascending powers of q = z^-1
    plus = np.array([1.0, 1.0])
    for i in range(order + 1):
        power = order - i  # power of s of coefficient i
        term = np.array([k**power])
        for _ in range(power):
            term = np.convolve(term, minus)
        for _ in range(order - power):
            term = np.convolve(term, plus)
        pnum += num[i] * term
        pden += den[i] * term
    b = np.zeros(3)
    a = np.zeros(3)
    b[: order + 1] = pnum / pden[0]
    a[: order + 1] = pden / pden[0]
    return np.array([b[0], b[1], b[2], a[1], a[2]])


_IDENTITY = np.array([1.0, 0.0, 0.0, 0.0, 0.0])


def _filter_coefficients(params: ServoParameters, rate: float) -> np.ndarray:
    """Biquad coefficients, shape (3, 5): torque low-pass, notch, velocity filter."""
    nyquist = rate / 2.0
    checks = {
        "torque_lowpass_frequency": params.torque_lowpass_frequency,
        "notch frequency (notch_frequency or the mechanical resonance)": (
            params.effective_notch_frequency
        ),
        "velocity_filter_frequency": params.velocity_filter_frequency,
    }
    for name, f in checks.items():
        if f is not None and f >= nyquist:
            raise ValueError(
                f"The {name} must be below the Nyquist frequency of the controller "
                f"({nyquist:g} Hz at inner_rate={rate:g} Hz); got {f:g} Hz. Raise inner_rate "
                "(or ServoParameters.controller_rate) or lower the frequency."
            )
    out = np.tile(_IDENTITY, (3, 1))
    f_lp = params.torque_lowpass_frequency
    if f_lp is not None:
        w = 2.0 * math.pi * f_lp
        if params.torque_lowpass_order == 1:
            out[0] = _tustin([0.0, w], [1.0, w], rate, f_lp)
        else:
            z = params.torque_lowpass_damping
            out[0] = _tustin([0.0, 0.0, w * w], [1.0, 2.0 * z * w, w * w], rate, f_lp)
    f_n = params.effective_notch_frequency
    if f_n is not None:
        w = 2.0 * math.pi * f_n
        zp = params.notch_damping
        zz = params.notch_depth * zp
        out[1] = _tustin([1.0, 2.0 * zz * w, w * w], [1.0, 2.0 * zp * w, w * w], rate, f_n)
    f_v = params.velocity_filter_frequency
    if f_v is not None:
        w = 2.0 * math.pi * f_v
        out[2] = _tustin([0.0, w], [1.0, w], rate, f_v)
    return out


# --------------------------------------------------------------------------------------
# The loop (one source; compiled by numba when available)
# --------------------------------------------------------------------------------------

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


def _servo_loop(
    command: np.ndarray,
    steps_per_sample: int,
    substeps: int,
    p: np.ndarray,
    filt: np.ndarray,
    state: np.ndarray,
    position_noise: np.ndarray,
    disturbance: np.ndarray,
    out: np.ndarray,
) -> None:
    """Run the drive and the mechanics over ``command`` (one chunk), in place.

    Parameters
    ----------
    command : numpy.ndarray
        Shape (n,): position command [rad] (or torque [N m] in open-loop mode), held over
        each logging period.
    steps_per_sample : int
        Controller steps per logging period.
    substeps : int
        Mechanical integration steps per controller step.
    p : numpy.ndarray
        Shape (_N_P,): packed parameters (see the ``_P_*`` indices).
    filt : numpy.ndarray
        Shape (3, 5): biquads ``[b0, b1, b2, a1, a2]`` of the torque low-pass, the notch and
        the velocity filter.
    state : numpy.ndarray
        Shape (_N_S,): state at the start of the chunk; overwritten with the final state.
    position_noise : numpy.ndarray
        Shape (n * steps_per_sample,) resolver noise [rad], or shape (0,) for none.
    disturbance : numpy.ndarray
        Shape (n * steps_per_sample,) torque disturbance [N m], or shape (0,) for none.
    out : numpy.ndarray
        Shape (n, _N_OUT): filled with the logged signals (see the ``_O_*`` indices).
    """
    n = command.shape[0]
    kp = p[_P_KP]
    kv = p[_P_KV]
    kvki_tc = p[_P_KVKI_TC]
    vlim = p[_P_VLIM]
    tlim = p[_P_TLIM]
    jm = p[_P_JM]
    jl = p[_P_JL]
    k_s = p[_P_K]
    c_s = p[_P_C]
    res = p[_P_RES]
    inv_res = 1.0 / res if res > 0.0 else 0.0
    tc = p[_P_TC]
    inv_tc = 1.0 / tc
    load_fb = p[_P_LOADFB] != 0.0
    rigid = p[_P_RIGID] != 0.0
    open_loop = p[_P_OPEN] != 0.0
    h = tc / substeps
    # implicit friction: thresholds and viscous divisors per mechanical step
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
    lb0, lb1, lb2, la1, la2 = filt[0, 0], filt[0, 1], filt[0, 2], filt[0, 3], filt[0, 4]
    nb0, nb1, nb2, na1, na2 = filt[1, 0], filt[1, 1], filt[1, 2], filt[1, 3], filt[1, 4]
    vb0, vb1, vb2, va1, va2 = filt[2, 0], filt[2, 1], filt[2, 2], filt[2, 3], filt[2, 4]
    has_noise = position_noise.shape[0] > 0
    has_dist = disturbance.shape[0] > 0

    th_m = state[_S_THM]
    w_m = state[_S_WM]
    th_l = state[_S_THL]
    w_l = state[_S_WL]
    y_prev = state[_S_YPREV]
    integ = state[_S_INT]
    lp1 = state[_S_LP1]
    lp2 = state[_S_LP2]
    no1 = state[_S_NO1]
    no2 = state[_S_NO2]
    vf1 = state[_S_VF1]
    vf2 = state[_S_VF2]

    k = 0  # controller step within the chunk
    for i in range(n):
        r = command[i]
        for j in range(steps_per_sample):
            # ---- resolver: noise, then quantisation
            th_fb = th_l if load_fb else th_m
            if has_noise:
                th_fb += position_noise[k]
            if res > 0.0:
                y = math.floor(th_fb * inv_res + 0.5) * res
            else:
                y = th_fb
            # ---- drive
            if open_loop:
                v_cmd = 0.0
                tau = r
                if tau > tlim:
                    tau = tlim
                elif tau < -tlim:
                    tau = -tlim
            else:
                # velocity estimate: backward difference + first-order filter (DF2T)
                v_raw = (y - y_prev) * inv_tc
                y_prev = y
                v_meas = vb0 * v_raw + vf1
                vf1 = vb1 * v_raw - va1 * v_meas + vf2
                vf2 = vb2 * v_raw - va2 * v_meas
                # position loop (P) with velocity limit
                v_cmd = kp * (r - y)
                if v_cmd > vlim:
                    v_cmd = vlim
                elif v_cmd < -vlim:
                    v_cmd = -vlim
                # velocity loop (PI)
                e_v = v_cmd - v_meas
                u = kv * e_v + integ
                # torque low-pass, then notch (DF2T biquads)
                u_lp = lb0 * u + lp1
                lp1 = lb1 * u - la1 * u_lp + lp2
                lp2 = lb2 * u - la2 * u_lp
                u_no = nb0 * u_lp + no1
                no1 = nb1 * u_lp - na1 * u_no + no2
                no2 = nb2 * u_lp - na2 * u_no
                # current limit with conditional integration (anti-windup)
                tau = u_no
                pushing = False
                if u_no > tlim:
                    tau = tlim
                    pushing = e_v > 0.0
                elif u_no < -tlim:
                    tau = -tlim
                    pushing = e_v < 0.0
                if not pushing:
                    integ += kvki_tc * e_v
                    if integ > tlim:
                        integ = tlim
                    elif integ < -tlim:
                        integ = -tlim
            if j == 0:
                out[i, _O_Y] = y
                out[i, _O_THL] = th_l
                out[i, _O_WL] = w_l
                out[i, _O_THM] = th_m
                out[i, _O_WM] = w_m
                out[i, _O_VCMD] = v_cmd
                out[i, _O_TAU] = tau
            tau_app = tau
            if has_dist:
                tau_app += disturbance[k]
            # ---- mechanics: symplectic Euler, implicit viscous + Coulomb friction
            for _s in range(substeps):
                if rigid:
                    x = w_m + h_over_jm * tau_app
                    if x > thr_m:
                        x -= thr_m
                    elif x < -thr_m:
                        x += thr_m
                    else:
                        x = 0.0
                    w_m = x * inv_div_m
                    th_m += h * w_m
                    w_l = w_m
                    th_l = th_m
                else:
                    tau_c = k_s * (th_m - th_l) + c_s * (w_m - w_l)
                    x = w_m + h_over_jm * (tau_app - tau_c)
                    if x > thr_m:
                        x -= thr_m
                    elif x < -thr_m:
                        x += thr_m
                    else:
                        x = 0.0
                    xl = w_l + h_over_jl * tau_c
                    if xl > thr_l:
                        xl -= thr_l
                    elif xl < -thr_l:
                        xl += thr_l
                    else:
                        xl = 0.0
                    w_m = x * inv_div_m
                    w_l = xl * inv_div_l
                    th_m += h * w_m
                    th_l += h * w_l
            k += 1

    state[_S_THM] = th_m
    state[_S_WM] = w_m
    state[_S_THL] = th_l
    state[_S_WL] = w_l
    state[_S_YPREV] = y_prev
    state[_S_INT] = integ
    state[_S_LP1] = lp1
    state[_S_LP2] = lp2
    state[_S_NO1] = no1
    state[_S_NO2] = no2
    state[_S_VF1] = vf1
    state[_S_VF2] = vf2


#: The loop as plain Python (the reference; always available).
_servo_loop_py = _servo_loop

_JIT_CACHE: dict[str, Callable[..., None] | None] = {}


def _compiled_loop() -> Callable[..., None] | None:
    """Return the numba-compiled loop, or ``None`` if numba is not installed."""
    if "loop" not in _JIT_CACHE:
        try:
            import numba
        except ImportError:  # pragma: no cover - depends on the environment
            _JIT_CACHE["loop"] = None
        else:
            _JIT_CACHE["loop"] = numba.njit(cache=True, nogil=True, error_model="numpy")(
                _servo_loop
            )
    return _JIT_CACHE["loop"]


def numba_available() -> bool:
    """Return whether numba can be imported (the fast simulation path).

    Returns
    -------
    bool
        ``True`` if :func:`simulate_servo` runs compiled code by default.
    """
    return _compiled_loop() is not None


def __getattr__(name: str) -> Any:
    # ``_servo_loop_jit`` is compiled lazily so that importing the module stays cheap.
    if name == "_servo_loop_jit":
        loop = _compiled_loop()
        if loop is None:
            raise AttributeError("_servo_loop_jit is unavailable: numba is not installed")
        return loop
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# --------------------------------------------------------------------------------------
# Driver
# --------------------------------------------------------------------------------------

_CHUNK = 16384  # logged samples per call of the loop (bounds the inner-rate noise memory)

Engine = Literal["auto", "numba", "python"]


def _check_signal(values: Any, name: str, unit: str) -> np.ndarray:
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(
            f"{name} must be a 1-D array of numbers [{unit}]; could not convert "
            f"{type(values).__name__}. Pass a list or numpy array of floats."
        ) from None
    if arr.ndim != 1:
        raise ValueError(
            f"{name} must be 1-D (one value per sample) [{unit}]; got shape {arr.shape}. "
            "Pass a flat array (e.g. arr.ravel())."
        )
    if arr.shape[0] == 0:
        raise ValueError(f"{name} must have at least one sample; got an empty array.")
    bad = ~np.isfinite(arr)
    if bad.any():
        first = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"{name} must be finite; got {int(bad.sum())} non-finite value(s), first at "
            f"index {first} ({arr[first]!r}). Remove or interpolate NaN/inf samples."
        )
    return np.ascontiguousarray(arr)


def _check_rates(sample_time: Any, inner_rate: Any, params: ServoParameters) -> tuple[float, int]:
    if isinstance(sample_time, bool) or not isinstance(sample_time, _REAL):
        raise ValueError(
            f"sample_time must be a positive number of seconds; got {sample_time!r}. "
            "Pass e.g. 0.01."
        )
    sample_time = float(sample_time)
    if not (math.isfinite(sample_time) and sample_time > 0):
        raise ValueError(
            f"sample_time must be finite and > 0 [s]; got {sample_time!r}. Pass e.g. 0.01."
        )
    rate = params.controller_rate if inner_rate is None else inner_rate
    if isinstance(rate, bool) or not isinstance(rate, _REAL):
        raise ValueError(f"inner_rate must be a positive number [Hz] or None; got {rate!r}.")
    rate = float(rate)
    if not (math.isfinite(rate) and rate > 0):
        raise ValueError(f"inner_rate must be finite and > 0 [Hz]; got {rate!r}. Pass e.g. 5000.")
    ratio = rate * sample_time
    steps = round(ratio)
    if steps < 1 or abs(ratio - steps) > 1e-9 * max(1.0, ratio):
        raise ValueError(
            "inner_rate must be an integer multiple of 1/sample_time; got inner_rate="
            f"{rate:g} Hz and sample_time={sample_time:g} s (ratio {ratio:g}). Pass e.g. "
            f"inner_rate={max(1, math.ceil(ratio)) / sample_time:g}."
        )
    if rate < 1000.0:
        raise ValueError(
            f"inner_rate must be >= 1000 Hz (the drive's loop rate); got {rate:g} Hz. "
            "Pass a faster rate, e.g. 5000."
        )
    return sample_time, int(steps)


def _streams(seed: Any, n: int) -> list[np.random.Generator]:
    """``n`` independent generators derived from ``seed`` (int, SeedSequence, Generator)."""
    if isinstance(seed, np.random.Generator):
        if hasattr(seed, "spawn"):
            return list(seed.spawn(n))
        seeds = seed.integers(0, 2**63 - 1, size=n)  # pragma: no cover - numpy < 1.25
        return [np.random.default_rng(int(s)) for s in seeds]  # pragma: no cover
    if isinstance(seed, np.random.SeedSequence):
        seq = seed
    else:
        if seed is not None and (
            isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0
        ):
            raise ValueError(
                f"seed must be None, a non-negative int, a SeedSequence or a Generator; got "
                f"{seed!r}. Pass e.g. seed=0."
            )
        seq = np.random.SeedSequence(None if seed is None else int(seed))
    return [np.random.default_rng(child) for child in seq.spawn(n)]


def _pick_loop(engine: str) -> Callable[..., None]:
    if engine == "python":
        return _servo_loop_py
    if engine not in ("auto", "numba"):
        raise ValueError(
            f"engine must be 'auto', 'numba' or 'python'; got {engine!r}. Pass 'auto'."
        )
    loop = _compiled_loop()
    if loop is None:
        if engine == "numba":
            raise ValueError(
                "engine='numba' needs numba, which is not installed. Install the 'sim' extra "
                "(pip install 'clpc[sim]') or pass engine='auto'."
            )
        return _servo_loop_py
    return loop


def _pack(params: ServoParameters, rate: float, open_loop: bool) -> np.ndarray:
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


def _run(
    signal: np.ndarray,
    *,
    open_loop: bool,
    sample_time: float,
    steps: int,
    params: ServoParameters,
    streams: list[np.random.Generator],
    initial_position: float,
    initial_velocity: float,
    engine: str,
) -> np.ndarray:
    """Simulate; return the (n, _N_OUT) output array."""
    loop = _pick_loop(engine)
    rate = steps / sample_time
    p = _pack(params, rate, open_loop)
    filt = _filter_coefficients(params, rate) if not open_loop else np.tile(_IDENTITY, (3, 1))
    n_sub = int(params.mechanical_substeps)
    state = np.zeros(_N_S)
    state[_S_THM] = state[_S_THL] = initial_position
    state[_S_WM] = state[_S_WL] = initial_velocity
    res = params.resolution
    state[_S_YPREV] = (
        math.floor(initial_position * (1.0 / res) + 0.5) * res if res > 0 else initial_position
    )
    n = signal.shape[0]
    out = np.empty((n, _N_OUT))
    empty = np.empty(0)
    rng_noise, rng_dist = streams[0], streams[1]
    for start in range(0, n, _CHUNK):
        stop = min(n, start + _CHUNK)
        m_inner = (stop - start) * steps
        noise = (
            params.position_noise_std * rng_noise.standard_normal(m_inner)
            if params.position_noise_std > 0
            else empty
        )
        dist = (
            params.disturbance_torque_std * rng_dist.standard_normal(m_inner)
            if params.disturbance_torque_std > 0
            else empty
        )
        loop(signal[start:stop], steps, n_sub, p, filt, state, noise, dist, out[start:stop])
    return out


def _check_params(params: Any) -> ServoParameters:
    if params is None:
        return ServoParameters()
    if not isinstance(params, ServoParameters):
        raise ValueError(
            f"params must be a ServoParameters or None; got {type(params).__name__}. "
            "Build one with ServoParameters(...) or ServoParameters().replace(...)."
        )
    return params


def _check_initial(value: Any, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, _REAL):
        raise ValueError(f"{name} must be a finite number; got {value!r}.")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} must be finite; got {value!r}. Pass a finite float.")
    return value


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
        ``"auto"`` uses the numba-compiled loop when numba is installed, else plain
        Python; ``"numba"`` requires numba; ``"python"`` forces the (slow) reference.

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
    >>> from clpc.plants import simulate_servo
    >>> rec = simulate_servo(np.r_[np.zeros(10), np.ones(90)], seed=0)
    >>> bool(abs(rec.true_position[-1] - 1.0) < 1e-3)
    True
    """
    cmd = _check_signal(command, "command", "rad")
    params = _check_params(params)
    sample_time, steps = _check_rates(sample_time, inner_rate, params)
    init = (
        float(cmd[0])
        if initial_position is None
        else _check_initial(initial_position, "initial_position")
    )
    streams = _streams(seed, 4)
    out = _run(
        cmd,
        open_loop=False,
        sample_time=sample_time,
        steps=steps,
        params=params,
        streams=streams,
        initial_position=init,
        initial_velocity=0.0,
        engine=engine,
    )
    n = cmd.shape[0]
    logged_cmd = cmd.copy()
    if params.command_noise_std > 0:
        logged_cmd += params.command_noise_std * streams[2].standard_normal(n)
    tau = out[:, _O_TAU]
    logged_tau = tau.copy()
    if params.torque_noise_std > 0:
        logged_tau += params.torque_noise_std * streams[3].standard_normal(n)
    return ServoRecord(
        time=_readonly(np.arange(n) * sample_time),
        position_command=_readonly(logged_cmd),
        true_position_command=_readonly(cmd),
        position=_readonly(out[:, _O_Y]),
        true_position=_readonly(out[:, _O_THL]),
        velocity=_readonly(out[:, _O_WL]),
        motor_position=_readonly(out[:, _O_THM]),
        motor_velocity=_readonly(out[:, _O_WM]),
        velocity_command=_readonly(out[:, _O_VCMD]),
        torque_command=_readonly(logged_tau),
        true_torque_command=_readonly(tau),
        sample_time=sample_time,
        inner_rate=steps / sample_time,
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
    init = _check_initial(initial_position, "initial_position")
    vel = _check_initial(initial_velocity, "initial_velocity")
    out = _run(
        tq,
        open_loop=True,
        sample_time=sample_time,
        steps=steps,
        params=params,
        streams=_streams(seed, 4),
        initial_position=init,
        initial_velocity=vel,
        engine=engine,
    )
    n = tq.shape[0]
    return MotorRecord(
        time=_readonly(np.arange(n) * sample_time),
        torque=_readonly(out[:, _O_TAU]),
        position=_readonly(out[:, _O_Y]),
        true_position=_readonly(out[:, _O_THL]),
        velocity=_readonly(out[:, _O_WL]),
        motor_position=_readonly(out[:, _O_THM]),
        motor_velocity=_readonly(out[:, _O_WM]),
        sample_time=sample_time,
        inner_rate=steps / sample_time,
        params=params,
    )
