"""``clpc identify``: a model of a file, structure and estimator chosen (or LPC alone)."""

from __future__ import annotations

import contextlib
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from clpc.cli.errors import ClpcCommand
from clpc.cli.options import (
    OrderType,
    collect,
    json_option,
    method_option,
    na_nb_options,
    save_option,
)
from clpc.cli.output import echo_json, warn_unnamed_time
from clpc.cli.record_options import (
    file_argument,
    input_option,
    output_option,
    record_settings,
    sampling_options,
)
from clpc.core.output_folder import OutputFolder
from clpc.lpc.reasons import pct
from clpc.lpc.selection import ESTIMATORS
from clpc.report import format_model_summary, write_identify_report
from clpc.report.identifiability import lead_lines
from clpc.report.text import estimator_name
from clpc.workflows import IdentifyResult, IdentifySettings, identify_file

__all__ = ["identify"]


def _selection_line(result: IdentifyResult) -> str:
    """The order selection table on one line."""
    assert result.selection is not None
    sel = result.selection
    if result.criterion == "validation":
        what = f"held-out score: mean of free-run and {sel.horizon}-step fit %, higher is better"
    else:
        what = f"{result.criterion.upper()}, lower is better"
    marks = [f" ({s})" if s == "unstable" else "" for s in sel.stability] or [""] * len(sel.orders)
    scores = result.scores()
    table = ", ".join(
        f"N={o}: {v:.1f}{m}" for o, v, m in zip(sel.orders, scores, marks, strict=True)
    )
    line = f"order selection ({what}): {table} -> N={sel.best}"
    return f"{line}\n  {sel.reason}" if sel.reason else line


def _delay_line(scan: dict[str, Any]) -> str:
    """LPC's delay scan on one line (``--estimator lpc --nk auto``)."""
    fits = ", ".join(  # a diverging fit is None in the JSON-safe summary
        f"nk={d}: {pct(-math.inf if v is None else v)}"
        for d, v in zip(scan["delays"], scan["validation_fit"], strict=True)
    )
    return (
        "delay selection (held-out k-step prediction fit %, the smallest delay within 1 point "
        f"of the best): {fits} -> nk={scan['best']}"
    )


class DelayType(click.ParamType):
    """``auto`` or an int >= 0."""

    name = "NK|auto"

    def convert(
        self, value: Any, param: click.Parameter | None, ctx: click.Context | None
    ) -> int | str:
        """``"auto"``, or the delay as an int (a usage error otherwise)."""
        if str(value).strip().lower() == "auto":
            return "auto"
        try:
            nk = int(str(value))
        except ValueError:
            self.fail(f"must be an int >= 0 or 'auto'; got {value!r}.", param, ctx)
        if nk < 0:
            self.fail(f"must be an int >= 0 or 'auto'; got {nk}.", param, ctx)
        return nk


def _comparison_lines(result: IdentifyResult) -> list[str]:
    """The estimator comparison: one line per candidate and output, then the reason."""
    found = result.comparison
    assert found is not None
    many = len({r["output"] for r in found.table}) > 1
    lines = [
        "estimator comparison (fitted on the record before each origin at 1/2, 2/3 and 0.8 of "
        f"it, scored on all after it; mean free run and {found.horizon}-step prediction fit %, "
        "higher is better):"
    ]
    for r in found.table:
        out = f" {r['output']}" if many else ""
        mark = "  <- chosen" if r["chosen"] else ""
        note = f"  ({r['note']})" if r["note"] else ""
        lines.append(
            f"  {r['estimator'].upper():<8} na={r['na']} nb={r['nb']} nk={r['nk']}{out}: free "
            f"run {pct(r['free_run'])}, {found.horizon}-step {pct(r['kstep'])}, "
            f"{r['stability']}{mark}{note}"
        )
    lines.append(f"  reason: {found.reason}")
    return lines


