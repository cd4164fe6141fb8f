"""The paper's section VI experiment, end to end, on the simulated brushless servo.

``run_experiment(out_dir)`` simulates the position-controlled servo of Fig. 4
(:mod:`clpc_paper.plants`), runs the CLPC appraiser with the settings of Table 1 on two
identifications,

* (a) the control system, position command -> measured position (Figs. 6-12, 15-17);
* (b) the motor as actuator, torque command -> measured position (Figs. 13-14);

and writes the paper's Figs. 5-17 (:mod:`clpc_paper.experiment.figures`), ``summary.json`` (the
numbers behind them), ``report.md`` (every figure beside the claim it tests,
:mod:`clpc_paper.experiment.report`) and ``report.html`` (the same text as a web page,
:mod:`clpc_paper.experiment.html_report`).

Two commands are used. The paper's ramp with saturation (Fig. 5) gives the main figures;
it excites the loop only while it ramps (its second difference is zero except at the two
corners), so the same pipeline also runs on a richer command: the same ramp-and-hold
moves repeated with a 2 s period (the window length) plus a small PRBS dither.

Signals flow as on a real drive: the servo is logged at 1 ms (the drive's trace buffer)
and the appraiser works at Table 1's 10 ms ``sample_time``, anti-alias filtering and
decimating the log itself (:class:`clpc.CLPC` with ``dt`` 1 ms, ``decimate_to`` 10 ms). Every model
is evaluated on the same decimated signals (:func:`clpc.appraiser.decimate` is
the appraiser's own filter).

Data flow (no module imports one above it): ``settings`` -> ``results`` -> ``analysis``,
``statistics``, ``identification`` -> ``evaluation`` -> ``claim_checks`` -> ``claims`` ->
``markdown`` -> ``sections`` -> ``report`` -> ``html_report``; ``marks`` -> ``figure_base``,
``figures_signals`` -> ``figures``; ``run`` (this module) calls them all. A further section
of the demo is one more ``analyse_*`` call here, its numbers one more key of the summary.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from clpc.report import jsonable
from clpc_paper.experiment.claims import claims
from clpc_paper.experiment.evaluation import (
    aliasing_check,
    analyse_command,
    extended_ramp,
    torque_without_friction,
)
from clpc_paper.experiment.figures import write_figures
from clpc_paper.experiment.html_report import render_html_report
from clpc_paper.experiment.nonlinear import nonlinear_claim, run_nonlinear
from clpc_paper.experiment.report import render_report
from clpc_paper.experiment.settings import (
    LOG_SAMPLE_TIME,
    RAMP,
    RICH_DITHER,
    RICH_MOVES,
    SAMPLE_TIME,
    durations,
    settings_record,
)
from clpc_paper.experiment.statistics import rigid_body
from clpc_paper.plants import ServoParameters, prbs, ramp_with_saturation, trapezoid_moves

__all__ = ["commands", "run_experiment"]

Command = Callable[[float], np.ndarray]  #: sample time [s] -> command samples [rad]


def commands(
    ramp_duration: float, rich_duration: float, dither_seed: Any
) -> tuple[Command, Command]:
    """The ramp with saturation (Fig. 5) and the rich command, as functions of the sample time."""

    def ramp(dt: float) -> np.ndarray:
        return ramp_with_saturation(
            ramp_duration, dt, start=RAMP.start, ramp_time=RAMP.ramp_time, level=RAMP.level
        )

    def rich(dt: float) -> np.ndarray:
        m = RICH_MOVES
        moves = trapezoid_moves(
            rich_duration,
            dt,
            positions=m.positions,
            max_velocity=m.max_velocity,
            max_acceleration=m.max_acceleration,
            dwell=m.dwell,
            start=m.start,
        )
        rng = np.random.default_rng(dither_seed)
        dither = prbs(
            rich_duration,
            dt,
            seed=rng,
            amplitude=RICH_DITHER.amplitude,
            min_hold=RICH_DITHER.min_hold,
        )
        return moves + dither

    return ramp, rich


def run_experiment(
    out_dir: str | Path,
    *,
    duration: float | None = None,
    quick: bool = False,
    seed: int = 0,
    method: str = "robust",
) -> dict[str, Any]:
    """Reproduce the paper's section VI on the simulated servo; write figures and reports.

    Parameters
    ----------
    out_dir : str or Path
        Output folder (created): ``fig05_command.png`` ... ``fig17_position_error.png``,
        ``figR_rich_command.png``, ``summary.json``, ``report.md``, ``report.html``.
    duration : float, optional
        Length of both records [s], at least 3. Default: 3.4 s for the ramp (until the
        ramp leaves the 2 s window) and 20 s (quick: 8 s) for the rich command.
    quick : bool
        Shorter rich record and lighter figures (for tests; a few seconds).
    seed : int
        Seed of the servo noise and of the PRBS dither.
    method : {"robust", "paper"}
        LPC solution used by the appraiser and the global LPC baseline.

    Returns
    -------
    dict
        The summary written to ``summary.json`` (JSON-safe: non-finite numbers are None).
    """
    t_start = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    ramp_duration, rich_duration = durations(duration, quick)
    seeds = np.random.SeedSequence(seed).spawn(5)
    params = ServoParameters()
    ramp_fn, rich_fn = commands(ramp_duration, rich_duration, seeds[2])
    ramp = analyse_command("ramp", ramp_fn(LOG_SAMPLE_TIME), seeds[0], method, params, RAMP.corner)
    rich = analyse_command("rich", rich_fn(LOG_SAMPLE_TIME), seeds[1], method, params)
    # the cause check of Figs. 13-14: the same ramp run on the servo without Coulomb friction
    smooth = torque_without_friction(ramp.command_log, seeds[0], method, params, RAMP.corner)
    summary: dict[str, Any] = {
        "settings": settings_record(ramp_duration, rich_duration, quick, seed, method),
        "rigid_body": rigid_body(params, SAMPLE_TIME),
        "commands": {"ramp": ramp.summary, "rich": rich.summary},
        "torque_without_friction": smooth.summary,
        "extended_ramp": extended_ramp(seeds[3], method, params),
        "aliasing_check": aliasing_check(rich_fn, seeds[4], method, params),
    }
    summary["claims"] = claims(summary)
    summary["nonlinear_servo"] = run_nonlinear(out, seed=seed, quick=quick)  # issue 18
    summary["claims"].append(nonlinear_claim(summary["nonlinear_servo"]))
    summary["figures"] = write_figures(out, ramp, rich, smooth, quick=quick)
    summary["runtime_s"] = time.perf_counter() - t_start
    summary = jsonable(summary)
    (out / "summary.json").write_text(json.dumps(summary, indent=2), encoding="utf-8")
    (out / "report.md").write_text(render_report(summary), encoding="utf-8")
    render_html_report(summary, out / "report.html")  # the same text as a web page
    return summary
