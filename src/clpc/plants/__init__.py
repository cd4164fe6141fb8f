"""Simulated plants and their excitation signals.

* :mod:`clpc.plants.servo` - the position-controlled brushless servo of the paper's
  Fig. 4 (cascaded P position / PI velocity loops, torque low-pass and notch filters,
  current limit, two-mass mechanics with friction, quantised noisy resolver);
* :mod:`clpc.plants.commands` - position command generators (the paper's Fig. 5 ramp
  with saturation, steps, trapezoidal moves, chirp, PRBS, multisine).
"""

from clpc.plants.commands import (
    chirp,
    multisine,
    prbs,
    ramp_with_saturation,
    steps,
    time_grid,
    trapezoid_moves,
)
from clpc.plants.servo import (
    MotorRecord,
    ServoParameters,
    ServoRecord,
    numba_available,
    simulate_motor_open_loop,
    simulate_servo,
)

__all__ = [
    "MotorRecord",
    "ServoParameters",
    "ServoRecord",
    "chirp",
    "multisine",
    "numba_available",
    "prbs",
    "ramp_with_saturation",
    "simulate_motor_open_loop",
    "simulate_servo",
    "steps",
    "time_grid",
    "trapezoid_moves",
]
