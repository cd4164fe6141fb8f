r"""An mkdocs hook: the CLI reference page generated from the click commands at build time.

``docs/cli-reference.md`` holds the marker ``<!-- clpc-cli-reference -->``; this hook replaces
it with one section per command: its one-line summary and its ``--help`` text, exactly as the
terminal prints it (click's own formatter, 78 columns). mkdocs-click was tried first: with
click 8.3 its option tables print ``Sentinel.UNSET`` as the default of every flag, and it
flattens the ``\b`` example blocks of the help texts into one paragraph.

Used by ``mkdocs.yml`` (``hooks``).
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import click

MARKER = "<!-- clpc-cli-reference -->"
WIDTH = 78  # the code column of the site's pages at common widths


def _sections(
    command: click.Command, name: str, parent: click.Context | None
) -> Iterator[tuple[str, click.Command, click.Context]]:
    """``(full name, command, context)`` of ``command`` and of every subcommand, depth first."""
    settings = {**command.context_settings, "terminal_width": WIDTH, "max_content_width": WIDTH}
    ctx = click.Context(command, info_name=name, parent=parent, **settings)
    yield ctx.command_path, command, ctx
    if isinstance(command, click.Group):
        for sub_name in command.list_commands(ctx):
            sub = command.get_command(ctx, sub_name)
            if sub is not None and not sub.hidden:
                yield from _sections(sub, sub_name, ctx)


def reference() -> str:
    """The Markdown of every command's section, ``clpc`` first."""
    from clpc.cli import cli

    lines: list[str] = []
    for path, command, ctx in _sections(cli, "clpc", None):
        depth = path.count(" ")
        slug = path.replace(" ", "-")
        lines += [f"{'#' * (2 + depth)} `{path}` {{ #{slug} }}", ""]
        summary = command.get_short_help_str(limit=1000)
        if summary:
            lines += [summary, ""]
        lines += ["```text", f"$ {path} --help", command.get_help(ctx), "```", ""]
    return "\n".join(lines)


def on_config(config: Any, **kwargs: Any) -> None:
    """Document the tree's own ``src/clpc`` (as the API pages do), not an installed copy."""
    src = str(Path(config.config_file_path).resolve().parent / "src")
    if src not in sys.path:
        sys.path.insert(0, src)


def on_page_markdown(markdown: str, **kwargs: Any) -> str:
    """Replace the marker (if the page has it) by the generated reference."""
    if MARKER not in markdown:
        return markdown
    return markdown.replace(MARKER, reference())
