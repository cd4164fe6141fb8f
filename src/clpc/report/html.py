"""A self-contained HTML report: titled sections of text, tables and PNG figures."""

from __future__ import annotations

import base64
import html
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["Section", "write_html_report"]


@dataclass
class Section:
    """One section of an HTML report.

    Parameters
    ----------
    heading : str
    text : str, optional
        Paragraph text (escaped; blank lines separate paragraphs).
    table : mapping or sequence of rows, optional
        A mapping ``{name: value}`` (two-column table) or rows whose first row is the header.
    images : sequence of path-like
        PNG files to show (embedded as base64, or linked relative to the report).
    preformatted : str, optional
        Text shown verbatim (e.g. a printed model).
    """

    heading: str
    text: str | None = None
    table: Mapping[str, Any] | Sequence[Sequence[Any]] | None = None
    images: Sequence[str | PathLike[str]] = field(default_factory=list)
    preformatted: str | None = None


_CSS = (
    "body{font-family:sans-serif;max-width:60em;margin:2em auto;color:#222}"
    "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;"
    "padding:.25em .6em;text-align:right}th{background:#f3f3f3}td:first-child{text-align:left}"
    "img{max-width:100%;border:1px solid #eee}pre{background:#f8f8f8;padding:.8em;"
    "overflow-x:auto}"
)


def _cell(v: Any) -> str:
    if isinstance(v, (float, np.floating)):
        return html.escape(f"{float(v):.6g}")
    return html.escape(str(v))


def _table_html(table: Mapping[str, Any] | Sequence[Sequence[Any]]) -> str:
    if isinstance(table, Mapping):
        rows = [f"<tr><td>{_cell(k)}</td><td>{_cell(v)}</td></tr>" for k, v in table.items()]
        return "<table>" + "".join(rows) + "</table>"
    rows_in = [list(r) for r in table]
    if not rows_in:
        return ""
    head = "".join(f"<th>{_cell(c)}</th>" for c in rows_in[0])
    body = "".join(
        "<tr>" + "".join(f"<td>{_cell(c)}</td>" for c in row) + "</tr>" for row in rows_in[1:]
    )
    return f"<table><tr>{head}</tr>{body}</table>"


def _image_html(img: Path, report_dir: Path, embed: bool) -> str:
    alt = html.escape(img.stem)
    if embed:
        data = base64.b64encode(img.read_bytes()).decode("ascii")
        return f'<p><img alt="{alt}" src="data:image/png;base64,{data}"></p>'
    try:
        rel = img.resolve().relative_to(report_dir.resolve()).as_posix()
    except ValueError:
        rel = img.resolve().as_uri()
    return f'<p><img alt="{alt}" src="{html.escape(rel)}"></p>'


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
        f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
    ]
    for sec in sections:
        sec = sec if isinstance(sec, Section) else Section(**sec)
        parts.append(f"<h2>{html.escape(sec.heading)}</h2>")
        if sec.text:
            parts += [f"<p>{html.escape(p.strip())}</p>" for p in sec.text.split("\n\n")]
        if sec.preformatted:
            parts.append(f"<pre>{html.escape(sec.preformatted)}</pre>")
        if sec.table is not None:
            parts.append(_table_html(sec.table))
        parts += [_image_html(Path(img), out.parent, embed_images) for img in sec.images]
    parts.append("</body></html>")
    out.write_text("\n".join(parts), encoding="utf-8")
    return out
