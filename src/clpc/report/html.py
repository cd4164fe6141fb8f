"""A self-contained HTML report: titled sections of text, warnings, tables and PNG figures.

The page is valid HTML5 with a viewport meta (readable on a phone), numbers that never wrap
inside (``1.2e-06`` stays on one line), warnings in a visible box and sections that can be
collapsed (``<details>``, e.g. the settings at the end).
"""

from __future__ import annotations

import base64
import html
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from clpc.core.atomic import write_file

__all__ = ["Section", "table_html", "warnings_html", "write_html_report"]

#: an image: its file, or its file and a caption
Image = str | PathLike[str] | tuple[str | PathLike[str], str]


@dataclass
class Section:
    """One section of an HTML report.

    Parameters
    ----------
    heading : str
        Section heading ("" for an untitled section, e.g. an introduction).
    text : str, optional
        Paragraph text (escaped; blank lines separate paragraphs).
    table : mapping or sequence of rows, optional
        A mapping ``{name: value}`` (two-column table) or rows whose first row is the header.
    images : sequence of path-like or (path-like, caption)
        PNG files to show (embedded as base64, or linked relative to the report).
    preformatted : str, optional
        Text shown verbatim (e.g. a printed model).
    warnings : sequence of str
        Shown first, in a highlighted box.
    collapsed : bool
        Show the section folded (``<details>``); the reader opens it.
    html : str, optional
        Trusted HTML inserted as is after the text (e.g. a model's ``_repr_html_``).
    """

    heading: str
    text: str | None = None
    table: Mapping[str, Any] | Sequence[Sequence[Any]] | None = None
    images: Sequence[Image] = field(default_factory=list)
    preformatted: str | None = None
    warnings: Sequence[str] = ()
    collapsed: bool = False
    html: str | None = None


_CSS = (
    "body{font-family:system-ui,sans-serif;max-width:62em;margin:1.5em auto;padding:0 1em;"
    "color:#222;line-height:1.45}"
    "h1{font-size:1.6em}h2{margin-top:1.6em;border-bottom:1px solid #ddd}"
    "table{border-collapse:collapse;margin:.8em 0;font-size:.92em;display:block;"
    "overflow-x:auto;max-width:100%}"
    "td,th{border:1px solid #ccc;padding:.25em .6em;text-align:left;vertical-align:top}"
    "th{background:#f3f3f3}td.num{text-align:right;white-space:nowrap;"
    "font-variant-numeric:tabular-nums}caption{text-align:left;font-weight:600}"
    "figure{margin:1em 0}figcaption{font-size:.9em;color:#555}"
    "img{max-width:100%;height:auto;border:1px solid #eee}"
    "pre{background:#f8f8f8;padding:.8em;overflow-x:auto;font-size:.88em}"
    ".warn{border:2px solid #d9822b;background:#fff4e5;padding:.5em 1em;margin:.8em 0;"
    "border-radius:4px}.warn ul{margin:.3em 0;padding-left:1.2em}"
    ".ok{border:2px solid #3c9a5f;background:#edf8f0;padding:.5em 1em;margin:.8em 0;"
    "border-radius:4px}"
    "details>summary{cursor:pointer;font-size:1.5em;font-weight:bold;margin-top:1.2em}"
    "blockquote{margin:.8em 0;padding:.1em 1em;border-left:4px solid #9ab;background:#f6f8fa}"
    "td.bad{background:#fde2e1;font-weight:600}td.partly{background:#fff4e5;font-weight:600}"
    "td.good{background:#edf8f0}code{font-size:.92em;background:#f3f3f3;padding:0 .2em}"
)


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(
        v, (bool, np.bool_)
    )


def _cell(v: Any, tag: str = "td") -> str:
    if _is_number(v):
        text = f"{float(v):.6g}" if isinstance(v, (float, np.floating)) else str(v)
        return f'<{tag} class="num">{html.escape(text)}</{tag}>'
    if v is None:
        return f"<{tag}>&ndash;</{tag}>"
    return f"<{tag}>{html.escape(str(v))}</{tag}>"


