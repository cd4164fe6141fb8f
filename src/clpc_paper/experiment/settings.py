"""Settings of the section VI experiment: Table 1, the two commands, the claim thresholds.

Everything the other modules of :mod:`clpc_paper.experiment` share as a constant lives here, and
:func:`settings_record` is the ``settings`` block of ``summary.json``.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

from clpc_paper.checks import check_positive

__all__ = [
    "A0_MIN",
    "CLUSTER_SIZE",
    "D_QUASI_CONSTANT",
    "EXTENDED_RAMP_DURATION",
    "LABELS",
    "LOG_SAMPLE_TIME",
    "PARAMETERS_SIZE",
    "RAMP",
    "RAMP_DURATION",
    "RICH_DITHER",
    "RICH_DURATION",
    "RICH_DURATION_QUICK",
    "RICH_MOVES",
    "SAMPLE_TIME",
    "TOLERANCES",
    "WINDOW_SIZE",
    "Dither",
    "Moves",
    "Ramp",
    "durations",
    "settings_record",
]


@dataclass(frozen=True)
class Ramp:
    """The paper's ramp with saturation (Fig. 5): 0 -> ``level`` rad from ``start`` [s]."""

    start: float
    ramp_time: float
    level: float

    @property
    def corner(self) -> float:
        """Time of the saturation corner [s]."""
        return self.start + self.ramp_time


@dataclass(frozen=True)
class Moves:
    """Ramp-and-hold moves (:func:`clpc_paper.plants.trapezoid_moves`) [rad, rad/s, rad/s^2, s]."""

    positions: tuple[float, float]
    max_velocity: float
    max_acceleration: float
    dwell: float
    start: float


@dataclass(frozen=True)
class Dither:
    """PRBS dither (:func:`clpc_paper.plants.prbs`) [rad, s]."""

    amplitude: float
    min_hold: float


# ---------------------------------------------------------------- Table 1
SAMPLE_TIME = 0.01  #: appraiser sample time [s]
PARAMETERS_SIZE = 3  #: size of a and b (N = 2)
WINDOW_SIZE = 201  #: lag vectors per window (2 s)
CLUSTER_SIZE = 12  #: lag vectors between updates
LOG_SAMPLE_TIME = 0.001  #: servo logging period [s] (decimated by the appraiser)
#: convergence tolerances tried in order: (theta_tol, D_tol, consecutive)
TOLERANCES = ((0.02, 0.1, 5), (0.05, 0.2, 5))

# ---------------------------------------------------------------- the commands
RAMP = Ramp(start=0.5, ramp_time=0.9, level=1.0)  #: Fig. 5 ramp [s, s, rad]
RAMP_DURATION = RAMP.start + RAMP.ramp_time + 2.0  #: ramp leaves the window [s]
EXTENDED_RAMP_DURATION = 6.0  #: the ramp record continued past RAMP_DURATION [s]
RICH_DURATION, RICH_DURATION_QUICK = 20.0, 8.0  #: rich command record lengths [s]
#: 2 s period of ramp-and-hold moves
RICH_MOVES = Moves(
    positions=(0.0, 1.0), max_velocity=2.0, max_acceleration=20.0, dwell=0.4, start=0.5
)
RICH_DITHER = Dither(amplitude=0.03, min_hold=0.05)  #: PRBS dither [rad, s]

# ---------------------------------------------------------------- thresholds and labels
D_QUASI_CONSTANT = 0.1  #: D is quasi-constant when its coefficient of variation is below
A0_MIN = 0.05  #: an accepted theta with a0 below this does not determine y(n)
#: The paper's appraiser accepts every computable estimate: the experiment reproduces it with
#: the guard off (``CLPC(guard=False)``); the default LPC solve (raw units) is used as is.
GUARD = False
LABELS = ("a01", "a11", "a21", "b01", "b11", "b21")  #: the paper's names (eq. 39)


def durations(duration: float | None, quick: bool) -> tuple[float, float]:
    """Lengths of the ramp and rich records [s]: the defaults, or ``duration`` for both."""
    if duration is None:
        return RAMP_DURATION, RICH_DURATION_QUICK if quick else RICH_DURATION
    value = check_positive(duration, "duration", "s")
    if value < 3.0:
        raise ValueError(
            f"duration must be at least 3 s (the ramp saturates at 1.4 s and the 2 s window "
            f"must fill); got {duration!r}. Pass e.g. duration=None for the defaults."
        )
    return value, value


def settings_record(
    ramp_duration: float, rich_duration: float, quick: bool, seed: int, method: str
) -> dict[str, Any]:
    """The ``settings`` block of ``summary.json``."""
    return {
        "sample_time": SAMPLE_TIME,
        "parameters_size": PARAMETERS_SIZE,
        "window_size": WINDOW_SIZE,
        "window_time": (WINDOW_SIZE - 1) * SAMPLE_TIME,
        "cluster_size": CLUSTER_SIZE,
        "log_sample_time": LOG_SAMPLE_TIME,
        "method": method,
        "guard": GUARD,
        "scaling": "none",
        "tolerances": [list(t) for t in TOLERANCES],
        "ramp": {"duration": ramp_duration, **asdict(RAMP)},
        "rich": {"duration": rich_duration, **asdict(RICH_MOVES), "dither": asdict(RICH_DITHER)},
        "quick": quick,
        "seed": seed,
    }
