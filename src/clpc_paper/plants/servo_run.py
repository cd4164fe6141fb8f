"""Run the servo loop over a whole record: set-up, noise streams, chunks.

The record is cut into chunks of :data:`_CHUNK` logged samples; the inner-rate noise of a
chunk is drawn just before it runs (bounded memory) and the state is carried from chunk to
chunk, so the result does not depend on the chunk size.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from clpc_paper.plants.servo_filters import _IDENTITY, _filter_coefficients
from clpc_paper.plants.servo_layout import _N_OUT, LoopConfig, LoopInputs, _initial_state, _pack
from clpc_paper.plants.servo_loop import _pick_loop
from clpc_paper.plants.servo_parameters import ServoParameters

__all__ = ["RunSetup"]

_CHUNK = 16384  # logged samples per call of the loop (bounds the inner-rate noise memory)


@dataclass(frozen=True)
class RunSetup:
    """Checked settings of one simulation.

    Attributes
    ----------
    params : ServoParameters
        Servo parameters.
    sample_time : float
        Logging period [s].
    steps : int
        Controller steps per logging period [-].
    open_loop : bool
        Whether the signal is a torque driving the bare mechanics (no controller).
    engine : str
        ``"auto"``, ``"numba"`` or ``"python"``.
    initial_position : float
        Initial motor and load angle [rad].
    initial_velocity : float
        Initial motor and load velocity [rad/s].
    """

    params: ServoParameters
    sample_time: float
    steps: int
    open_loop: bool
    engine: str
    initial_position: float
    initial_velocity: float = 0.0

    @property
    def rate(self) -> float:
        """Controller rate ``steps / sample_time`` [Hz]."""
        return self.steps / self.sample_time


def _run(signal: np.ndarray, setup: RunSetup, streams: list[np.random.Generator]) -> np.ndarray:
    """Simulate ``signal``, shape ``(n,)``; return the logged outputs, shape ``(n, _N_OUT)``.

    ``streams[0]`` draws the resolver noise, ``streams[1]`` the torque disturbance.
    """
    loop = _pick_loop(setup.engine)
    params = setup.params
    rate = setup.rate
    filt = _filter_coefficients(params, rate) if not setup.open_loop else np.tile(_IDENTITY, (3, 1))
    config = LoopConfig(
        setup.steps, int(params.mechanical_substeps), _pack(params, rate, setup.open_loop), filt
    )
    state = _initial_state(setup.initial_position, setup.initial_velocity, params.resolution)
    n = signal.shape[0]
    out = np.empty((n, _N_OUT))
    for start in range(0, n, _CHUNK):
        stop = min(n, start + _CHUNK)
        noise, dist = _inner_noise(params, streams, (stop - start) * setup.steps)
        loop(config, LoopInputs(signal[start:stop], noise, dist), state, out[start:stop])
    return out


def _inner_noise(
    params: ServoParameters, streams: list[np.random.Generator], m: int
) -> tuple[np.ndarray, np.ndarray]:
    """Resolver noise [rad] and torque disturbance [N m] of ``m`` controller steps.

    Each has shape ``(m,)``, or ``(0,)`` when its standard deviation is 0.
    """
    empty = np.empty(0)
    noise = (
        params.position_noise_std * streams[0].standard_normal(m)
        if params.position_noise_std > 0
        else empty
    )
    dist = (
        params.disturbance_torque_std * streams[1].standard_normal(m)
        if params.disturbance_torque_std > 0
        else empty
    )
    return noise, dist
