"""The options that several commands share, each declared once (as decorator factories).

:func:`collect` turns the keyword arguments click passes into one settings dataclass, so
that a command function receives typed settings instead of a dozen options.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from typing import Any

import click

from clpc.data.time_units import TIME_UNITS
from clpc.data.timebase import DEFAULT_TIME_RTOL
from clpc.workflows import AppraiserSettings, RecordSpec

__all__ = [
    "Decorator",
    "OrderType",
    "appraiser_options",
    "appraiser_settings",
    "collect",
    "combine",
    "dt_option",
    "file_argument",
    "format_option",
    "input_option",
    "json_option",
    "method_option",
    "model_argument",
    "na_nb_options",
    "nk_option",
    "out_dir_option",
    "output_option",
    "record_settings",
    "sampling_options",
    "save_option",
    "stream_sampling_options",
    "time_base_options",
]

Decorator = Callable[[Callable[..., Any]], Callable[..., Any]]


def combine(*decorators: Decorator) -> Decorator:
    """Several decorators as one (the first given is the outermost, as when stacked)."""

    def apply(func: Callable[..., Any]) -> Callable[..., Any]:
        for decorator in reversed(decorators):
            func = decorator(func)
        return func

    return apply


def collect(name: str, factory: Callable[..., Any]) -> Decorator:
    """Replace the keyword arguments named like ``factory``'s parameters by one: ``name``.

    Stack it just above the command function; a ``collect`` higher up runs first, so its
    product can be a parameter of a lower one (e.g. ``record`` of ``IdentifySettings``).
    """
    params = list(inspect.signature(factory).parameters)

    def decorate(func: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(func)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            values = {p: kwargs.pop(p) for p in params if p in kwargs}
            return func(*args, **kwargs, **{name: factory(**values)})

        return wrapper

    return decorate


class OrderType(click.ParamType):
    """``auto`` or an int >= 1."""

    name = "N|auto"

    def convert(
        self, value: Any, param: click.Parameter | None, ctx: click.Context | None
    ) -> int | str:
        """``"auto"``, or the order as an int (a usage error otherwise)."""
        if isinstance(value, int) and not isinstance(value, bool):
            order = value
        elif str(value).strip().lower() == "auto":
            return "auto"
        else:
            try:
                order = int(str(value))
            except ValueError:
                self.fail(f"must be an int >= 1 or 'auto'; got {value!r}.", param, ctx)
        if order < 1:
            self.fail(f"must be an int >= 1 or 'auto'; got {order}.", param, ctx)
        return order


# ============================================================================ arguments
def file_argument() -> Decorator:
    """The data file ``FILE``."""
    return click.argument("file", type=click.Path(dir_okay=False))


def model_argument() -> Decorator:
    """The saved model ``MODEL.json``."""
    return click.argument("model_file", metavar="MODEL.json", type=click.Path(dir_okay=False))


# ============================================================================ columns
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


def stream_sampling_options() -> Decorator:
    """``--dt``, ``--time COL`` (into ``time_col``), ``--time-unit``, ``--time-rtol``."""
    return combine(
        dt_option(),
        click.option(
            "--time",
            "time_col",
            metavar="COL",
            default=None,
            help="Column of sample times; dt is the mean of its first steps; a gap is "
            "reported and the grid re-anchored, a stamp off the grid is a malformed line.",
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
        click.option(
            "--time",
            "time_col",
            metavar="COL",
            default=None,
            help="Column of sample times; dt is its mean step (steps uniform within --time-rtol).",
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


# ============================================================================ estimation
def method_option(help: str | None = "LPC solution (see clpc.LPC).") -> Decorator:
    """``--method robust|paper``."""
    return click.option(
        "--method",
        type=click.Choice(["robust", "paper"]),
        default="robust",
        show_default=True,
        help=help,
    )


def na_nb_options() -> Decorator:
    """``--na`` and ``--nb``: the orders of A and B, each overriding ``--order`` for its own."""
    return combine(
        click.option(
            "--na",
            type=click.IntRange(min=1),
            default=None,
            help="Output order (A has na + 1 coefficients); overrides --order for A.",
        ),
        click.option(
            "--nb",
            type=click.IntRange(min=0),
            default=None,
            help="Input order (each B has nb + 1 coefficients: MATLAB's arx nb is this + 1); "
            "overrides --order for B.",
        ),
    )


def nk_option() -> Decorator:
    """``--nk``: the input delay."""
    return click.option(
        "--nk",
        type=click.IntRange(min=0),
        default=0,
        show_default=True,
        help="Input delay in samples (0: b0 acts at once, as in the paper; a physical plant "
        "with no direct feed-through has nk >= 1, as MATLAB's default).",
    )


def appraiser_options() -> Decorator:
    """The appraiser's options, collected into ``appraiser`` (:class:`AppraiserSettings`)."""
    return combine(
        click.option(
            "--order",
            "-n",
            type=click.IntRange(min=1),
            default=2,
            show_default=True,
            help="Model order N (na = nb = N unless --na/--nb are given), as in clpc identify.",
        ),
        na_nb_options(),
        click.option(
            "--window-size",
            "-w",
            type=click.IntRange(min=2),
            default=201,
            show_default=True,
            help="Lag vectors per LPC window.",
        ),
        click.option(
            "--cluster-size",
            "-c",
            type=click.IntRange(min=1),
            default=12,
            show_default=True,
            help="Lag vectors between updates.",
        ),
        nk_option(),
        click.option(
            "--decimate-to",
            type=click.FloatRange(min=0, min_open=True),
            default=None,
            help="Sample time [s] the appraiser works at: an integer multiple of the data's "
            "--dt (the data are low-pass filtered and decimated).",
        ),
        method_option(),
        click.option(
            "--guard/--no-guard",
            default=True,
            show_default=True,
            help="Accept estimates only from trusted windows (enough rows, excited above "
            "quantization, determined); --no-guard is the paper's appraiser.",
        ),
    )


def appraiser_settings() -> Decorator:
    """Collect the options of :func:`appraiser_options` into ``appraiser``."""
    return collect("appraiser", AppraiserSettings)


# ============================================================================ outputs
def json_option(help: str = "Print one JSON object.") -> Decorator:
    """``--json`` into ``as_json``."""
    return click.option("--json", "as_json", is_flag=True, help=help)


def save_option(help: str) -> Decorator:
    """``--save MODEL.json``."""
    return click.option(
        "--save", type=click.Path(dir_okay=False), default=None, metavar="MODEL.json", help=help
    )


def out_dir_option(help: str) -> Decorator:
    """``--out DIR`` (required) into ``out_dir``."""
    return click.option(
        "--out", "out_dir", type=click.Path(file_okay=False), required=True, help=help
    )


def format_option(choices: list[str], help: str) -> Decorator:
    """``--format`` into ``fmt`` (the first choice is the default)."""
    return click.option(
        "--format",
        "fmt",
        type=click.Choice(choices),
        default=choices[0],
        show_default=True,
        help=help,
    )
