"""The ``clpc`` group, its commands and the console entry point.

Commands are imported when they run (or when their own ``--help`` is asked for), not when
the group is built: ``clpc --help`` reads each command's one-line summary from its module's
source (its docstring, parsed with :mod:`ast`), so it starts without numpy's or scipy's
import time.
"""

from __future__ import annotations

import ast
import functools
import gc
import importlib
import importlib.util
from collections.abc import Sequence

import click

from clpc._version import __version__
from clpc.cli.errors import ClpcGroup

__all__ = ["COMMANDS", "cli", "main", "run"]

#: command name -> (module, attribute) of its click command, in the order of ``clpc --help``
COMMANDS: dict[str, tuple[str, str]] = {
    "identify": ("clpc.cli.identify", "identify"),
    "track": ("clpc.cli.track", "track"),
    "track-many": ("clpc.cli.track_many", "track_many"),
    "stream": ("clpc.cli.stream", "stream"),
    "simulate": ("clpc.cli.models", "simulate"),
    "compare": ("clpc.cli.models", "compare"),
    "datasets": ("clpc.cli.info", "datasets"),
    "demo": ("clpc.cli.info", "demo"),
    "multimodel": ("clpc.cli.multimodel", "multimodel"),
}


@functools.cache
def command_docstring(name: str) -> str:
    """The docstring of command ``name``'s function, read from its source without importing it.

    Returns ``""`` when the source cannot be read (the summary then comes from the command).
    """
    module, attribute = COMMANDS[name]
    spec = importlib.util.find_spec(module)
    if spec is None or spec.origin is None:
        return ""
    try:
        with open(spec.origin, encoding="utf-8") as handle:
            tree = ast.parse(handle.read())
    except (OSError, SyntaxError):
        return ""
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name == attribute:
            return ast.get_docstring(node) or ""
    return ""


class LazyGroup(ClpcGroup):
    """A group whose subcommands are imported on first use (see :data:`COMMANDS`)."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        """Every command name (sorted, as click lists them)."""
        return sorted({*COMMANDS, *self.commands})

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        """The command ``cmd_name``, importing its module the first time."""
        if cmd_name not in self.commands and cmd_name in COMMANDS:
            module, attribute = COMMANDS[cmd_name]
            self.add_command(getattr(importlib.import_module(module), attribute), cmd_name)
        return self.commands.get(cmd_name)

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        """The command list of ``clpc --help`` from the docstrings, without imports."""
        names = self.list_commands(ctx)
        limit = formatter.width - 6 - max(len(name) for name in names)
        rows = []
        for name in names:
            doc = command_docstring(name) if name in COMMANDS else ""
            if doc:
                text = click.Command(name, help=doc).get_short_help_str(limit)
            else:
                command = self.get_command(ctx, name)
                if command is None or command.hidden:
                    continue
                text = command.get_short_help_str(limit)
            rows.append((name, text))
        with formatter.section("Commands"):
            formatter.write_dl(rows)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, "-V", "--version", prog_name="clpc")
def cli() -> None:
    """System identification with LPC (batch) and CLPC (the windowed appraiser).

    \b
    Examples:
      clpc datasets
      clpc identify dryer.csv --input u --output y --dt 0.08
      clpc track run.csv --input u --output y --out results/
      my_daq | clpc stream --window-size 201 --cluster-size 12
    """  # noqa: D301


def main(argv: Sequence[str] | None = None) -> None:
    """Run the command line in this interpreter; ``argv`` defaults to ``sys.argv[1:]``.

    Raises :class:`SystemExit` with the exit status, as click does.
    """
    cli.main(args=list(argv) if argv is not None else None, prog_name="clpc")


def run() -> None:
    """The process's entry point (``clpc``, ``python -m clpc``): :func:`main`.

    Raises :class:`SystemExit` with the exit status; the interpreter then exits normally
    (exit handlers, flushed streams, modules torn down). Before that the objects alive are
    moved out of the cyclic garbage collector's reach (:func:`gc.freeze`): its last passes
    over numba's, scipy's and matplotlib's objects took 0.3-1.4 s of a command's exit and
    free nothing the process still needs (every file clpc writes is closed by then).
    """
    try:
        main()
    finally:
        gc.freeze()
