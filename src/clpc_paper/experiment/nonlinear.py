"""The paper's nonlinear claim on a plant that needs it: the crank servo (issue 18).

Section V of the paper promises that globally nonlinear data are locally linear in time
windows, so clusters identify better than one global fit. The servo of section VI is
linear at the paper's amplitudes; this part runs the crank servo of
:mod:`clpc_paper.plants.crank_servo` (gravity and inertia that change with the angle) and its
negative control (the same plant with the velocity integrator on), each identified from
random command levels and judged on new levels and on a slow triangle sweep, with

* one global LPC model and one global least-squares model (N = 2);
* CLPC causal: each sample with the model of the last window completed before it (run on
  the validation record itself: an adaptive model, not one a user can keep);
* the CLPC steady-state model (the average of the windows);
* :class:`clpc.MultiModel` built from the identification trace (``from_trace``).

Free-run and 10-step fits are scored from the first CLPC update of each validation record
on (so that every model is scored on the same samples).
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from clpc import ARX, CLPC, LPC, MultiModel, fit_percent, operating_point_diagnostics
from clpc.multimodel import simulate_time_varying
from clpc.plotting import plot_multimodel
from clpc_paper.experiment.nonlinear_figures import fig_fits
from clpc_paper.plants.crank_servo import (
    CrankParameters,
    crank_commands,
    crank_operating_point,
    simulate_crank_servo,
)

__all__ = ["CLAIM_MARGIN", "nonlinear_claim", "run_nonlinear", "section_nonlinear"]

#: points of validation free-run fit by which the best cluster-based model must beat the
#: best global fit for "clusters identify better" (on each validation record)
CLAIM_MARGIN = 2.0
K_STEPS = 10
PLANTS = {
    "nonlinear": CrankParameters(),
    "control": CrankParameters(velocity_integrator=10.0),
}
ORDER = 2


def _held(trace: Any, n: int, lag: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Monic model arrays at each sample from the last update with index <= n - lag."""
    k = np.arange(n) - lag
    last = np.searchsorted(trace.index, k, side="right") - 1
    ok = (last >= 0) & np.asarray(trace.arrays["has_model"][:, 0])[np.maximum(last, 0)]
    theta = trace.arrays["theta"][np.maximum(last, 0), 0, :]
    a0 = np.where(ok, theta[:, 0], 1.0)
    den = theta[:, : ORDER + 1] / a0[:, None]
    num = -theta[:, ORDER + 1 :] / a0[:, None]
    icpt = trace.arrays["c"][np.maximum(last, 0), 0] / a0
    return den, num, icpt, ok


def _causal_scores(u: np.ndarray, y: np.ndarray, start: int) -> tuple[float, float]:
    """Free-run and 10-step fits of CLPC causal on a validation record (from ``start``)."""
    trace = CLPC(order=ORDER, window_size=201, cluster_size=12).run(u, y, dt=0.01)
    n = y.size
    den, num, icpt, _ = _held(trace, n, 1)
    sim = simulate_time_varying(
        den[start - ORDER :],
        num[start - ORDER :],
        icpt[start - ORDER :],
        u[start - ORDER :],
        y[start - ORDER : start],
    )[ORDER:]
    preds = [y]
    den_k, num_k, icpt_k, _ = _held(trace, n, K_STEPS)
    forced = icpt_k[ORDER:] + sum(num_k[ORDER:, j] * u[ORDER - j : n - j] for j in range(ORDER + 1))
    for step in range(1, K_STEPS + 1):
        acc = forced.copy()
        for lag in range(1, ORDER + 1):
            acc -= den_k[ORDER:, lag] * preds[max(step - lag, 0)][ORDER - lag : n - lag]
        cur = y.copy()
        cur[ORDER:] = acc
        preds.append(cur)
    return fit_percent(y[start:], sim), fit_percent(y[start:], preds[K_STEPS][start:])


def _scores(model: Any, u: np.ndarray, y: np.ndarray, start: int) -> tuple[float, float]:
    sim = model.simulate(
        u[start:], y_init=y[start - ORDER : start], u_init=u[start - ORDER : start]
    )
    pred = model.predict(u, y, k=K_STEPS)
    return fit_percent(y[start:], sim), fit_percent(y[start:], pred[start:])


