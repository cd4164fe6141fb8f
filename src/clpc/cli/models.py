"""``clpc simulate`` and ``clpc compare``: a saved model on new data."""

from __future__ import annotations

import sys

import click

from clpc.cli.errors import ClpcCommand
from clpc.cli.options import collect, json_option, model_argument
from clpc.cli.output import echo_json, write_csv
from clpc.cli.record_options import (
    file_argument,
    input_option,
    output_option,
    record_settings,
    sampling_options,
)
from clpc.report import format_fit
from clpc.workflows import CompareSettings, compare_file, simulate_file

__all__ = ["compare", "simulate"]


@click.command(cls=ClpcCommand)
@model_argument()
@file_argument()
@input_option(
    required=False,
    help="Input column(s), in the model's input order (default: the model's names).",
)
@click.option(
    "--out",
    "-o",
    type=click.Path(dir_okay=False),
    default=None,
    help="Write the simulation here (csv, tsv, parquet, npy, npz); default stdout.",
)
@click.option(
    "--time",
    "time_col",
    metavar="COL",
    default=None,
    help="A time column to keep (written first, unchanged).",
)
def simulate(
    model_file: str, file: str, inputs: tuple[str, ...], out: str | None, time_col: str | None
) -> None:
    """Simulate a saved model on the input columns of FILE (free run, zero initial state).

    Writes the input columns and one simulated column per output (named OUTPUT_sim).

    \b
    Examples:
      clpc simulate model.json new_inputs.csv --input u --out sim.csv
      clpc simulate model.json new_inputs.csv > sim.csv
      clpc simulate model.json log.csv --input u --time t > sim.csv
    """  # noqa: D301
    result = simulate_file(model_file, file, inputs, out, time_col)
    if out:
        click.echo(f"wrote {out} ({result.values.shape[0]} rows)", err=True)
    else:
        write_csv(result.names, result.values)


@click.command(cls=ClpcCommand)
@model_argument()
@file_argument()
@input_option(required=False, help="Input column(s) (default: the model's input names).")
@output_option(
    required=False, help="Measured output column(s) (default: the model's output names)."
)
@click.option(
    "--k",
    "k",
    type=click.IntRange(min=1),
    default=None,
    help="Compare k-step-ahead predictions (default: free-run simulation).",
)
@sampling_options()
@click.option(
    "--plot",
    type=click.Path(dir_okay=False),
    default=None,
    metavar="PNG",
    help="Also plot measured vs model to this PNG file.",
)
@json_option()
@record_settings()
@collect("settings", CompareSettings)
def compare(settings: CompareSettings, as_json: bool) -> None:
    """Compare a saved model with measured data: fit % of simulation or k-step prediction.

    The first max-lag samples give the initial conditions; the fit % (100 = perfect,
    0 = as good as the mean) is computed over the rest. Data whose --dt or --time says
    they are sampled at another rate than the model's are refused; a response that diverges
    exits 1. MODEL.json may also be a multi-model (clpc multimodel --save): it names no
    columns, so give -u per input and -y.

    \b
    Examples:
      clpc compare model.json validation.csv --input uVal --output yVal
      clpc compare multimodel.json validation.csv -u command -y position
      clpc compare model.json validation.csv -u uVal -y yVal --k 10 --plot cmp.png
    """  # noqa: D301
    result = compare_file(settings)
    diverged = [name for name, fit in result.fit.items() if fit is None]
    if as_json:
        echo_json(result.to_dict())
        _exit_if_diverged(diverged, result.compared)
        return
    last = result.n_samples - 1
    for name, fit in result.fit.items():
        click.echo(
            f"fit of {result.compared}, {name}: {format_fit(fit)}  "
            f"(samples {result.first_sample}..{last})"
        )
    if result.plot:
        click.echo(f"wrote {result.plot}")
    _exit_if_diverged(diverged, result.compared)


def _exit_if_diverged(names: list[str], compared: str) -> None:
    """A comparison whose response diverges failed: say so and exit 1."""
    if names:
        click.echo(
            f"Error: the model's {compared} diverges on this record (output(s) {names}): "
            "there is no fit to report.",
            err=True,
        )
        sys.exit(1)
