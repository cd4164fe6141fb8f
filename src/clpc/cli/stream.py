"""``clpc stream``: the appraiser on standard input, one JSON line per update."""

from __future__ import annotations

import json
import os
import sys
from typing import Any

import click

from clpc.cli.errors import ClpcCommand, _silence_stdout
from clpc.cli.options import appraiser_options, appraiser_settings, collect, format_option
from clpc.cli.record_options import input_option, output_option, stream_sampling_options
from clpc.cli.stream_io import EXIT_CLOSED_PIPE, Interrupts, Stopped, stdin_batches
from clpc.workflows import StreamSettings
from clpc.workflows.stream_session import LineStream

__all__ = ["stream"]


@click.command(cls=ClpcCommand)
@appraiser_options()
@stream_sampling_options()
@input_option(
    required=False,
    help="Input column: csv name (from a header line) or 0-based index, or JSON key; "
    "repeat for several inputs (needs --output too).",
)
@output_option(required=False, help="Output column, as --input; repeat for several outputs.")
@click.option(
    "--inputs",
    "n_in",
    type=click.IntRange(min=1),
    default=1,
    show_default=True,
    help="Number of inputs per sample (without --input).",
)
@click.option(
    "--outputs",
    "n_out",
    type=click.IntRange(min=1),
    default=1,
    show_default=True,
    help="Number of outputs per sample (without --output).",
)
@format_option(["csv", "jsonl"], 'Lines "u1,...,y1,..." or {"u": ..., "y": ...}.')
@click.option(
    "--on-error",
    type=click.Choice(["skip", "stop"]),
    default="skip",
    show_default=True,
    help="A malformed line: report it and skip it, or exit 1.",
)
@click.option(
    "--state",
    "state_file",
    metavar="FILE",
    type=click.Path(dir_okay=False),
    default=None,
    help="Continue from the appraiser saved in FILE (if it exists; its settings are used) "
    "and save it there when the stream ends, fails or is stopped by a signal.",
)
@appraiser_settings()
@collect("settings", StreamSettings)
def stream(settings: StreamSettings, state_file: str | None) -> None:
    """Run the appraiser on samples from standard input; one JSON line per cluster update.

    Each input line is one sample: csv "u,y" (or "u1,u2,y1,y2" with --inputs 2
    --outputs 2), or jsonl {"u": 0.1, "y": 2.0} (lists for several channels). With
    --input/--output (and --time) the columns are chosen by header name or 0-based index
    (csv) or by key (jsonl, one number per key). Blank lines and lines starting with # are
    ignored; a first csv line of names is the header when it matches (reported on
    standard error). Each update is written at once (flushed) with index, time, theta,
    den, num, D, lambda_min, accepted, determined and the other statistics. A malformed
    line is reported on standard error with its line number, then skipped (--on-error
    skip) or ends the run with exit code 1 (--on-error stop); so is a last line without
    a newline (cut short). With --time, a gap (dropped samples) is reported once and the
    grid re-anchored; a stamp that goes back or lands between grid points is a malformed
    line; the unit comes from the column's name (t_ms is ms) or --time-unit. A line
    longer than CLPC_MAX_LINE_BYTES bytes (default 4 MiB) ends the run with exit code 1
    (the state is saved first), whatever --on-error says.

    \b
    Exit codes:
      0    the stream ended
      1    a data error, no valid sample, or no update because of the time column
      2    a usage error (options, columns the header lacks)
      129  stopped by SIGHUP, 130 by SIGINT, 143 by SIGTERM (state saved first)
      141  standard output was closed by its reader (e.g. | head)

    \b
    Examples:
      my_daq | clpc stream --window-size 201 --cluster-size 12
      tail -f log.jsonl | clpc stream --format jsonl --inputs 2 --outputs 2
      cat log.csv | clpc stream -u volt -y pos --time t
    """  # noqa: D301
    if sys.stdout is None:
        raise click.ClickException("standard output is closed; nowhere to write the updates.")
    appraiser = None
    if state_file is not None and os.path.exists(state_file):
        from clpc.appraiser import CLPC

        appraiser = CLPC.load(state_file)
    run = LineStream(settings, appraiser)
    with Interrupts() as stops:
        try:
            skipped, samples = _run(run, stops)
        except Stopped as stop:
            _save(run, state_file)
            click.echo(f"clpc stream: stopped by {stop.name}{_saved(run, state_file)}", err=True)
            sys.exit(stop.exit_code)
        except BrokenPipeError:
            _save(run, state_file)
            _silence_stdout()
            sys.exit(EXIT_CLOSED_PIPE)
        except Exception:
            _save(run, state_file)
            raise
    _save(run, state_file)
    if skipped:
        click.echo(f"clpc stream: {skipped} malformed line(s) skipped", err=True)
    if not samples:
        raise click.ClickException(
            "no valid sample arrived on standard input; check the format (--format), the "
            "columns (--input/--output, --inputs/--outputs) and the lines reported above."
        )
    problem = run.clock_problem()
    if problem:
        raise click.ClickException(problem)


def _run(run: LineStream, stops: Interrupts) -> tuple[int, int]:
    """Stream standard input through ``run``; the malformed lines and samples counted."""
    skipped = samples = 0
    for batch in run.run(stdin_batches(stops)):
        for message in batch.notes:
            click.echo(f"clpc stream: {message}", err=True)
        for message in batch.skipped:
            click.echo(f"clpc stream: {message} (skipped)", err=True)
        skipped += len(batch.skipped)
        samples += batch.samples
        if batch.records:
            sys.stdout.write("".join(json.dumps(r, allow_nan=False) + "\n" for r in batch.records))
            sys.stdout.flush()
        stops.check()
    return skipped, samples


def _save(run: LineStream, state_file: str | None) -> None:
    if state_file is not None and run.appraiser is not None:
        run.appraiser.save(state_file)


def _saved(run: LineStream, state_file: Any) -> str:
    if state_file is None or run.appraiser is None:
        return ""
    return f"; state saved to {state_file}"
