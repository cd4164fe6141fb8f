"""The paper's claims of section VI, each with the numeric criterion that decides it.

:func:`claims` turns the experiment's summary into a verdict per paper claim and per command
(``"reproduced"``, ``"partly"``, ``"not reproduced"``) with the numbers behind it, the
criterion, why that threshold and, when not reproduced, why
(:mod:`clpc_paper.experiment.claim_checks`). It reads only the JSON-safe summary, so a saved
``summary.json`` can be judged again.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from clpc_paper.experiment.actuator_checks import check_actuator, check_torque
from clpc_paper.experiment.claim_checks import (
    NOT_REPRODUCED,
    PARTLY,
    REPRODUCED,
    check_clusters,
    check_corner,
    check_d,
    check_parameters,
    check_position,
    check_stable,
    fmt,
    fmt_poles,
)

__all__ = [
    "CLAIMS",
    "NOT_REPRODUCED",
    "PARTLY",
    "REPRODUCED",
    "Claim",
    "claim_row",
    "claims",
    "fmt",
    "fmt_poles",
    "verdict_of",
]

Check = Callable[[dict[str, Any], dict[str, Any], str], dict[str, Any]]
"""(one command's summary, the whole summary, command name) -> the verdict dict

``{"verdict", "numbers" (what was measured), "criterion" (the threshold), "why" (why that
threshold), "reason" (why not reproduced, from the measurements; absent when reproduced)}``
"""


@dataclass(frozen=True)
class Claim:
    """One claim of the paper: its id, the figures that show it, its words and its test."""

    id: str
    figures: tuple[int, ...]
    paper: str
    check: Check
    commands: tuple[str, ...] | None = None  #: the commands it applies to (None: all)


CLAIMS = (
    Claim(
        "D",
        (6,),
        "D increases for each cluster and after a few clusters it is quasi constant",
        lambda c, s, n: check_d(c["control_system"]),
    ),
    Claim(
        "parameters",
        (7, 8, 9, 10, 11, 12),
        "the parameters (39) are quasi constant after a few clusters",
        lambda c, s, n: check_parameters(c["control_system"], s["settings"]),
    ),
    Claim(
        "stable_model",
        (15, 16, 17),
        "the steady-state model of the control system is stable (position follows command)",
        lambda c, s, n: check_stable(c["control_system"]),
    ),
    Claim(
        "actuator_poles",
        (13, 14),
        "the motor as actuator (torque -> position) is identified: integrating poles near z = 1",
        lambda c, s, n: check_actuator(c["actuator"], s["rigid_body"]),
    ),
    Claim(
        "torque_estimate",
        (13, 14),
        "the estimated torque command tracks the experimental one and its error converges",
        lambda c, s, n: check_torque(
            c["actuator"], s.get("torque_without_friction") if n == "ramp" else None
        ),
    ),
    Claim(
        "position_error_converges",
        (15, 16, 17),
        "the stability of the model ensures the convergence of the identification errors",
        lambda c, s, n: check_position(c["control_system"]),
    ),
    Claim(
        "corner_error",
        (17,),
        "a large identification error at t = 1.4 s (the ramp's corner)",
        lambda c, s, n: check_corner(c["control_system"]),
        commands=("ramp",),
    ),
    Claim(
        "clusters",
        (),
        "clusters: local (windowed) LPC identifies better than one global fit",
        lambda c, s, n: check_clusters(c),
    ),
)


def claims(summary: dict[str, Any]) -> list[dict[str, Any]]:
    """Verdict and numbers for every paper claim, per command (``ramp`` and ``rich``)."""
    out = []
    for claim in CLAIMS:
        row: dict[str, Any] = {"id": claim.id, "figures": list(claim.figures), "paper": claim.paper}
        for name, cmd in summary["commands"].items():
            if claim.commands is None or name in claim.commands:
                row[name] = claim.check(cmd, summary, name)
        out.append(row)
    return out


def claim_row(summary: dict[str, Any], key: str) -> dict[str, Any]:
    """The row of ``summary["claims"]`` with id ``key``."""
    return next(c for c in summary["claims"] if c["id"] == key)


def verdict_of(summary: dict[str, Any], key: str, name: str) -> str:
    """The verdict of claim ``key`` for command ``name`` (not reproduced when it has none)."""
    row = claim_row(summary, key)
    return str(row[name]["verdict"]) if name in row else NOT_REPRODUCED
