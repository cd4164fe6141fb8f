"""Simulated plants and their excitation signals.

* :mod:`clpc_paper.plants.servo` - the position-controlled brushless servo of the paper's
  Fig. 4 (cascaded P position / PI velocity loops, torque low-pass and notch filters,
  current limit, two-mass mechanics with friction, quantised noisy resolver); its
  parameters are :mod:`clpc_paper.plants.servo_parameters`, its logs
  :mod:`clpc_paper.plants.servo_records`, its compiled inner loop
  :mod:`clpc_paper.plants.servo_loop`;
* :mod:`clpc_paper.plants.commands` - position commands (the paper's Fig. 5 ramp with
  saturation, steps, trapezoidal moves) on the sample grid of :mod:`clpc_paper.plants.grid`;
* :mod:`clpc_paper.plants.excitation` - excitation signals (chirp, PRBS, multisine);
* :mod:`clpc_paper.plants.crank_servo` - a servo lifting a load through a crank: gravity and
  inertia that change with the position (issue 18), with its integrator negative control.
"""

from clpc_paper.plants.commands import ramp_with_saturation, steps, trapezoid_moves
from clpc_paper.plants.crank_servo import (
    CrankParameters,
    CrankRecord,
    crank_commands,
    crank_operating_point,
    simulate_crank_servo,
)
from clpc_paper.plants.excitation import chirp, multisine, prbs
from clpc_paper.plants.grid import time_grid
from clpc_paper.plants.servo import (
    MotorRecord,
    ServoParameters,
    ServoRecord,
    numba_available,
    simulate_motor_open_loop,
    simulate_servo,
)

__all__ = [
    "CrankParameters",
    "CrankRecord",
    "MotorRecord",
    "ServoParameters",
    "ServoRecord",
    "chirp",
    "crank_commands",
    "crank_operating_point",
    "multisine",
    "numba_available",
    "prbs",
    "ramp_with_saturation",
    "simulate_crank_servo",
    "simulate_motor_open_loop",
    "simulate_servo",
    "steps",
    "time_grid",
    "trapezoid_moves",
]
