"""The options that several commands share, each declared once (as decorator factories).

The options of the record a command reads (file, columns, sampling) are in
:mod:`clpc.cli.record_options`.

:func:`collect` turns the keyword arguments click passes into one settings dataclass, so
that a command function receives typed settings instead of a dozen options.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from typing import Any

import click

from clpc.workflows import AppraiserSettings

__all__ = [
    "Decorator",
    "OrderType",
    "appraiser_options",
    "appraiser_settings",
    "collect",
    "combine",
    "format_option",
    "json_option",
    "method_option",
    "model_argument",
    "na_nb_options",
    "nk_option",
    "out_dir_option",
    "save_option",
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
def model_argument() -> Decorator:
    """The saved model ``MODEL.json``."""
    return click.argument("model_file", metavar="MODEL.json", type=click.Path(dir_okay=False))


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
