"""``clpc identify``: batch LPC on a file."""

from __future__ import annotations

import click

from clpc.cli.errors import ClpcCommand
from clpc.cli.options import (
    OrderType,
    collect,
    file_argument,
    input_option,
    json_option,
    method_option,
    nk_option,
    output_option,
    record_settings,
    sampling_options,
    save_option,
)
from clpc.cli.output import echo_json
from clpc.report import format_model_summary
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


@click.command(cls=ClpcCommand)
@file_argument()
@input_option()
@output_option()
@click.option(
    "--order",
    "-n",
    type=OrderType(),
    default="2",
    show_default=True,
    help="Model order N (na = nb = N), or 'auto' (see --criterion, over 1..--max-order).",
)
@click.option(
    "--max-order",
    type=click.IntRange(min=1),
    default=6,
    show_default=True,
    help="Largest order tried by --order auto.",
)
@click.option(
    "--criterion",
    type=click.Choice(["validation", "bic", "aic", "remark1"]),
    default="validation",
    show_default=True,
    help="How --order auto chooses: on the last third held out, the mean of the free-run "
    "and the k-step prediction fit (k: one dominant time constant), unstable orders "
    "rejected (validation); BIC, AIC or the paper's Remark 1.",
)
@nk_option()
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
    type=click.Path(dir_okay=False),
    default=None,
    metavar="REPORT.html",
    help="Write an HTML report: model, parameters +- sigma, residual analysis, Bode plot.",
)
@record_settings()
@collect("settings", IdentifySettings)
def identify(settings: IdentifySettings, as_json: bool) -> None:
    """Identify a linear model -B(z)/A(z) from a record with batch LPC.

    Prints the monic transfer function (powers of z^-1), poles and stability, the degree of
    linearity D, the fit % of the free-run simulation and of 1- and 10-step predictions on
    the same data, and whether the data determine the model.

    \b
    Examples:
      clpc identify dryer.csv --input u --output y --order 2 --dt 0.08
      clpc identify run.csv -u torque -y position --order auto --time t --save m.json
      clpc identify arm.csv -u u1 -u u2 -y y1 -y y2 --json
    """  # noqa: D301
    result = identify_file(settings)
    if as_json:
        echo_json(result.summary)
        return
    if result.selection is not None:
        click.echo(_selection_line(result))
    click.echo(format_model_summary(result.summary))
    if settings.save:
        click.echo(f"model saved to {settings.save}")
    if settings.report:
        click.echo(f"report written to {settings.report}")
