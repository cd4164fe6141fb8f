"""The options that say which record a command reads: file, columns, sampling.

Each declared once, as a decorator factory (the plumbing is :mod:`clpc.cli.options`);
:func:`record_settings` collects them into one :class:`~clpc.workflows.RecordSpec`.
"""

from __future__ import annotations

import click

from clpc.cli.options import Decorator, collect, combine
from clpc.data.time_units import TIME_UNITS
from clpc.data.timebase import DEFAULT_TIME_RTOL
from clpc.workflows import RecordSpec

__all__ = [
    "dt_option",
    "file_argument",
    "input_option",
    "output_option",
    "record_settings",
    "sampling_options",
    "stream_sampling_options",
    "time_base_options",
]


def file_argument() -> Decorator:
    """The data file ``FILE``."""
    return click.argument("file", type=click.Path(dir_okay=False))


def input_option(
    required: bool = True,
    help: str = "Input column (name, or 0-based index); repeat for several inputs.",
) -> Decorator:
    """``--input/-u COL`` (repeatable) into ``inputs``."""
    return click.option(
        "--input", "-u", "inputs", multiple=True, required=required, metavar="COL", help=help
    )


def output_option(
    required: bool = True, help: str = "Output column; repeat for several outputs."
) -> Decorator:
    """``--output/-y COL`` (repeatable) into ``outputs``."""
    return click.option(
        "--output", "-y", "outputs", multiple=True, required=required, metavar="COL", help=help
    )


def dt_option() -> Decorator:
    """``--dt``: the data's sample time."""
    return click.option(
        "--dt",
        type=click.FloatRange(min=0, min_open=True),
        default=None,
        help="Sample time of the data [s] (default 1, or from --time).",
    )


def time_base_options() -> Decorator:
    """``--time-unit`` and ``--time-rtol``: the one time-base rule of every command."""
    return combine(
        click.option(
            "--time-unit",
            type=click.Choice(list(TIME_UNITS)),
            default=None,
            help="Unit of the --time column (default: from its name, e.g. t_ms is ms; else s).",
        ),
        click.option(
            "--time-rtol",
            type=click.FloatRange(min=0, min_open=True),
            default=DEFAULT_TIME_RTOL,
            show_default=True,
            help="Largest relative deviation of one time step from the median step.",
        ),
    )


def time_column_option(help_text: str) -> Decorator:
    """``--time COL`` (into ``time_col``): the column of sample times.

    Parameters
    ----------
    help_text : str
        What the command does with the column (streams and files differ).
    """
    return click.option("--time", "time_col", metavar="COL", default=None, help=help_text)


def stream_sampling_options() -> Decorator:
    """``--dt``, ``--time COL`` (into ``time_col``), ``--time-unit``, ``--time-rtol``."""
    return combine(
        dt_option(),
        time_column_option(
            "Column of sample times; dt is the mean of its first steps; a gap is reported and "
            "the grid re-anchored, a stamp off the grid is a malformed line."
        ),
        time_base_options(),
    )


def sampling_options() -> Decorator:
    """The sampling options of a record read from a file.

    ``--dt``, ``--time COL`` (into ``time_col``), ``--time-unit``, ``--time-rtol``,
    ``--resample`` and ``--skip-rows``.
    """
    return combine(
        dt_option(),
        time_column_option(
            "Column of sample times; dt is its mean step (steps within --time-rtol; a gap of "
            "whole sample times is reported and the grid re-anchored)."
        ),
        time_base_options(),
        click.option(
            "--resample",
            is_flag=True,
            help="Interpolate onto a uniform time grid instead of refusing a jittery --time "
            "column (not for track).",
        ),
        click.option(
            "--skip-rows",
            type=click.IntRange(min=0),
            default=0,
            show_default=True,
            help="Lines to skip at the top of a text file (a metadata line); a units row "
            "under the header (s,m,V) is skipped without it.",
        ),
    )


def record_settings() -> Decorator:
    """Collect ``file``, ``inputs``, ``outputs``, ``dt``, ``time_col`` into ``record``."""
    return collect("record", RecordSpec)
