"""The report's sections: each figure group beside the claim it tests, and what it means.

Every ``section_*`` function returns the Markdown lines of one section of ``report.md``,
built from the JSON-safe summary alone; the prose adapts to the verdicts.
"""

from __future__ import annotations

from typing import Any

from clpc_paper.experiment.claims import NOT_REPRODUCED, REPRODUCED, fmt, fmt_poles, verdict_of
from clpc_paper.experiment.markdown import baseline_rows, claim_block, img, model_row, yes
from clpc_paper.experiment.settings import A0_MIN, D_QUASI_CONSTANT, LABELS

__all__ = [
    "section_clusters",
    "section_command",
    "section_d",
    "section_models",
    "section_parameters",
    "section_position",
    "section_torque",
]


def section_command(summary: dict[str, Any]) -> list[str]:
    """Fig. 5: the command, and why a ramp with saturation identifies poorly."""
    ext = summary["extended_ramp"]
    ex_r = summary["commands"]["ramp"]["excitation"]
    ex_c = summary["commands"]["rich"]["excitation"]
    theta = ", ".join(f"{v:.3g}" for v in ext["held_theta_last"])
    return [
        "## Fig. 5 - the command, and why a ramp with saturation identifies poorly\n",
        img(summary, 5, "Fig. 5 Position command [rad]"),
        "A second-order model needs an input whose second difference is not zero: a ramp "
        "satisfies `(1 - z^-1)^2 r = 0` everywhere except at its corners. In the ramp record "
        "the command's second difference is non-zero in "
        f"{ex_r['second_difference_nonzero_samples']} of {ex_r['samples']} logged samples "
        f"({ex_r['second_difference_nonzero_fraction']:.2%}); in the rich command in "
        f"{ex_c['second_difference_nonzero_fraction']:.1%}. Once the ramp has left the 2 s "
        f"window nothing moves: continuing the ramp record to {ext['duration']:.0f} s, the "
        f"command is exactly constant in {ext['constant_command_windows']} of the "
        f"{ext['updates_after_ramp_left_window']} later windows (D falls to "
        f"{ext['D_last']:.2g} rad^2 from a peak of {ext['D_max']:.0f}). The appraiser flags "
        f"{ext['degenerate_flagged']} of them degenerate and accepts "
        f"{ext['accepted_constant_command']} estimates from constant-command windows "
        f"({ext['accepted_without_a0']} of all accepted estimates have a0 < {A0_MIN}); it "
        f"holds theta [{theta}] at the end. The main ramp record therefore ends at "
        f"{summary['settings']['ramp']['duration']:.1f} s, when the ramp leaves the window.\n",
    ]


def section_d(summary: dict[str, Any]) -> list[str]:
    """Fig. 6: D for each cluster."""
    rich_ok = summary["commands"]["rich"]["control_system"]["D"]["quasi_constant_after_fill"]
    ramp_ok = summary["commands"]["ramp"]["control_system"]["D"]["quasi_constant_after_fill"]
    return [
        "## Fig. 6 - D for each cluster\n",
        img(summary, 6, "Fig. 6 D for each cluster"),
        claim_block(summary, "D"),
        "D is the spread of the eigenvalues of a scatter *sum* (eq. 27), so it grows with the "
        "number of rows while the window fills (the first 16 updates) whatever the data. After "
        "the fill it is quasi-constant only if every 2 s window holds the same amount of "
        f"motion (cv < {D_QUASI_CONSTANT}): "
        f"{yes(rich_ok, 'true', 'false')} for the periodic rich command, "
        f"{yes(ramp_ok, 'true', 'false')} for the single ramp"
        f"{yes(ramp_ok, '.', ', whose D falls as the ramp slides out of the window.')}\n",
    ]


def section_parameters(summary: dict[str, Any]) -> list[str]:
    """Figs. 7-12: the parameters per cluster."""
    cs_c = summary["commands"]["rich"]["control_system"]
    det = cs_c["parameters"]["determined_fraction"]
    fit1 = fmt(cs_c["baselines"]["lpc_order1"]["simulation_fit"], ".2f")
    text = (
        "The curves are the appraiser's held outputs: the unit-norm theta (paper "
        f"convention). The solver calls {det:.0%} of the rich-command control-system "
        "windows determined (a unique N = 2 relation)."
    )
    if det < 0.5:
        text += (
            " At 10 ms the position loop (crossover about 9 Hz, velocity loop about "
            "70 Hz) is nearly first order - an N = 1 global LPC reaches a free-run fit "
            f"of {fit1} % - so the N = 2 relation is close to a family of relations "
            "sharing a common factor. The parameters still settle because the solver "
            "returns the minimum-norm member of that near-null subspace, but a01..b21 "
            "are individually weakly identified, while the transfer function is well "
            "determined (see the fits below)."
        )
    p_r = summary["commands"]["ramp"]["control_system"]["parameters"]
    step = p_r.get("largest_step")
    if step is not None:
        st = summary["settings"]
        gone = st["ramp"]["start"] + st["window_time"]
        text += (
            f" On the ramp the marker is where the convergence rule first holds (cluster "
            f"{p_r['cluster']}); the rule does not forbid later steps, and the largest one "
            f"({step['size']:.3f} in ||theta||, cluster {step['cluster']}, t = "
            f"{step['time']:.2f} s) comes after the ramp's start has left the 2 s window "
            f"(t = {gone:.2f} s): the windows then hold another part of the motion. The red "
            "line is the mean of the trusted updates from the marker on, the band their range."
        )
    return [
        "## Figs. 7-12 - the parameters a01, a11, a21, b01, b11, b21 per cluster\n",
        *[
            img(summary, n, f"Fig. {n} {lab} parameter")
            for n, lab in zip(range(7, 13), LABELS, strict=True)
        ],
        claim_block(summary, "parameters"),
        text + "\n",
    ]


