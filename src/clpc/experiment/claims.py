"""The paper's claims of section VI, each with the numeric criterion that decides it.

:func:`claims` turns the experiment's summary into a verdict per paper claim and per command
(``"reproduced"``, ``"partly"``, ``"not reproduced"``) with the numbers behind it. It reads
only the JSON-safe summary, so a saved ``summary.json`` can be judged again.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

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

REPRODUCED, PARTLY, NOT_REPRODUCED = "reproduced", "partly", "not reproduced"
POLE_NEAR_ONE = 0.05  #: an actuator pole within this distance of z = 1 is integrating
DC_TOLERANCE = 0.02  #: |DC gain - 1| for "the position follows the command"
TORQUE_FIT_GOOD = 50.0  #: torque estimate "tracks" above this fit [%]
CONVERGED_RATIO = 0.5  #: an error converges when RMS(last second) < this x RMS(first second)


def fmt(x: Any, spec: str = ".3g") -> str:
    """A number for the report, ``"n/a"`` for None."""
    return "n/a" if x is None else format(x, spec)


def fmt_poles(poles: list[list[float]]) -> str:
    """``[re, im]`` pairs as ``"0.9512, 0.3-0.1j"`` (4 decimals)."""
    return ", ".join(f"{re:.4f}{im:+.4f}j" if abs(im) > 1e-9 else f"{re:.4f}" for re, im in poles)


def _verdict(*ok: bool) -> str:
    return REPRODUCED if all(ok) else PARTLY if any(ok) else NOT_REPRODUCED


def _claim_d(cs: dict[str, Any]) -> dict[str, Any]:
    d = cs["D"]
    fill, after = d["fill"], d["after_fill"]
    rising = fill.get("rising_fraction", 0.0) >= 0.8
    text = (
        f"fill: D {fmt(fill.get('first'))} -> {fmt(fill.get('last'))} rad^2 in "
        f"{fill['n_updates']} updates, rising in {fmt(fill.get('rising_fraction'), '.0%')}"
        f" of them (cv {fmt(fill.get('cv'), '.2f')}); after the fill "
        f"(t >= {fmt(d['window_full_time'], '.2f')} s): cv {fmt(after.get('cv'), '.3f')},"
        f" drift {fmt(after.get('trend'), '+.2f')} of the mean"
    )
    return {"verdict": _verdict(rising, d["quasi_constant_after_fill"]), "numbers": text}


def _claim_parameters(cs: dict[str, Any], settings: dict[str, Any]) -> dict[str, Any]:
    p = cs["parameters"]
    if not p["converged"]:
        return {
            "verdict": NOT_REPRODUCED,
            "numbers": "no quasi-constant phase under any tolerance; the last accepted "
            "update is used as the steady state",
        }
    tol = settings["tolerances"][p["tolerance_level"]]
    text = (
        f"quasi-constant from cluster {p['cluster']} (t = {p['time']:.2f} s) with "
        f"|dtheta| < {tol[0]} and |dD|/D < {tol[1]} for {tol[2]} updates in a row; after "
        f"it max ||theta - theta_ss|| = {p['theta_variation']:.3f}; windows the solver "
        f"calls determined: {p['determined_fraction']:.0%}"
    )
    ok_small = p["theta_variation"] < 0.1
    return {"verdict": _verdict(p["tolerance_level"] == 0, ok_small), "numbers": text}


def _claim_stable(cs: dict[str, Any]) -> dict[str, Any]:
    m = cs["model"]
    dc = m["dc_gain"]
    follows = dc is not None and abs(dc - 1.0) < DC_TOLERANCE
    sim = cs["baselines"]["clpc"]["simulation_fit"]
    text = (
        f"poles |p| = {', '.join(f'{r:.3f}' for r in m['pole_radius'])}, DC gain "
        f"{fmt(dc, '.4f')}, free-run fit {fmt(sim, '.2f')} %"
    )
    return {"verdict": _verdict(m["stable"], follows), "numbers": text}


def _claim_actuator(act: dict[str, Any], rigid: dict[str, Any]) -> dict[str, Any]:
    m = act["model"]
    poles = fmt_poles(m["poles"])
    text = (
        f"poles {poles} (closest to 1 at {m['pole_distance_to_1']:.4f}); rigid body "
        f"{', '.join(f'{p:.4f}' for p in rigid['poles'])}"
    )
    if act.get("equivalent_damping") is not None:
        text += (
            f"; second pole = viscous damping {act['equivalent_damping']:.4f} N m s/rad "
            f"(servo: {rigid['viscous']:.4f} viscous, Coulomb {rigid['coulomb']:.3f} N m)"
        )
    return {"verdict": _verdict(m["pole_distance_to_1"] < POLE_NEAR_ONE), "numbers": text}


def _claim_torque(act: dict[str, Any]) -> dict[str, Any]:
    e, fit = act["torque_error"], act["torque_fit"]
    if e.get("diverged"):
        return {"verdict": NOT_REPRODUCED, "numbers": "the estimated torque diverged"}
    tracks = fit is not None and fit >= TORQUE_FIT_GOOD
    ratio = e["rms_last_second"] / max(e["rms_first_second"], 1e-300)
    converges = ratio < CONVERGED_RATIO
    text = (
        f"torque fit {fmt(fit, '.1f')} %; error RMS first second "
        f"{e['rms_first_second']:.4f} N m, last second {e['rms_last_second']:.4f} N m "
        f"(ratio {ratio:.2f})"
    )
    return {"verdict": _verdict(tracks, converges), "numbers": text}


def _claim_position(cs: dict[str, Any]) -> dict[str, Any]:
    e = cs["position_error"]
    if e.get("diverged"):
        return {"verdict": NOT_REPRODUCED, "numbers": "the free-run simulation diverged"}
    ratio = e["rms_last_second"] / max(e["rms_first_second"], 1e-300)
    text = (
        f"error RMS first second {1e3 * e['rms_first_second']:.3f} mrad, last second "
        f"{1e3 * e['rms_last_second']:.3f} mrad (ratio {ratio:.2f}); peak "
        f"{1e3 * e['peak']:.3f} mrad at t = {e['peak_time']:.2f} s"
    )
    if e.get("mean_before_ramp") is not None:
        text += (
            f"; before the ramp starts the error is the model's offset at rest, "
            f"{1e3 * e['mean_before_ramp']:.3f} mrad on average"
        )
    return {"verdict": _verdict(ratio < CONVERGED_RATIO), "numbers": text}


def _claim_corner(cs: dict[str, Any]) -> dict[str, Any]:
    e = cs["position_error"]
    if e.get("diverged") or e.get("corner_peak") is None:
        return {"verdict": NOT_REPRODUCED, "numbers": "no corner error available"}
    at_corner = abs(e["peak_time"] - e["corner_time"]) <= 0.15
    text = (
        f"largest error {1e3 * e['peak']:.3f} mrad at t = {e['peak_time']:.2f} s; "
        f"within 0.15 s of {e['corner_time']:.1f} s: {1e3 * e['corner_peak']:.3f} mrad "
        f"(position range 1 rad)"
    )
    return {"verdict": _verdict(at_corner), "numbers": text}


def _claim_clusters(cmd: dict[str, Any]) -> dict[str, Any]:
    cs, act = cmd["control_system"]["baselines"], cmd["actuator"]["baselines"]
    best_clpc = max(_num(cs["clpc"]["k10_fit"]), _num(cs["clpc_online"]["k10_fit"]))
    best_act = max(_num(act["clpc"]["k10_fit"]), _num(act["clpc_online"]["k10_fit"]))
    wins = [best_clpc > _num(cs["lpc"]["k10_fit"]), best_act > _num(act["lpc"]["k10_fit"])]
    text = (
        f"10-step fit, control system: CLPC {fmt(cs['clpc']['k10_fit'], '.2f')} / online "
        f"{fmt(cs['clpc_online']['k10_fit'], '.2f')} vs global LPC "
        f"{fmt(cs['lpc']['k10_fit'], '.2f')} vs LS {fmt(cs['arx']['k10_fit'], '.2f')} %; "
        f"actuator: CLPC {fmt(act['clpc']['k10_fit'], '.1f')} / online "
        f"{fmt(act['clpc_online']['k10_fit'], '.1f')} vs LPC "
        f"{fmt(act['lpc']['k10_fit'], '.1f')} vs LS {fmt(act['arx']['k10_fit'], '.1f')} %"
    )
    return {"verdict": _verdict(*wins), "numbers": text}


def _num(x: Any) -> float:
    return float("-inf") if x is None else float(x)


Check = Callable[[dict[str, Any], dict[str, Any]], dict[str, Any]]
"""(one command's summary, the whole summary) -> ``{"verdict": ..., "numbers": ...}``"""


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
        lambda c, s: _claim_d(c["control_system"]),
    ),
    Claim(
        "parameters",
        (7, 8, 9, 10, 11, 12),
        "the parameters (39) are quasi constant after a few clusters",
        lambda c, s: _claim_parameters(c["control_system"], s["settings"]),
    ),
    Claim(
        "stable_model",
        (15, 16, 17),
        "the steady-state model of the control system is stable (position follows command)",
        lambda c, s: _claim_stable(c["control_system"]),
    ),
    Claim(
        "actuator_poles",
        (13, 14),
        "the motor as actuator (torque -> position) is identified: integrating poles near z = 1",
        lambda c, s: _claim_actuator(c["actuator"], s["rigid_body"]),
    ),
    Claim(
        "torque_estimate",
        (13, 14),
        "the estimated torque command tracks the experimental one and its error converges",
        lambda c, s: _claim_torque(c["actuator"]),
    ),
    Claim(
        "position_error_converges",
        (15, 16, 17),
        "the stability of the model ensures the convergence of the identification errors",
        lambda c, s: _claim_position(c["control_system"]),
    ),
    Claim(
        "corner_error",
        (17,),
        "a large identification error at t = 1.4 s (the ramp's corner)",
        lambda c, s: _claim_corner(c["control_system"]),
        commands=("ramp",),
    ),
    Claim(
        "clusters",
        (),
        "clusters: local (windowed) LPC identifies better than one global fit",
        lambda c, s: _claim_clusters(c),
    ),
)


def claims(summary: dict[str, Any]) -> list[dict[str, Any]]:
    """Verdict and numbers for every paper claim, per command (``ramp`` and ``rich``)."""
    out = []
    for claim in CLAIMS:
        row: dict[str, Any] = {"id": claim.id, "figures": list(claim.figures), "paper": claim.paper}
        for name, cmd in summary["commands"].items():
            if claim.commands is None or name in claim.commands:
                row[name] = claim.check(cmd, summary)
        out.append(row)
    return out


def claim_row(summary: dict[str, Any], key: str) -> dict[str, Any]:
    """The row of ``summary["claims"]`` with id ``key``."""
    return next(c for c in summary["claims"] if c["id"] == key)


def verdict_of(summary: dict[str, Any], key: str, name: str) -> str:
    """The verdict of claim ``key`` for command ``name`` (not reproduced when it has none)."""
    row = claim_row(summary, key)
    return str(row[name]["verdict"]) if name in row else NOT_REPRODUCED
