"""How a result shows itself: a ``repr`` of one screen and a notebook table, never whole arrays.

* :func:`summarise` - any value as one short line: arrays by shape, dtype and range
  (``array(shape=(1000,), float64, min=-1.2, max=3.4)``), long text cut, long collections
  counted.
* :func:`compact_repr` - class decorator of a result dataclass: its ``__repr__`` lists the
  fields, each summarised, on one line or one field a line; its ``_repr_html_`` (unless the
  class writes its own) is the same as an HTML table.
* :func:`html_table` - a caption and rows of (name, HTML) as a ``<table>``.
"""

from __future__ import annotations

import dataclasses
import html
import inspect
from collections.abc import Mapping
from typing import Any, TypeVar

import numpy as np

__all__ = ["MAX_REPR", "compact_repr", "html_table", "summarise"]

T = TypeVar("T", bound=type)

#: characters of a whole ``repr`` at most (about one screen)
MAX_REPR = 2000
#: characters of a field's value in a ``repr``, and of an item inside a collection
FIELD_WIDTH, ITEM_WIDTH = 240, 100
#: entries of an array shown in full; items of a collection shown one a line
SMALL_ARRAY, SHOWN_ITEMS = 8, 6
#: characters of a value that counts as short (a record of short values is shown cut)
SHORT = 30
#: rows of a list of records shown as a table in HTML
HTML_ROWS = 20
_CELL = "style='text-align:left;vertical-align:top'"


def _cut(text: str, width: int) -> str:
    """``text`` on one line, at most ``width`` characters (the cut marked by an ellipsis)."""
    text = " ".join(text.split())
    return text if len(text) <= width else text[: width - 1] + "…"


def _number(x: Any) -> str:
    return f"{x:.4g}" if isinstance(x, float) else str(x)


def _array(a: np.ndarray, width: int) -> str:
    """An array: in full when small, else its shape, dtype and range."""
    if 0 < a.size <= SMALL_ARRAY and a.dtype.kind in "biufc":
        text = np.array2string(a, separator=", ", formatter={"float_kind": _number})
        return _cut(f"array({text})", width)
    head = f"array(shape={a.shape}, {a.dtype}"
    if a.size == 0 or a.dtype.kind not in "biufc":
        return head + ")"
    if a.dtype.kind == "b":
        return f"{head}, true={int(np.count_nonzero(a))})"
    if a.dtype.kind == "c":
        return f"{head}, max |x|={_number(float(np.nanmax(np.abs(a))))})"
    finite = np.isfinite(a)
    if not finite.any():
        return f"{head}, no finite value)"
    values = a[finite]
    tail = "" if finite.all() else f", non-finite={int(a.size - finite.sum())}"
    lo, hi = values.min().item(), values.max().item()
    return f"{head}, min={_number(lo)}, max={_number(hi)}{tail})"