def section_models(summary: dict[str, Any]) -> list[str]:
    """The steady-state models, the rigid body and the aliasing check."""
    cmds, rb = summary["commands"], summary["rigid_body"]
    alias = summary["aliasing_check"]["model"]
    act_r, act_c = cmds["ramp"]["actuator"]["model"], cmds["rich"]["actuator"]["model"]
    text = (
        f"A(1) = sum(den) is 0 for an integrator: {act_c['den_sum']:.2g} for the "
        f"rich-command actuator model, {act_r['den_sum']:.2g} for the ramp's."
    )
    if verdict_of(summary, "actuator_poles", "rich") == REPRODUCED:
        text += (
            " With the rich command one actuator pole sits at z = 1 as the physics says "
            "(velocity integrates to position); the other is faster than the rigid "
            f"body's {min(rb['poles']):.4f}: the Coulomb friction ({rb['coulomb']} N m) is "
            "comparable to the torques of these moves and acts, linearised, as a much "
            "larger viscous damping."
        )
    if verdict_of(summary, "actuator_poles", "ramp") != REPRODUCED:
        text += (
            " During a ramp the position satisfies (1 - z^-1)^2 y = 0 by itself and the "
            "torque is nearly the constant friction torque, so the ramp data cannot "
            "separate A(z) from B(z); the ramp's actuator model is not the motor."
        )
    text += (
        " Logged directly at 10 ms (the servo's log then averages the torque over each "
        "10 ms, a boxcar anti-alias filter, instead of the appraiser's Butterworth on a 1 ms "
        "log), the rich-command actuator poles come out at "
        f"{fmt_poles(alias['poles'])}, {alias['pole_distance_to_1']:.4f} from 1, "
        f"stable: {alias['stable']}."
    )
    return [
        "## Steady-state models\n",
        "| model | den (monic) | num | poles | zeros | DC gain | stable |",
        "|---|---|---|---|---|---|---|",
        model_row("control system, ramp", cmds["ramp"]["control_system"]["model"]),
        model_row("control system, rich", cmds["rich"]["control_system"]["model"]),
        model_row("actuator, ramp", act_r),
        model_row("actuator, rich", act_c),
        model_row("actuator, rich, logged at 10 ms (aliased torque)", alias),
        f"\nRigid body (motor + load inertia J = {rb['inertia']:.2e} kg m^2, viscous friction "
        f"{rb['viscous']:.1e} N m s/rad, zero-order hold at 10 ms): poles "
        f"{', '.join(f'{p:.5f}' for p in rb['poles'])}, num "
        f"[{', '.join(f'{v:.4f}' for v in rb['num'])}] (z^-1, z^-2).\n",
        claim_block(summary, "stable_model"),
        claim_block(summary, "actuator_poles"),
        text + "\n",
    ]


