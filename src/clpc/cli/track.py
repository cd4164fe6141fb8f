"""``clpc track``: the CLPC appraiser over a file, with a progress bar."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import click

from clpc.cli.errors import ClpcCommand
from clpc.cli.options import (
    appraiser_options,
    appraiser_settings,
    collect,
    format_option,
    out_dir_option,
    save_option,
)
from clpc.cli.output import warn_unnamed_time
from clpc.cli.record_options import (
    file_argument,
    input_option,
    output_option,
    record_settings,
    sampling_options,
)
from clpc.report import format_model_summary
from clpc.workflows import (
    Chunk,
    ChunkFilter,
    TrackResult,
    TrackSettings,
    count_data_lines,
    track_file,
)

__all__ = ["track"]


def _progress_bar(file: str, skip_rows: int = 0) -> ChunkFilter:
    """Chunks passed on under a progress bar on standard error (rows of ``file``).

    On a terminal: click's bar; into a pipe or a file: one plain line per chunk
    (``tracking: 200000 of 1000000 rows (20%)``), which a log or ``tail -f`` can show.
    """

    def show(chunks: Iterator[Chunk]) -> Iterator[Chunk]:
        length = count_data_lines(file, skip_rows) or 0
        if not sys.stderr.isatty():
            done = 0
            for names, values in chunks:
                yield names, values
                done += values.shape[0]
                share = f" ({100 * done / length:.0f}%)" if length else ""
                total = f" of {length}" if length else ""
                click.echo(f"tracking: {done}{total} rows{share}", err=True)
            return
        with click.progressbar(length=length, label="tracking", file=sys.stderr) as bar:
            for names, values in chunks:
                yield names, values
                bar.update(values.shape[0])

    return show


def _print_result(result: TrackResult) -> None:
    summary, conv = result.summary, result.summary["convergence"]
    click.echo(
        f"{summary['updates']} updates: {summary['accepted']} accepted, "
        f"{summary['determined']} determined, {summary['not_enough_data']} with too few rows"
    )
    if summary["D_last"] is not None:
        d_last = ", ".join(f"{d:.6g}" for d in summary["D_last"] if d is not None)
        click.echo(f"D at the last update: {d_last}")
    if conv["converged"]:
        click.echo(
            f"converged at update {conv['update']} (sample {conv['index']}, t = {conv['time']:g} s)"
        )
    else:
        click.echo("did not converge (no quasi-constant phase)")
    for line in summary["findings"]:
        click.echo(f"  {line}")
    if summary.get("advice"):
        click.echo(summary["advice"])
    if summary["model"] is not None:
        click.echo(f"model ({result.model_source}):")
        click.echo(format_model_summary(summary["model"]))
    for f in result.files:
        click.echo(f"wrote {f}")


def _track_distributed(settings: TrackSettings, workers: int | None, scheduler: str | None) -> None:
    """The record split into pieces on a Dask cluster (``docs/distributed-long.md``)."""
    from clpc.distributed.track_command import track_settings
    from clpc.io import save_model
    from clpc.workflows.save_check import save_refusal

    def announce(line: str) -> None:
        click.echo(line, err=True)

    from clpc.distributed import dask_client

    with dask_client(None, scheduler, workers, announce) as client:
        result, done = track_settings(settings, client=client)
    refused = None
    if settings.save and result.model is not None:
        refused = save_refusal(result.model, settings.save)
        if refused is None:
            save_model(result.model, settings.save)
            result.files.append(Path(settings.save))
    _print_result(result)
    click.echo(f"({done.parts} pieces; the trace is a Parquet dataset, one file per piece)")
    if settings.save and result.model is None:
        raise click.ClickException(
            f"no update was accepted: there is no model to save to {settings.save}."
        )
    if refused:
        raise click.ClickException(refused)


@click.command(cls=ClpcCommand)
@file_argument()
@input_option()
@output_option()
@out_dir_option("Folder for trace, figures and report (created).")
@appraiser_options()
@sampling_options()
@format_option(["csv", "parquet"], "Format of the trace file.")
@click.option(
    "--chunk-rows",
    type=click.IntRange(min=1),
    default=100_000,
    show_default=True,
    help="Rows read from the file at a time.",
)
@click.option(
    "--progress/--no-progress",
    default=None,
    help="Progress on standard error: a bar on a terminal, one line per chunk into a pipe "
    "(default: only on a terminal).",
)
@click.option(
    "--workers",
    type=click.IntRange(min=1),
    default=None,
    help="Split the record (.npy or Parquet) over a local Dask cluster of N worker "
    "processes; the workers write OUT/trace/ as a Parquet dataset and OUT/summary.json.",
)
@click.option(
    "--scheduler",
    "scheduler",
    metavar="ADDRESS",
    default=None,
    help="As --workers, on the running Dask scheduler at ADDRESS (e.g. tcp://host:8786).",
)
@save_option("Save the steady-state model.")
@record_settings()
@appraiser_settings()
@collect("settings", TrackSettings)
def track(
    settings: TrackSettings, progress: bool | None, workers: int | None, scheduler: str | None
) -> None:
    """Run the CLPC appraiser over a record (read in chunks) and write a trace and a report.

    Writes OUT/trace.csv (one row per cluster update: theta, monic den/num, D, flags),
    OUT/report.html with its figures (trace, fit, data, step, bode, pz .png). Exits 1 when
    --save was asked for and no update was accepted (there is no model to save), and
    when the steady-state model is unstable (a pole beyond 1 + 5e-3: nothing is saved).

    \b
    Examples:
      clpc track servo.csv -u torque -y position --time t --out run1/
      clpc track big.parquet -u u -y y --dt 0.001 --decimate-to 0.01 --out run2/ --progress
    """  # noqa: D301
    warn_unnamed_time(settings.record)
    if workers is not None or scheduler is not None:
        _track_distributed(settings, workers, scheduler)
        return
    show = progress if progress is not None else sys.stderr.isatty()
    bar = _progress_bar(settings.record.file, settings.record.skip_rows) if show else None
    result = track_file(settings, bar)
    _print_result(result)
    if settings.save and result.model is None:
        raise click.ClickException(
            f"no update was accepted: there is no model to save to {settings.save} (the "
            "trace and the report were written); see the findings above."
        )
    if result.save_refused:
        raise click.ClickException(result.save_refused)
