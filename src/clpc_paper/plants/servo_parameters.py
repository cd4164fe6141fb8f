"""Parameters of the simulated servo (:class:`ServoParameters`) and their validation."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc_paper.checks import REAL
from clpc_paper.checks import check_nonnegative as nonnegative
from clpc_paper.checks import check_positive as positive
from clpc_paper.checks import check_real as real

__all__ = ["ServoParameters"]

#: fields that must be finite and > 0
_POSITIVE = (
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
#: fields that must be finite and >= 0
_NONNEGATIVE = (
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
        _check_reals(self)
        _check_coupling(self)
        _check_filters(self)
        _check_integration(self)

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


def _check_reals(params: ServoParameters) -> None:
    """Every gain, limit, inertia, friction and noise level is finite, then in range."""
    for name in _POSITIVE + _NONNEGATIVE:
        real(getattr(params, name), f"ServoParameters.{name}")
    for name in _POSITIVE:
        positive(getattr(params, name), f"ServoParameters.{name}")
    for name in _NONNEGATIVE:
        nonnegative(getattr(params, name), f"ServoParameters.{name}")


def _check_coupling(params: ServoParameters) -> None:
    """A positive stiffness (``inf``: rigid); a compliant coupling needs a load inertia."""
    k = params.coupling_stiffness
    if isinstance(k, bool) or not isinstance(k, REAL) or math.isnan(k) or k <= 0:
        raise ValueError(
            f"ServoParameters.coupling_stiffness must be > 0 (math.inf = rigid); got {k!r}. "
            "Pass a positive stiffness in N m/rad or math.inf for a rigid coupling."
        )
    if not params.rigid and params.load_inertia <= 0:
        raise ValueError(
            "ServoParameters.load_inertia must be > 0 with a compliant coupling; got "
            f"{params.load_inertia!r}. Pass a positive load inertia or "
            "coupling_stiffness=math.inf."
        )


def _check_filters(params: ServoParameters) -> None:
    """Filter frequencies are ``None`` or > 0; the low-pass order is 1 or 2; notch depth."""
    for name in ("torque_lowpass_frequency", "velocity_filter_frequency", "notch_frequency"):
        value = getattr(params, name)
        if value is not None and not (math.isfinite(value) and value > 0):
            raise ValueError(
                f"ServoParameters.{name} must be None or a finite frequency > 0 [Hz]; "
                f"got {value!r}. Pass a positive frequency (or None)."
            )
    order = params.torque_lowpass_order
    if order not in (1, 2) or isinstance(order, bool):
        raise ValueError(
            f"ServoParameters.torque_lowpass_order must be 1 or 2; got {order!r}. Pass 1 or 2."
        )
    if not 0 <= params.notch_depth < 1:
        raise ValueError(
            f"ServoParameters.notch_depth must be in [0, 1); got {params.notch_depth!r}. "
            "Pass the notch's centre gain, e.g. 0.05 (-26 dB)."
        )


def _check_integration(params: ServoParameters) -> None:
    """At least one mechanical step per controller period."""
    n_sub = params.mechanical_substeps
    if isinstance(n_sub, bool) or not isinstance(n_sub, (int, np.integer)) or n_sub < 1:
        raise ValueError(
            f"ServoParameters.mechanical_substeps must be an integer >= 1; got {n_sub!r}. "
            "Pass e.g. 2."
        )
