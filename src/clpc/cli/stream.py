"""``clpc stream``: the appraiser on standard input, one JSON line per update."""

from __future__ import annotations

import json
import sys
from collections.abc import Iterator

import click

from clpc.cli.errors import ClpcCommand
from clpc.cli.options import (
    appraiser_options,
    appraiser_settings,
    collect,
    format_option,
    input_option,
    output_option,
    stream_sampling_options,
)
from clpc.workflows import StreamSettings, stream_samples

__all__ = ["stream"]


def _stdin_batches() -> Iterator[list[str]]:
    """Complete lines of standard input, in batches of what has arrived so far.

    ``read1`` returns what the pipe holds (at most 64 KiB) without waiting for more, so a
    slow producer gets its updates at once and a fast one is processed in vectorised batches.
    """
    raw = getattr(sys.stdin, "buffer", None)
    if raw is None or not hasattr(raw, "read1"):  # a text-only stream
        for line in iter(sys.stdin.readline, ""):
            yield [line]
        return
    rest = b""
    while block := raw.read1(1 << 16):
        lines = (rest + block).split(b"\n")
        rest = lines.pop()
        if lines:
            yield [line.decode("utf-8", errors="replace") for line in lines]
    if rest:
        yield [rest.decode("utf-8", errors="replace")]


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
@appraiser_settings()
@collect("settings", StreamSettings)
def stream(settings: StreamSettings) -> None:
    """Run the appraiser on samples from standard input; one JSON line per cluster update.

    Each input line is one sample: csv "u,y" (or "u1,u2,y1,y2" with --inputs 2
    --outputs 2), or jsonl {"u": 0.1, "y": 2.0} (lists for several channels). With
    --input/--output (and --time) the columns are chosen by header name or 0-based index
    (csv) or by key (jsonl, one number per key). Blank lines and lines starting with # are
    ignored; a first csv line of names is the header when it matches (reported on
    standard error). Each update is written at once (flushed) with index, time, theta,
    den, num, D, lambda_min, accepted, determined and the other statistics. A malformed
    line is reported on standard error with its line number, then skipped (--on-error
    skip) or ends the run with exit code 1 (--on-error stop). Exit code 1 as well when
    no valid sample arrived.

    \b
    Examples:
      my_daq | clpc stream --window-size 201 --cluster-size 12
      tail -f log.jsonl | clpc stream --format jsonl --inputs 2 --outputs 2
      cat log.csv | clpc stream -u volt -y pos --time t
    """  # noqa: D301
    skipped = samples = 0
    for batch in stream_samples(_stdin_batches(), settings):
        for message in batch.notes:
            click.echo(f"clpc stream: {message}", err=True)
        for message in batch.skipped:
            click.echo(f"clpc stream: {message} (skipped)", err=True)
        skipped += len(batch.skipped)
        samples += batch.samples
        if batch.records:
            sys.stdout.write("".join(json.dumps(r, allow_nan=False) + "\n" for r in batch.records))
            sys.stdout.flush()
    if skipped:
        click.echo(f"clpc stream: {skipped} malformed line(s) skipped", err=True)
    if not samples:
        raise click.ClickException(
            "no valid sample arrived on standard input; check the format (--format), the "
            "columns (--input/--output, --inputs/--outputs) and the lines reported above."
        )
