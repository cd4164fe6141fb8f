r"""The small Markdown subset of the experiment's ``report.md``, as HTML (no dependency).

Handles what :mod:`clpc_paper.experiment` writes into ``report.md``: ``#``/``##`` headings,
paragraphs, pipe tables (``\|`` escapes a bar inside a cell), images on their own line
(an image followed by a paragraph opening with its caption in ``*...*`` becomes one
``<figure>``), bullet lists (continuation lines indented), block quotes and inline
``**bold**``, ``*italic*`` and backquoted code. Everything else is escaped text, never raw HTML.
"""

from __future__ import annotations

import html
import re
from collections.abc import Callable

__all__ = ["markdown_to_html", "split_sections"]

#: a table cell's text -> CSS class of its ``<td>`` (or None)
CellClass = Callable[[str], str | None]

_IMAGE = re.compile(r"^!\[(?P<alt>.*)\]\((?P<src>[^)\s]+)\)$")
_RULE = re.compile(r"^\|?\s*:?-{3,}:?\s*(\|\s*:?-{3,}:?\s*)*\|?$")
_NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


def inline(text: str) -> str:
    """Escape ``text`` and render ``code``, **bold** and *italic* spans."""
    codes: list[str] = []

    def keep(m: re.Match[str]) -> str:
        codes.append(f"<code>{html.escape(m.group(1))}</code>")
        return f"\x00{len(codes) - 1}\x00"

    out = html.escape(re.sub(r"`([^`]+)`", keep, text), quote=False)
    out = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", out)
    out = re.sub(r"(?<![\w*])\*(?!\s)(.+?)(?<!\s)\*(?![\w*])", r"<em>\1</em>", out)
    return re.sub("\x00(\\d+)\x00", lambda m: codes[int(m.group(1))], out)


def _cells(line: str) -> list[str]:
    body = line.strip()
    body = body[1:] if body.startswith("|") else body
    body = body[:-1] if body.endswith("|") and not body.endswith("\\|") else body
    return [c.strip().replace("\\|", "|") for c in re.split(r"(?<!\\)\|", body)]


def _table(lines: list[str], cell_class: CellClass | None) -> str:
    head = "".join(f"<th>{inline(c)}</th>" for c in _cells(lines[0]))
    body = [_cells(line) for line in lines[2:]]
    width = max((len(r) for r in body), default=0)
    # a column is numeric (right-aligned, unwrapped) when all its cells but "-" are numbers
    numeric = [
        any(_NUMBER.match(c) for c in col) and all(_NUMBER.match(c) or c == "-" for c in col)
        for col in ([r[j] for r in body if j < len(r)] for j in range(width))
    ]
    rows = []
    for cells in body:
        tds = []
        for j, c in enumerate(cells):
            cls = "num" if numeric[j] else cell_class(c) if cell_class else None
            attr = f' class="{cls}"' if cls else ""
            tds.append(f"<td{attr}>{inline(c)}</td>")
        rows.append("<tr>" + "".join(tds) + "</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table>"


def _blocks(text: str) -> list[list[str]]:
    """Blank-line separated blocks; a table, a list or an image line starts its own block."""
    blocks: list[list[str]] = []
    cur: list[str] = []
    for line in text.splitlines():
        if not line.strip():
            if cur:
                blocks.append(cur)
            cur = []
            continue
        kind = _kind(line)
        if cur and kind in ("table", "image", "list", "quote") and _kind(cur[0]) != kind:
            blocks.append(cur)
            cur = []
        cur.append(line)
    if cur:
        blocks.append(cur)
    return blocks


def _kind(line: str) -> str:
    s = line.strip()
    if s.startswith("|"):
        return "table"
    if _IMAGE.match(s):
        return "image"
    if s.startswith("- "):
        return "list"
    if s.startswith(">"):
        return "quote"
    return "para"


def _figure(line: str, caption: str | None) -> str:
    m = _IMAGE.match(line.strip())
    assert m is not None
    alt, src = m.group("alt"), m.group("src")
    cap = f"<figcaption>{inline(caption)}</figcaption>" if caption else ""
    return f'<figure><img alt="{html.escape(alt)}" src="{html.escape(src)}">{cap}</figure>'


def markdown_to_html(text: str, *, cell_class: CellClass | None = None) -> str:
    """HTML of a Markdown fragment of the subset above.

    Parameters
    ----------
    text : str
        Markdown (without the section headings: see :func:`split_sections`).
    cell_class : callable, optional
        ``cell text -> CSS class or None`` for the ``<td>`` of non-numeric table cells
        (the cells of a numeric column get ``num``: right-aligned, never wrapped).

    Returns
    -------
    str
        The HTML (block elements only, well nested).
    """
    out: list[str] = []
    blocks = _blocks(text)
    i = 0
    while i < len(blocks):
        block = blocks[i]
        kind = _kind(block[0])
        if kind == "table" and len(block) >= 2 and _RULE.match(block[1].strip()):
            out.append(_table(block, cell_class))
        elif kind == "image":
            alt = _IMAGE.match(block[0].strip())
            nxt = " ".join(blocks[i + 1]) if i + 1 < len(blocks) else ""
            caption = None
            if alt and alt.group("alt") and nxt.startswith(f"*{alt.group('alt')}*"):
                caption, i = nxt, i + 1  # the caption paragraph joins the figure
            out.append(_figure(block[0], caption))
            out += [_figure(line, None) for line in block[1:]]
        elif kind == "list":
            items: list[str] = []
            for line in block:
                if line.lstrip().startswith("- "):
                    items.append(line.lstrip()[2:])
                elif items:
                    items[-1] += " " + line.strip()
            out.append("<ul>" + "".join(f"<li>{inline(t)}</li>" for t in items) + "</ul>")
        elif kind == "quote":
            body = " ".join(line.strip().lstrip(">").strip() for line in block)
            out.append(f"<blockquote><p>{inline(body)}</p></blockquote>")
        else:
            out.append(f"<p>{inline(' '.join(line.strip() for line in block))}</p>")
        i += 1
    return "\n".join(out)


def split_sections(text: str) -> tuple[str, str, list[tuple[str, str]]]:
    """Split a Markdown document at its ``#`` and ``##`` headings.

    Returns
    -------
    title : str
        The ``# `` heading ("" if none).
    intro : str
        The Markdown before the first ``## `` heading.
    sections : list of (heading, markdown)
        Each ``## `` heading and the Markdown under it, in order.
    """
    title, intro_lines = "", []
    sections: list[tuple[str, list[str]]] = []
    for line in text.splitlines():
        if line.startswith("## "):
            sections.append((line[3:].strip(), []))
        elif line.startswith("# ") and not title and not sections:
            title = line[2:].strip()
        elif sections:
            sections[-1][1].append(line)
        else:
            intro_lines.append(line)
    return (
        title,
        "\n".join(intro_lines).strip(),
        [(h, "\n".join(body).strip()) for h, body in sections],
    )
