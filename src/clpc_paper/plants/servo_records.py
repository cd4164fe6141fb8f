"""Logged signals of the servo simulations (:class:`ServoRecord`, :class:`MotorRecord`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TypedDict

import numpy as np

from clpc_paper.plants.servo_layout import _O_THL, _O_THM, _O_WL, _O_WM, _O_Y
from clpc_paper.plants.servo_parameters import ServoParameters

__all__ = ["MotorRecord", "ServoRecord"]


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a, dtype=np.float64)
    a.setflags(write=False)
    return a


class _ShaftLog(TypedDict):
    """The signals both records hold, each read-only of shape ``(n_samples,)``."""

    time: np.ndarray
    position: np.ndarray
    true_position: np.ndarray
    velocity: np.ndarray
    motor_position: np.ndarray
    motor_velocity: np.ndarray


def _shaft_log(out: np.ndarray, sample_time: float) -> _ShaftLog:
    """Sample instants [s], resolver reading and shafts from the loop's ``out`` (n, _N_OUT)."""
    return _ShaftLog(
        time=_readonly(np.arange(out.shape[0]) * sample_time),
        position=_readonly(out[:, _O_Y]),
        true_position=_readonly(out[:, _O_THL]),
        velocity=_readonly(out[:, _O_WL]),
        motor_position=_readonly(out[:, _O_THM]),
        motor_velocity=_readonly(out[:, _O_WM]),
    )


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
        current limit, averaged over the logging period that starts at ``time`` (what
        the motor integrates; one controller sample would alias the loop's noise), plus
        ``torque_noise_std`` logging noise, if any.
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