def section_torque(summary: dict[str, Any]) -> list[str]:
    """Figs. 13-14: experimental and estimated torque command, and what limits the estimate."""
    act_r = summary["commands"]["ramp"]["actuator"]
    smooth = summary.get("torque_without_friction")
    best = act_r["torque_best_window"]
    text = (
        "The estimated torque is the actuator model run backwards, u = (den(z) y - k)/num(z). "
        "Sampling a double integrator puts a zero of num(z) outside the unit circle, so the "
        "causal inverse (`LinearModel.infer_input`) is unstable; for the ramp model it "
        f'answers: "{act_r["causal_inverse"]}" The figures use the stable non-causal '
        "inverse (`clpc_paper.experiment.stable_inverse`: zeros inside the circle inverted "
        "forwards, outside backwards in time, both started at rest/settled), valid offline.\n\n"
        "What limits it, measured: (1) the servo logs the torque as its mean over each 1 ms "
        "(what the motor integrates); one controller sample per period put the velocity "
        "loop's noise torque, which never moves the motor, into the log. (2) Coulomb "
        f"friction ({summary['rigid_body']['coulomb']} N m, the whole torque of the ramp) "
        "holds the motor while the torque changes at rest and in the hold: the best linear "
        "estimate of this torque from this position, least squares fitted on the record "
        f"itself, reaches {fmt(act_r['torque_linear_bound'], '.1f')} %, and the best single "
        f"trusted window's model {fmt(best['fit'], '.1f')} % (cluster {best['cluster']}). "
        "(3) The steady-state model averages the later windows, from which the ramp's start "
        "has gone and whose torque gain collapses (B(1) "
        f"{fmt(best.get('num_sum'), '.3g')} in the best window, "
        f"{fmt(best.get('last_window_num_sum'), '.2g')} in the last): B(1) = "
        f"{act_r['model']['num_sum']:.3g} (rigid body "
        f"{sum(summary['rigid_body']['num']):.3g}) and A(1) = {act_r['model']['den_sum']:.2g}"
        ", so the intercept k fitted at the windows' operating point turns into a torque "
        f"of -k/B(1) = {fmt(act_r['model'].get('input_at_zero'), '.3f')} N m at rest."
    )
    if smooth is not None:
        e = smooth["torque_error"]
        text += (
            " Panel (b) runs the same ramp, seed and settings on the servo without Coulomb "
            f"friction: torque fit {fmt(smooth['torque_fit'], '.1f')} %, error RMS over the "
            f"last second {1e3 * e['rms_last_second']:.2f} mN m against a noise level of "
            f"{1e3 * smooth['torque_noise_level']:.2f} mN m; at rest its estimate sits at "
            f"its own -k/B(1) = {1e3 * (smooth['model'].get('input_at_zero') or 0.0):.2f} "
            f"mN m (mean error there {1e3 * (e.get('mean_before_ramp') or 0.0):.2f} mN m)."
        )
    return [
        "## Figs. 13-14 - experimental and estimated torque command\n",
        img(summary, 13, "Fig. 13 Experimental and estimated torque command [N m]"),
        img(summary, 14, "Fig. 14 Torque command identification error [mN m]"),
        claim_block(summary, "torque_estimate"),
        text + "\n",
    ]


def section_position(summary: dict[str, Any]) -> list[str]:
    """Figs. 15-17: experimental and estimated position."""
    ramp = summary["commands"]["ramp"]
    e_c = summary["commands"]["rich"]["control_system"]["position_error"]
    text = (
        "The estimated position is a free run of the control-system model from the "
        "command, started from the two measured initial positions."
    )
    if verdict_of(summary, "corner_error", "ramp") != REPRODUCED:
        text += (
            " The simulated loop is linear at this amplitude (peak torque "
            f"{ramp['torque_peak']:.2f} N m against a 3 N m limit): the corner gives a "
            "visible transient in Fig. 17 but not the largest error, so the paper's large "
            "error at 1.4 s (which it attributes to nonlinearity beyond quadratic) has no "
            "counterpart here."
        )
    if (
        not e_c.get("diverged")
        and verdict_of(summary, "position_error_converges", "rich") != REPRODUCED
    ):
        text += (
            " With a command that keeps moving, the error of a stable model stays at its "
            f"mismatch level ({1e3 * e_c['rms']:.3f} mrad RMS over the record) instead of "
            "converging to zero: stability bounds the error, the mismatch sets its size."
        )
    return [
        "## Figs. 15-17 - experimental and estimated position\n",
        img(summary, 15, "Fig. 15 Experimental angular position [rad]"),
        img(summary, 16, "Fig. 16 Estimated angular position [rad]"),
        img(summary, 17, "Fig. 17 Position identification error [mrad]"),
        claim_block(summary, "position_error_converges"),
        claim_block(summary, "corner_error"),
        text + "\n",
    ]


def section_clusters(summary: dict[str, Any]) -> list[str]:
    """Why clusters matter (or not): CLPC against the global fits."""
    wins = [verdict_of(summary, "clusters", n) != NOT_REPRODUCED for n in ("ramp", "rich")]
    text = (
        "'CLPC on-line (held)' predicts with the parameters the appraiser held when the "
        "prediction is made (its time-varying model). Clusters pay off when the local "
        "linear model changes along the record."
    )
    if not any(wins):
        text += (
            " The simulated servo is linear enough at these amplitudes that one global "
            "LPC or least-squares fit on the whole record is as good or better. What the "
            "clusters do give here is the per-window diagnostics (D, the determined flag, "
            "degenerate windows) that show where the data carry information."
        )
    return [
        "## Why clusters matter (or not, here)\n",
        "\n".join(baseline_rows(summary)),
        "",
        claim_block(summary, "clusters"),
        text + "\n",
    ]
