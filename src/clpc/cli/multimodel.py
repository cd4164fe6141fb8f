"""``clpc multimodel``: local LPC models blended by validity functions (issue 18)."""

from __future__ import annotations

import click

from clpc.cli.errors import ClpcCommand
from clpc.cli.options import json_option
from clpc.cli.output import echo_json
from clpc.cli.record_options import file_argument, input_option, output_option, sampling_options
from clpc.workflows.common import RecordSpec
from clpc.workflows.multimodel import MultiModelSettings, multimodel_file

__all__ = ["multimodel"]


@click.command(cls=ClpcCommand)
@file_argument()
@input_option()
@output_option(help="Output column (one).")
@sampling_options()
@click.option(
    "--order",
    "-n",
    type=click.IntRange(min=1),
    default=2,
    show_default=True,
    help="Order N of every local model (na = nb = N).",
)
@click.option(
    "--models",
    "n_models",
    type=click.IntRange(min=1),
    default=None,
    help="Number of local models (default: chosen by held-out free-run fit).",
)
@click.option(
    "--max-models",
    type=click.IntRange(min=1),
    default=8,
    show_default=True,
    help="Largest number of local models tried.",
)
@click.option(
    "--schedule",
    default="y",
    show_default=True,
    help="Scheduling variable: y (y(n-1)), u (u(n)) or a lag-vector column index.",
)
@click.option(
    "--save",
    type=click.Path(dir_okay=False),
    default=None,
    metavar="MODEL.json",
    help="Save the multi-model (clpc.MultiModel.load reads it back).",
)
@click.option(
    "--figure",
    type=click.Path(dir_okay=False),
    default=None,
    metavar="FIG.png",
    help="Draw local DC gain, pole frequencies and validity functions.",
)
@json_option()
def multimodel(
    file: str,
    inputs: tuple[str, ...],
    outputs: tuple[str, ...],
    dt: float | None,
    time_col: str | None,
    time_unit: str | None,
    time_rtol: float,
    resample: bool,
    skip_rows: int,
    order: int,
    n_models: int | None,
    max_models: int,
    schedule: str,
    save: str | None,
    figure: str | None,
    as_json: bool,
) -> None:
    """Identify a nonlinear plant as local LPC models of an operating point.

    \b
    Example:
      clpc multimodel run.csv -u command -y position --dt 0.01 --save mm.json --figure mm.png
    """  # noqa: D301
    record = RecordSpec(
        file,
        tuple(inputs),
        tuple(outputs),
        dt,
        time_col,
        time_unit=time_unit,
        time_rtol=time_rtol,
        resample=resample,
        skip_rows=skip_rows,
    )
    settings = MultiModelSettings(record, order, n_models, max_models, schedule, save, figure)
    summary = multimodel_file(settings)
    if as_json:
        echo_json(summary)
        return
    click.echo(
        f"{summary['n_models']} local model(s) on {summary['schedule']} "
        f"({summary['estimator']}; {summary['chosen_by']})"
    )
    click.echo(f"centres from the {summary['centre_source']}: {summary['centre_reason']}")
    for i, (c, m) in enumerate(zip(summary["centres"], summary["local_models"], strict=True)):
        flag = " [unstable LPC replaced by least squares]" if m["replaced"] else ""
        click.echo(f"  model {i}: centre {c:.4g}, DC gain {m['dc_gain']:.4g}{flag}")
    fits = summary["fit_on_record"]
    click.echo(
        f"fit on the record (free run / 10-step %): multi-model "
        f"{fits['multimodel']['free_run']:.2f} / {fits['multimodel']['k10']:.2f}; one global "
        f"least-squares model {fits['global_least_squares']['free_run']:.2f} / "
        f"{fits['global_least_squares']['k10']:.2f}"
    )
    for key in ("saved", "figure"):
        if key in summary:
            click.echo(f"{key}: {summary[key]}")
