"""The ``clpc`` command line (click)."""

from clpc.cli.commands import cli, main

__all__ = ["cli", "main"]
