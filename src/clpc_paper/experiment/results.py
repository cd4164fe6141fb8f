"""What one run of the experiment computes: an identification and a command's results."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc import Convergence, LinearModel, Trace

__all__ = ["CommandResult", "Identification", "TorqueCheck"]


@dataclass
class Identification:
    """One CLPC identification and its evaluation data (signals at ``SAMPLE_TIME``).

    Attributes
    ----------
    trace : Trace
        Per-cluster output of the appraiser.
    convergence : Convergence
        Verdict used for the steady-state model.
    level : int
        Index in :data:`~clpc_paper.experiment.settings.TOLERANCES` of the tolerances that
        converged, -1 if none did.
    model : LinearModel
        Steady-state model (mean theta after convergence, else the last accepted one).
    u, y : ndarray, shape (T,)
        Decimated input and output [rad or N m, rad].
    """

    trace: Trace
    convergence: Convergence
    level: int
    model: LinearModel
    u: np.ndarray
    y: np.ndarray


@dataclass
class CommandResult:
    """Everything computed for one command (the figures need the arrays)."""

    name: str
    command_log: np.ndarray
    control: Identification
    actuator: Identification
    position_hat: np.ndarray
    torque_hat: np.ndarray
    summary: dict[str, Any]


@dataclass
class TorqueCheck:
    """The ramp's torque estimate on the servo without Coulomb friction (the cause check).

    ``u`` and ``u_hat`` are the decimated torque command and its estimate [N m];
    ``summary`` the same numbers as ``commands.ramp.actuator`` in ``summary.json``.
    """

    u: np.ndarray
    u_hat: np.ndarray
    summary: dict[str, Any]