@click.command(cls=ClpcCommand)
@file_argument()
@input_option()
@output_option()
@click.option(
    "--order",
    "-n",
    type=OrderType(),
    default="auto",
    show_default=True,
    help="Model order N (na = nb = N), or 'auto': na 1..--max-order and nb 0..--max-order "
    "screened independently (with --estimator lpc: N by --criterion).",
)
@click.option(
    "--max-order",
    type=click.IntRange(min=1),
    default=10,
    show_default=True,
    help="Largest order tried by --order auto.",
)
@click.option(
    "--criterion",
    type=click.Choice(["validation", "bic", "aic", "remark1"]),
    default="validation",
    show_default=True,
    help="How --estimator lpc --order auto chooses: on the last third held out, the mean of "
    "the free-run and the k-step prediction fit (k: one dominant time constant), unstable "
    "orders rejected (validation); BIC, AIC or the paper's Remark 1.",
)
@na_nb_options()
@click.option(
    "--nk",
    type=DelayType(),
    default="auto",
    show_default=True,
    help="Input delay in samples (0: b0 acts at once, as in the paper; a physical plant with "
    "no direct feed-through has nk >= 1, as MATLAB's default), or 'auto' (0..--max-delay "
    "compared on held-out data).",
)
@click.option(
    "--max-delay",
    type=click.IntRange(min=0),
    default=5,
    show_default=True,
    help="Largest delay tried by --nk auto.",
)
@click.option(
    "--estimator",
    type=click.Choice(ESTIMATORS),
    default="auto",
    show_default=True,
    help="auto: screen the structures by least squares, compare least squares (arx), LPC, "
    "output error (oe) and subspace models on held-out data, print the table and the reason, "
    "keep the best; arx, oe or subspace: the same, keeping that one; lpc: the paper's LPC "
    "alone, no comparison.",
)
@method_option()
@click.option(
    "--mimo",
    type=click.Choice(["miso", "paired"]),
    default=None,
    help="Multi-channel structure (default miso; paired = output j on input j).",
)
@sampling_options()
@json_option()
@save_option("Save the model (load it again with clpc simulate/compare).")
@click.option(
    "--report",
    type=click.Path(file_okay=False),
    default=None,
    help="Also write an HTML report with figures to this folder (REPORT/report.html).",
)
@record_settings()
@collect("settings", IdentifySettings)
def identify(settings: IdentifySettings, as_json: bool, report: str | None) -> None:
    """Identify a linear model -B(z)/A(z) from a record: structure and estimator chosen.

    By default the orders na, nb and the delay nk are screened by least squares; least
    squares, LPC, output error and subspace models are compared on held-out data at the best
    structures, and the best is kept (the table and the reason are printed; a progress line
    per stage on a terminal). --estimator lpc fits the paper's LPC alone. Then: what the
    record cannot decide (an input not persistently exciting of the order, an undetermined
    DC gain) first, the monic transfer function (powers of z^-1), the DC gains +- one sigma,
    the poles (the dominant ones in rad/s, Hz, damping, time constants) and stability, the
    fit % of the free-run simulation and of 1- and 10-step predictions on the same data,
    and the verdict.

    \b
    Examples:
      clpc identify dryer.csv --input u --output y --dt 0.08
      clpc identify run.csv -u torque -y position --time t --save m.json
      clpc identify arm.csv -u u1 -u u2 -y y1 -y y2 --json
      clpc identify dryer.csv -u u -y y --estimator lpc --order 2 --nk 0
    """  # noqa: D301
    # the report's folder is locked first: a second run into it is refused before fitting
    folder = OutputFolder(report, "--report") if report else None
    warn_unnamed_time(settings.record)
    with folder if folder is not None else contextlib.nullcontext():
        result = identify_file(settings, _progress())
        if as_json:
            echo_json(result.summary)
            return
        for line in lead_lines(result.summary):  # what the data cannot decide, first
            click.echo(line)
        if result.comparison is not None:
            click.echo("\n".join(_comparison_lines(result)))
        if "delay_selection" in result.summary:
            click.echo(_delay_line(result.summary["delay_selection"]))
        if result.selection is not None:
            click.echo(_selection_line(result))
        click.echo(format_model_summary(result.summary, lead=False))
        if settings.save:
            click.echo(f"model saved to {settings.save}")
        if folder is not None:
            click.echo(f"wrote {_write_report(settings, result, folder)}")


def _progress() -> Callable[[str], None] | None:
    """One line per stage on stderr when it is a terminal (``None`` otherwise)."""
    if not sys.stderr.isatty():
        return None
    start = time.perf_counter()

    def say(line: str) -> None:
        click.echo(f"[{time.perf_counter() - start:5.1f} s] {line}", err=True)

    return say


def _write_report(settings: IdentifySettings, result: IdentifyResult, out: OutputFolder) -> Any:
    """The HTML report of a fit (:func:`clpc.report.write_identify_report`), committed."""
    record = settings.record
    shown = {
        "file": record.file,
        "estimator": settings.estimator,
        "order": settings.order,
        "nk": settings.nk,
        "method": settings.method,
        "mimo": settings.mimo,
        "criterion": settings.criterion if not settings.compares else None,
    }
    files = write_identify_report(
        out.staging,
        result.model,
        record.load(),
        title=f"identify report ({estimator_name(result.summary)} model): {Path(record.file).name}",
        settings=shown,
        selection=result.summary.get("order_selection"),
        comparison=result.comparison,
    )
    out.commit()  # one run's files, all complete, or the previous run's untouched
    return out.final(files[-1])
