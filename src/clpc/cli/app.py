"""The ``clpc`` group, its commands and the console entry point."""

from __future__ import annotations

from collections.abc import Sequence

import click

from clpc._version import __version__
from clpc.cli.errors import ClpcGroup
from clpc.cli.identify import identify
from clpc.cli.info import datasets, demo
from clpc.cli.models import compare, simulate
from clpc.cli.multimodel import multimodel
from clpc.cli.stream import stream
from clpc.cli.track import track

__all__ = ["cli", "main"]


@click.group(cls=ClpcGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, "-V", "--version", prog_name="clpc")
def cli() -> None:
    """System identification with LPC (batch) and CLPC (the windowed appraiser).

    \b
    Examples:
      clpc datasets
      clpc identify dryer.csv --input u --output y --order auto --dt 0.08
      clpc track run.csv --input u --output y --out results/
      my_daq | clpc stream --window 201 --cluster 12
    """  # noqa: D301


for _command in (identify, track, stream, simulate, compare, datasets, demo, multimodel):
    cli.add_command(_command)


def main(argv: Sequence[str] | None = None) -> None:
    """Console entry point (``clpc``); ``argv`` defaults to ``sys.argv[1:]``."""
    cli.main(args=list(argv) if argv is not None else None, prog_name="clpc")
