"""Where errors become exit codes: one line on standard error, no traceback.

Exit codes: 0 success, 1 a data or model error, 2 a usage error (unknown option, bad option
value, settings that contradict each other or the model).
"""

from __future__ import annotations

import io
import os
import sys
import warnings
from typing import Any

import click

__all__ = ["ClpcCommand", "ClpcGroup", "one_line", "user_errors"]


def user_errors() -> tuple[type[BaseException], ...]:
    """Library errors reported as one line with exit code 1.

    Imported here, when a command runs, so that ``clpc --help`` never imports the library.
    """
    from clpc.data import DataError
    from clpc.model import ModelError

    return (DataError, ModelError, OSError, ValueError, ImportError)


def one_line(exc: BaseException) -> str:
    """The message of ``exc`` on one line (its type name when it has none)."""
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


def _silence_stdout() -> None:
    """Point stdout at /dev/null so that the interpreter's final flush does not fail."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, io.UnsupportedOperation):  # no real file descriptor
        pass


def usage_message(exc: Exception) -> str:
    """A workflow's settings error in the words of the command line's options."""
    from clpc.workflows.common import ChannelCountError, SamplingConflictError

    if isinstance(exc, ChannelCountError):
        return (
            f"the model has {len(exc.model_names)} {exc.kind}(s) {exc.model_names}; "
            f"--{exc.kind} was given {len(exc.given)} time(s): {exc.given}."
        )
    if isinstance(exc, SamplingConflictError):
        return "pass either --dt or --time, not both."
    return one_line(exc)


class ClpcCommand(click.Command):
    """A command whose settings errors are usage errors (exit 2, with the usage line)."""

    def invoke(self, ctx: click.Context) -> Any:
        """Run the command; a :class:`SettingsError` becomes a :class:`click.UsageError`."""
        from clpc.workflows.common import SettingsError

        try:
            return super().invoke(ctx)
        except SettingsError as exc:
            raise click.UsageError(usage_message(exc), ctx) from None


class ClpcGroup(click.Group):
    """The top-level group: the one place where library errors become one-line messages."""

    def invoke(self, ctx: click.Context) -> Any:
        """Run the subcommand; library errors exit 1 with one line, a closed pipe quietly.

        A warning the library issues (e.g. dropped samples in a time column) is one line on
        stderr, ``warning: ...``, without Python's source location.
        """
        try:
            with warnings.catch_warnings():
                warnings.showwarning = _one_line_warning
                return super().invoke(ctx)
        except (click.ClickException, click.exceptions.Exit, click.exceptions.Abort):
            raise
        except BrokenPipeError:  # the reader went away (e.g. `clpc simulate ... | head`)
            _silence_stdout()
            ctx.exit(1)
        except user_errors() as exc:  # DataError, ModelError, FileNotFoundError, ValueError
            raise click.ClickException(one_line(exc)) from None


def _one_line_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: Any = None,
    line: str | None = None,
) -> None:
    """:func:`warnings.showwarning` for the command line: ``warning: <message>`` on stderr."""
    click.echo(f"warning: {message}", err=True)
