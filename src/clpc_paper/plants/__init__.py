"""Simulated plants and their excitation signals (``docs/architecture.md`` lists the modules).

The brushless servo of the paper's Fig. 4, a crank servo (issue 18), position commands.
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
