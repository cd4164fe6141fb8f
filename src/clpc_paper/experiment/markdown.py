"""Markdown building blocks of the experiment report: figures, claims, tables.

Each function reads the JSON-safe summary of :func:`clpc_paper.experiment.run_experiment` and
returns Markdown text.
"""

from __future__ import annotations

from typing import Any

from clpc_paper.experiment.claims import claim_row, fmt, fmt_poles

__all__ = [
    "baseline_rows",
    "claim_block",
    "img",
    "model_row",
    "setup_table",
    "verdict_table",
    "yes",
]


def img(summary: dict[str, Any], number: int | str, caption: str) -> str:
    """A figure of the report with its caption and file name."""
    name = summary["figures"][str(number)]
    return f"![{caption}]({name})\n\n*{caption}* (`{name}`)\n"


def claim_block(summary: dict[str, Any], key: str) -> str:
    """Claim ``key``: the paper's words, its criterion and why, and the verdicts.

    Per command: the verdict, the measured numbers and, when not reproduced, why.
    """
    row = claim_row(summary, key)
    lines = [f"> **Paper:** {row['paper']}.\n"]
    first = next((row[n] for n in ("ramp", "rich") if n in row), None)
    if first is not None and "criterion" in first:
        lines.append(f"**Criterion:** {first['criterion']} - *why:* {first['why']}.\n")
    for name in ("ramp", "rich"):
        if name in row:
            res = row[name]
            text = f"- **{name}** - *{res['verdict']}*: {res['numbers']}."
            if res.get("reason"):
                text += f" **Why not:** {res['reason']}."
            lines.append(text)
    return "\n".join(lines) + "\n"


def model_row(label: str, m: dict[str, Any]) -> str:
    """One row of the steady-state models table."""
    poles = fmt_poles(m["poles"])
    zeros = ", ".join(
        f"{re:.3g}{im:+.3g}j" if abs(im) > 1e-9 else f"{re:.3g}" for re, im in m["zeros"]
    )
    den = ", ".join(f"{v:.4f}" for v in m["den"])
    num = ", ".join(f"{v:.4g}" for v in m["num"])
    return (
        f"| {label} | [{den}] | [{num}] | {poles} | {zeros} | {fmt(m['dc_gain'], '.4g')} "
        f"| {'yes' if m['stable'] else 'no'} |"
    )


def baseline_rows(summary: dict[str, Any]) -> list[str]:
    """The fit table: CLPC (steady state, on-line) against the global fits."""
    rows = [
        "| record | identification | metric | CLPC steady state | CLPC on-line (held) "
        "| global LPC | least squares | global LPC, N = 1 |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, cmd in summary["commands"].items():
        for ident, metrics in (
            ("control system", ("simulation_fit", "k1_fit", "k10_fit")),
            ("actuator", ("k1_fit", "k10_fit")),
        ):
            b = cmd["control_system" if ident == "control system" else "actuator"]["baselines"]
            for metric in metrics:
                cells = [
                    fmt(b[k].get(metric), ".2f") if k in b else "-"
                    for k in ("clpc", "clpc_online", "lpc", "arx", "lpc_order1")
                ]
                label = {
                    "simulation_fit": "free-run fit %",
                    "k1_fit": "1-step fit %",
                    "k10_fit": "10-step fit %",
                }[metric]
                rows.append(f"| {name} | {ident} | {label} | " + " | ".join(cells) + " |")
    return rows


def setup_table(summary: dict[str, Any]) -> str:
    """The set-up table: Table 1 of the paper beside the settings used here."""
    s = summary["settings"]
    ramp, rich = s["ramp"], s["rich"]
    tol = "; ".join(f"({t[0]}, {t[1]}, {t[2]})" for t in s["tolerances"])
    return f"""| setting | paper (Table 1) | here |
|---|---|---|
| sample time | 10 ms | {1e3 * s["sample_time"]:.0f} ms (appraiser); servo logged at \
{1e3 * s["log_sample_time"]:.0f} ms, anti-alias filtered and decimated by the appraiser |
| parameter_size | 3 (N = 2) | {s["parameters_size"]} |
| window_size | 201 samples (2 s) | {s["window_size"]} samples ({s["window_time"]:.1f} s) |
| data_cluster_dimension | 12 samples | {s["cluster_size"]} samples |
| LPC solution | eigenvector of the smallest eigenvalue | `method="{s["method"]}"`, \
`scaling="{s.get("scaling", "none")}"` (the library's default: total least squares in the \
data's units), every computable estimate accepted (`guard=False`: the paper's appraiser; the \
library's default guard would accept only trusted windows) |
| command | ramp with saturation (Fig. 5) | ramp 0 -> {ramp["level"]} rad from \
{ramp["start"]} s to {ramp["start"] + ramp["ramp_time"]:.1f} s, then held; \
{ramp["duration"]:.1f} s record |
| richer command | - | ramp-and-hold moves {rich["positions"][0]} <-> {rich["positions"][1]} rad \
({rich["max_velocity"]} rad/s, {rich["max_acceleration"]} rad/s^2, {rich["dwell"]} s dwell: a 2 s \
period, the window length) + PRBS dither {rich["dither"]["amplitude"]} rad, \
{rich["dither"]["min_hold"]} s minimum hold; {rich["duration"]:.0f} s record |
| convergence tolerances | "quasi constant" | (theta_tol, D_tol, consecutive) tried in order, \
trusted updates only: {tol}; none met -> last trusted update |
| servo log | - | torque logged as its mean over each 1 ms (what the motor integrates) |

Seed {s["seed"]}; quick = {s["quick"]}; run time {summary["runtime_s"]:.1f} s.
"""


def verdict_table(summary: dict[str, Any]) -> str:
    """One row per claim: the verdict for each command (beside the claim), figures, criterion."""
    rows = [
        "| paper's claim | ramp (Fig. 5) | rich command | figures | criterion |",
        "|---|---|---|---|---|",
    ]
    for c in summary["claims"]:
        figs = ", ".join(str(f) for f in c["figures"]) or "-"
        columns = ("ramp", "rich") if "ramp" in c or "rich" in c else _other_columns(c)
        cells = [_cell(c, n, columns) for n in columns]
        crit = _criteria(c, columns).replace("|", "\\|")  # a cell: escape the bars
        cells += ["-"] * (2 - len(cells))
        rows.append(f"| {c['paper']} | {cells[0]} | {cells[1]} | {figs} | {crit} |")
    return "\n".join(rows) + "\n"


def _criteria(claim: dict[str, Any], columns: tuple[str, ...]) -> str:
    """The claim's criterion, or each scenario's when they differ (e.g. a negative control)."""
    crits = {n: claim[n]["criterion"] for n in columns if "criterion" in claim.get(n, {})}
    if len(set(crits.values())) > 1:
        return "; ".join(f"{n}: {v}" for n, v in crits.items())
    return next(iter(crits.values()), "-")


def _other_columns(claim: dict[str, Any]) -> tuple[str, ...]:
    """The scenario keys of a claim judged on other records than the ramp and rich command."""
    return tuple(k for k, v in claim.items() if isinstance(v, dict) and "verdict" in v)[:2]


def _cell(claim: dict[str, Any], name: str, columns: tuple[str, ...]) -> str:
    """A verdict cell, prefixed with its scenario when it is not the column's own command."""
    if name not in claim:
        return "-"
    verdict = claim[name]["verdict"]
    return verdict if columns == ("ramp", "rich") else f"{name}: {verdict}"


def yes(flag: bool, yes: str, no: str) -> str:
    """``yes`` if ``flag`` else ``no``."""
    return yes if flag else no