def summarise(value: Any, width: int = ITEM_WIDTH) -> str:
    """One short line that stands for ``value`` in a ``repr``.

    Parameters
    ----------
    value : object
        Anything: arrays, numbers, text, collections, frames, results.
    width : int, optional
        Characters at most (text and collections are cut, with an ellipsis).

    Returns
    -------
    str
        Numbers with 4 significant digits, arrays of more than :data:`SMALL_ARRAY` entries
        by shape, dtype, minimum and maximum (of the finite entries), text quoted and cut,
        collections listed item by item when they fit and counted when they do not,
        objects by the first line of their own ``repr``.
    """
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, np.ndarray):
        return _array(value, width)
    if isinstance(value, float):
        return _number(value)
    if value is None or isinstance(value, (bool, int)):
        return repr(value)
    if isinstance(value, str):
        return _cut(repr(value), width)
    if hasattr(value, "columns") and hasattr(value, "shape"):  # a pandas DataFrame
        cols = ", ".join(map(str, list(value.columns)[:SHOWN_ITEMS]))
        return _cut(f"{type(value).__name__}(shape={value.shape}, columns=[{cols}])", width)
    if isinstance(value, Mapping):
        shown = [(k, summarise(v, width // 2)) for k, v in value.items()]
        inner = ", ".join(f"{k!s}: {v}" for k, v in shown)
        if len(inner) + 2 <= width or all(len(v) <= SHORT for _, v in shown):
            return _cut("{" + inner + "}", width)  # a record of numbers and words
        keys = ", ".join(map(str, value))
        return _cut(f"dict({len(value)} keys: {keys})", width)
    if isinstance(value, (list, tuple)):
        ends = "[]" if isinstance(value, list) else ("(", ",)" if len(value) == 1 else ")")
        inner = ", ".join(summarise(v, width) for v in value)
        if len(inner) + 2 <= width:
            return ends[0] + inner + ends[1]
        kind = type(value[0]).__name__ if value else "item"
        return _cut(f"{type(value).__name__}({len(value)} × {kind}: {inner})", width)
    return _object(value, width)


def _generated(cls: type) -> bool:
    """Whether ``cls`` shows itself by the ``repr`` of its fields (``dataclass``'s or ours)."""
    if not dataclasses.is_dataclass(cls) or cls.__repr__ is _repr:
        return cls.__repr__ is _repr
    code = getattr(inspect.unwrap(cls.__repr__), "__code__", None)
    return code is not None and code.co_filename == "<string>"  # written by dataclasses


def _object(value: Any, width: int) -> str:
    """Any other object: its fields summarised if it is a dataclass, else its own ``repr``."""
    if not _generated(type(value)):
        lines = repr(value).splitlines() or [""]
        return _cut(lines[0] + (" …" if len(lines) > 1 else ""), width)
    inner = ", ".join(f"{k}={summarise(v, width // 2)}" for k, v in _shown(value))
    return _cut(f"{type(value).__name__}({inner})", width)


def _field_text(value: Any) -> str:
    """A field's value in a ``repr``: one line, or its items one a line when they do not fit."""
    one = summarise(value, FIELD_WIDTH)
    if not isinstance(value, (list, tuple)) or len(one) < FIELD_WIDTH or not value:
        return one
    ends = "[]" if isinstance(value, list) else "()"
    items = [f"        {summarise(v, ITEM_WIDTH)}," for v in value[:SHOWN_ITEMS]]
    if len(value) > SHOWN_ITEMS:
        items.append(f"        … {len(value) - SHOWN_ITEMS} more")
    return "\n".join([ends[0], *items, f"    {ends[1]}"])


def _shown(obj: Any) -> list[tuple[str, Any]]:
    """The fields a ``repr`` shows: the dataclass fields not marked ``repr=False``."""
    return [(f.name, getattr(obj, f.name)) for f in dataclasses.fields(obj) if f.repr]


def _repr(self: Any) -> str:
    """A ``repr`` of one screen: the fields summarised."""
    name = type(self).__name__
    parts = [(k, _field_text(v)) for k, v in _shown(self)]
    line = f"{name}(" + ", ".join(f"{k}={v}" for k, v in parts) + ")"
    if len(line) <= ITEM_WIDTH and "\n" not in line:
        return line
    text = "\n".join([f"{name}(", *(f"    {k}={v}," for k, v in parts), ")"])
    return text if len(text) <= MAX_REPR else text[: MAX_REPR - 2] + "\n…"


def _cell(value: Any) -> str:
    """A value in a table cell: text as it is, anything else summarised."""
    return _cut(value, 40) if isinstance(value, str) else summarise(value, 40)


def _records_html(rows: list[Mapping[str, Any]]) -> str:
    """A list of records with the same keys as a table (at most :data:`HTML_ROWS` rows)."""
    keys = list(rows[0])
    head = "".join(f"<th>{html.escape(str(k))}</th>" for k in keys)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(_cell(row.get(k)))}</td>" for k in keys) + "</tr>"
        for row in rows[:HTML_ROWS]
    )
    more = len(rows) - HTML_ROWS
    tail = f"<tr><td colspan='{len(keys)}'>… {more} more rows</td></tr>" if more > 0 else ""
    return f"<table><tr>{head}</tr>{body}{tail}</table>"


def _value_html(value: Any) -> str:
    """A field's value in HTML: a result's own table, records as a table, else the summary."""
    if hasattr(value, "_repr_html_") and not isinstance(value, type):
        return str(value._repr_html_())
    if (
        isinstance(value, list)
        and value
        and all(isinstance(v, Mapping) and list(v) == list(value[0]) for v in value)
    ):
        return _records_html(value)
    if isinstance(value, (list, tuple)) and value and all(isinstance(v, str) for v in value):
        items = "".join(f"<li>{html.escape(v)}</li>" for v in value[:HTML_ROWS])
        return f"<ul>{items}</ul>"
    if isinstance(value, str):
        return html.escape(_cut(value, 4 * FIELD_WIDTH))
    return html.escape(summarise(value, FIELD_WIDTH))


def html_table(caption: str, rows: list[tuple[str, str]]) -> str:
    """A two-column HTML table: a name, then its (already escaped) HTML, one row each.

    Parameters
    ----------
    caption : str
        Plain text above the table (escaped here).
    rows : list of (str, str)
        The name (plain text, escaped here) and the cell's HTML (trusted, inserted as is).

    Returns
    -------
    str
        ``<table><caption>…</caption><tr><th>name</th><td>cell</td></tr>…</table>``.
    """
    body = "".join(
        f"<tr><th {_CELL}>{html.escape(name)}</th><td {_CELL}>{cell}</td></tr>"
        for name, cell in rows
    )
    return f"<table><caption>{html.escape(caption)}</caption>{body}</table>"


def _repr_html(self: Any) -> str:
    """The fields as an HTML table (Jupyter)."""
    rows = [(k, _value_html(v)) for k, v in _shown(self)]
    return html_table(type(self).__name__, rows)


def compact_repr(cls: T) -> T:
    """Give a result dataclass a one-screen ``repr`` and a notebook table.

    Parameters
    ----------
    cls : type
        A dataclass (put the decorator above ``@dataclass``). Its fields with
        ``repr=False`` are left out of both.

    Returns
    -------
    type
        ``cls``, with ``__repr__`` (at most :data:`MAX_REPR` characters: every field
        summarised by :func:`summarise`) and, unless it defines its own, ``_repr_html_``.
    """
    if not dataclasses.is_dataclass(cls):
        raise TypeError(f"compact_repr needs a dataclass; got {cls.__name__}.")
    cls.__repr__ = _repr  # type: ignore[method-assign]
    if "_repr_html_" not in cls.__dict__:
        cls._repr_html_ = _repr_html  # type: ignore[attr-defined]
    return cls