def _one_plant(name: str, params: CrankParameters, seeds: list[Any], quick: bool) -> dict:
    n_id, n_val, legs, leg = (20, 10, 2, 20.0) if quick else (60, 30, 4, 30.0)
    ident = simulate_crank_servo(crank_commands(n_id, seed=seeds[0]), seed=seeds[1], params=params)
    records = {
        "levels": simulate_crank_servo(
            crank_commands(n_val, seed=seeds[2]), seed=seeds[3], params=params
        ),
        "sweep": simulate_crank_servo(
            crank_commands(legs, hold=leg, sweep=True, seed=seeds[4]), seed=seeds[5], params=params
        ),
    }
    u, y = ident.command, ident.position
    trace = CLPC(order=ORDER, window_size=201, cluster_size=12).run(u, y, dt=0.01)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        steady = trace.steady_state_model(allow_unconverged=True)
    models: dict[str, Any] = {
        "global_lpc": LPC(order=ORDER).fit(u, y, dt=0.01),
        "global_ls": ARX(order=ORDER).fit(u, y, dt=0.01),
        "clpc_steady_state": steady,
        "multimodel": MultiModel.from_trace(trace, u, y),
    }
    start = 201 + ORDER  # the first CLPC update of a validation record
    fits: dict[str, dict[str, Any]] = {}
    for rec_name, rec in records.items():
        vu, vy = rec.command, rec.position
        row = {
            k: dict(zip(("free_run", "k10"), _scores(m, vu, vy, start), strict=True))
            for k, m in models.items()
        }
        row["clpc_causal"] = dict(
            zip(("free_run", "k10"), _causal_scores(vu, vy, start), strict=True)
        )
        fits[rec_name] = row
    mm: MultiModel = models["multimodel"]
    diag = operating_point_diagnostics(trace, u, y)
    return {
        "plant": name,
        "integrator": params.velocity_integrator,
        "samples": {
            "identification": int(y.size),
            **{k: int(r.position.size) for k, r in records.items()},
        },
        "fits": fits,
        "multimodel": {
            "n_models": mm.n_models,
            "centres": mm.centres,
            "estimator": mm.diagnostics["estimator"],
            "centre_source": mm.diagnostics["centre_source"],
            "centre_reason": mm.diagnostics["centre_reason"],
            "chosen_by": mm.diagnostics["chosen_by"],
            "replaced": mm.diagnostics["replaced"],
        },
        "operating_point": diag.summary(),
        "steady_state_warning": [str(w.message) for w in caught],
        "_objects": (mm, records["levels"], models, start),
    }


def run_nonlinear(out: Path, seed: int = 0, quick: bool = False) -> dict[str, Any]:
    """Run both plants, write the figures; the JSON-safe summary of this part."""
    t0 = time.perf_counter()
    seq = np.random.SeedSequence([seed, 18]).spawn(2)
    result: dict[str, Any] = {"claim_margin": CLAIM_MARGIN, "k_steps": K_STEPS, "figures": {}}
    for (name, params), ss in zip(PLANTS.items(), seq, strict=True):
        part = _one_plant(name, params, ss.spawn(6), quick)
        mm, rec, models, start = part.pop("_objects")
        result[name] = part
        ref = crank_operating_point(np.linspace(-0.5, 3.0, 200), params)
        result["figures"][f"{name}_multimodel"] = plot_multimodel(
            mm, out / f"figN_{name}_multimodel.png", reference=(ref[0], ref[1], ref[2])
        )
        result["figures"][f"{name}_fits"] = fig_fits(
            out / f"figN_{name}_fits.png", rec, models, start, name, quick
        )
    result["runtime_s"] = time.perf_counter() - t0
    return result


def _verdict(part: dict[str, Any], *, expect_gain: bool = True) -> tuple[str, str]:
    """The verdict on one plant and the numbers behind it.

    With ``expect_gain`` the claim holds when the clusters gain on every record; for the
    negative control (``expect_gain=False``) when they gain on none.
    """
    wins, texts = [], []
    for rec, row in part["fits"].items():
        cluster = max(row["multimodel"]["free_run"], row["clpc_causal"]["free_run"])
        glob = max(row["global_lpc"]["free_run"], row["global_ls"]["free_run"])
        wins.append(cluster - glob >= CLAIM_MARGIN)
        texts.append(
            f"{rec}: multi-model {row['multimodel']['free_run']:.1f}, CLPC causal "
            f"{row['clpc_causal']['free_run']:.1f} vs global LPC "
            f"{row['global_lpc']['free_run']:.1f}, LS {row['global_ls']['free_run']:.1f} % "
            f"free run ({cluster - glob:+.1f} points; margin {CLAIM_MARGIN})"
        )
    held = wins if expect_gain else [not w for w in wins]
    verdict = "reproduced" if all(held) else "partly" if any(held) else "not reproduced"
    return verdict, "; ".join(texts)