def table_html(
    table: Mapping[str, Any] | Sequence[Sequence[Any]], caption: str | None = None
) -> str:
    """A table as HTML, as a :class:`Section` shows its ``table`` (cells escaped).

    Parameters
    ----------
    table : mapping or sequence of rows
        A mapping ``{name: value}`` (two columns) or rows whose first row is the header.
    caption : str, optional
        Shown above the table (plain text).

    Returns
    -------
    str
        A ``<table>`` element (``""`` for no rows); numbers right-aligned, 6 significant
        digits, ``None`` as a dash.
    """
    cap = f"<caption>{html.escape(caption)}</caption>" if caption else ""
    if isinstance(table, Mapping):
        rows = [f"<tr>{_cell(k, 'th')}{_cell(v)}</tr>" for k, v in table.items()]
        return f"<table>{cap}" + "".join(rows) + "</table>"
    rows_in = [list(r) for r in table]
    if not rows_in:
        return ""
    head = "".join(f"<th>{html.escape(str(c))}</th>" for c in rows_in[0])
    body = "".join("<tr>" + "".join(_cell(c) for c in row) + "</tr>" for row in rows_in[1:])
    return f"<table>{cap}<tr>{head}</tr>{body}</table>"


def _image_html(image: Image, report_dir: Path, embed: bool) -> str:
    path, caption = image if isinstance(image, tuple) else (image, None)
    img = Path(path)
    alt = html.escape(caption or img.stem.replace("_", " "))
    if embed:
        data = base64.b64encode(img.read_bytes()).decode("ascii")
        src = f"data:image/png;base64,{data}"
    else:
        try:
            src = img.resolve().relative_to(report_dir.resolve()).as_posix()
        except ValueError:
            src = img.resolve().as_uri()
    cap = f"<figcaption>{html.escape(caption)}</figcaption>" if caption else ""
    return f'<figure><img alt="{alt}" src="{html.escape(src)}">{cap}</figure>'


def warnings_html(warnings: Sequence[str], title: str = "Warnings") -> str:
    """The highlighted box of a :class:`Section`'s ``warnings`` (text escaped), as HTML.

    Parameters
    ----------
    warnings : sequence of str
        The warnings, one list item each (plain text).
    title : str
        Heading of the box (plain text, default ``"Warnings"``).

    Returns
    -------
    str
        A ``<div class="warn">`` element.
    """
    items = "".join(f"<li>{html.escape(w)}</li>" for w in warnings)
    return (
        f'<div class="warn" role="note"><strong>{html.escape(title)}</strong><ul>{items}</ul></div>'
    )


def _section_html(sec: Section, report_dir: Path, embed: bool) -> str:
    parts = []
    if sec.warnings:
        parts.append(warnings_html(sec.warnings))
    if sec.text:
        parts += [f"<p>{html.escape(p.strip())}</p>" for p in sec.text.split("\n\n") if p.strip()]
    if sec.html:
        parts.append(sec.html)
    if sec.preformatted:
        parts.append(f"<pre>{html.escape(sec.preformatted)}</pre>")
    if sec.table is not None:
        parts.append(table_html(sec.table))
    parts += [_image_html(img, report_dir, embed) for img in sec.images]
    heading = html.escape(sec.heading)
    if not heading:  # an untitled section (e.g. an introduction under the title)
        return f"<section>{''.join(parts)}</section>"
    if sec.collapsed:
        return f"<details><summary>{heading}</summary>{''.join(parts)}</details>"
    return f"<section><h2>{heading}</h2>{''.join(parts)}</section>"


def write_html_report(
    path: str | PathLike[str],
    title: str,
    sections: Iterable[Section | Mapping[str, Any]],
    *,
    embed_images: bool = True,
) -> Path:
    """Write a self-contained HTML report.

    Parameters
    ----------
    path : str or path-like
        HTML file to write (parent folders are created).
    title : str
        Page title and top heading.
    sections : iterable of Section or mapping
        Sections in order; a mapping takes the :class:`Section` field names.
    embed_images : bool
        Embed the PNGs as base64 (default: the file stands alone) or link them relative to
        the report's folder.

    Returns
    -------
    Path
        The file written.
    """
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body><main>",
        f"<h1>{html.escape(title)}</h1>",
    ]
    for sec in sections:
        sec = sec if isinstance(sec, Section) else Section(**sec)
        parts.append(_section_html(sec, out.parent, embed_images))
    parts.append("</main></body></html>")
    write_file(out, "\n".join(parts))  # atomic: see clpc.core.atomic
    return out