def nonlinear_claim(result: dict[str, Any]) -> dict[str, Any]:
    """The claim row for ``summary["claims"]`` (verdicts for both plants)."""
    row: dict[str, Any] = {
        "id": "clusters_nonlinear",
        "figures": [],
        "paper": "clusters identify better than one global fit (crank servo; its negative "
        "control with the integrator on should show no gain)",
    }
    for name in PLANTS:
        control = name == "control"
        verdict, numbers = _verdict(result[name], expect_gain=not control)
        beats = (
            "the better of multi-model and CLPC causal beats the better of global LPC and "
            f"least squares by >= {CLAIM_MARGIN} points of validation free-run fit"
        )
        row[name] = {
            "verdict": verdict,
            "numbers": numbers,
            "criterion": f"no gain: on no record {beats}"
            if control
            else f"{beats} on every record",
        }
    return row


def section_nonlinear(summary: dict[str, Any]) -> list[str]:
    """The report's section on the crank servo (empty for summaries without it)."""
    result = summary.get("nonlinear_servo")
    if not result:
        return []
    lines = [
        "## A plant that needs clusters: the crank servo (issue 18)\n",
        "The servo lifts a 2 kg mass on a 5 cm crank: the gravity torque and the inertia "
        "change with the angle, and without a velocity integrator the local DC gain runs "
        "from 0.67 (bottom) to about 1.9 (top). The negative control is the same plant "
        "with the integrator on (static gain 1 everywhere). Validation free-run and "
        f"{K_STEPS}-step fits (%), N = 2, Table 1's windows:\n",
        "| plant | record | metric | global LPC | global LS | CLPC steady state | CLPC causal "
        "| multi-model |",
        "|---|---|---|---|---|---|---|---|",
    ]
    keys = ("global_lpc", "global_ls", "clpc_steady_state", "clpc_causal", "multimodel")
    for name in PLANTS:
        for rec, row in result[name]["fits"].items():
            for metric in ("free_run", "k10"):
                cells = " | ".join(f"{row[k][metric]:.1f}" for k in keys)
                lines.append(f"| {name} | {rec} | {metric} | {cells} |")
    lines.append("")
    claim = nonlinear_claim(result)
    for name in PLANTS:
        part = result[name]
        mm = part["multimodel"]
        lines += [
            f"**{name}** - *{claim[name]['verdict']}*: {claim[name]['numbers']}.\n",
            f"- Multi-model: {mm['n_models']} local models ({mm['estimator']}), centres "
            f"{', '.join(f'{c:.2f}' for c in mm['centres'])} rad from the {mm['centre_source']}"
            f" ({mm['centre_reason']}); chosen by {mm['chosen_by']}.",
            f"- Operating-point diagnostics of the trace: {part['operating_point']['verdict']}.",
            "- CLPC steady-state model: "
            + ("; ".join(part["steady_state_warning"]) or "no warning")
            + "\n",
            f"![{name}: multi-model](figN_{name}_multimodel.png)\n",
            f"![{name}: validation fits](figN_{name}_fits.png)\n",
        ]
    lines.append(
        "The negative control is nearly, not perfectly, linear: its inertia still changes "
        "3.5 times with the angle and its 2 s windows are too short to settle the "
        "integrator, so the diagnostics still flag it and the multi-model gains about a "
        f"point there - below the claim's margin of {CLAIM_MARGIN} points.\n"
    )
    lines.append(
        "D (lambda_max - lambda_min) measures a window's excitation (signal energy), not its "
        "linearity; the scale-free lambda_min / lambda_max sees nonlinearity inside a window "
        "only. Operating-point nonlinearity shows across windows: the diagnostics above.\n"
    )
    return lines
