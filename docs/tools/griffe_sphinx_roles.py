"""A griffe extension for the docs site: clpc's numpydoc docstrings as Markdown.

clpc's docstrings use Sphinx roles (``:class:`LPC```, ``:func:`~clpc.lpc.identify```) and a few
module docstrings hold bare doctest lines. mkdocstrings reads docstrings as Markdown, where a role
prints as text (":class:") and ``>>>`` makes nested block quotes. Once the whole package is
loaded, this extension rewrites every docstring:

* a role becomes an optional cross-reference (autorefs): a link when the target is rendered on
  some page of the site, plain code otherwise (never a warning, so ``mkdocs build --strict``
  fails only on real broken links);
* a parameter's choices ``{"a", "b"}`` become ``"a" | "b"`` (griffe would print a tuple);
* a run of ``>>>`` lines (with their output) outside a fenced block becomes a ``pycon`` block
  (without its ``# doctest:`` flags).

Used by ``mkdocs.yml`` (``plugins.mkdocstrings.handlers.python.options.extensions``).
"""

from __future__ import annotations

import html
import re
from typing import Any

import griffe

DOCTEST_FLAG = re.compile(r"\s*# doctest:.*$")
CHOICES = re.compile(
    r"^(?P<head>\s*\*{0,2}\w+(?:, \*{0,2}\w+)* : )\{(?P<choices>[^{}]+)\}\s*$", re.MULTILINE
)
ROLE = re.compile(r":(?:py:)?(class|func|meth|mod|data|attr|exc|obj|const):`(?P<body>[^`]+)`")


def _split(body: str) -> tuple[str, str]:
    """The shown text and the target of a role's body (``title <target>``, ``~a.b``, ``a.b``)."""
    explicit = re.fullmatch(r"(?P<title>.+?)\s*<(?P<target>[^>]+)>", body)
    if explicit:
        return explicit["title"], explicit["target"]
    target = body.lstrip("~!")
    shown = target.rsplit(".", 1)[-1] if body.startswith("~") else target
    return shown, target


def _resolve(obj: griffe.Object, target: str) -> str:
    """The full path of ``target`` as seen from ``obj`` (the target itself when unknown)."""
    target = target.rstrip("()")
    head, _, rest = target.partition(".")
    scope: griffe.Object | None = obj
    while scope is not None:
        try:
            path = scope.resolve(head)
        except (griffe.NameResolutionError, AttributeError):
            scope = scope.parent
            continue
        full = f"{path}.{rest}" if rest else path
        try:
            found = obj.modules_collection.get_member(full)
            return str(getattr(found, "canonical_path", full))
        except Exception:  # an alias that does not resolve, a missing member
            return full
    return target


def _pycon(text: str) -> str:
    """Fence each run of doctest lines (``>>>`` and its output) not already in a fence."""
    out: list[str] = []
    in_fence = False
    in_doctest = False
    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith(("```", "~~~")):
            in_fence = not in_fence
        if not in_fence and not in_doctest and stripped.startswith(">>>"):
            out.append("```pycon")
            in_doctest = True
        elif in_doctest and not stripped:
            out.append("```")
            in_doctest = False
        out.append(DOCTEST_FLAG.sub("", line) if in_doctest else line)
    if in_doctest:
        out.append("```")
    return "\n".join(out)


class SphinxRoles(griffe.Extension):
    """Rewrite Sphinx roles and bare doctests in every docstring of a loaded package."""

    def on_package(self, *, pkg: griffe.Module, **kwargs: Any) -> None:
        """Rewrite the docstrings of ``pkg`` and all its members (the package is complete)."""
        self._visit(pkg, set())

    def _visit(self, obj: griffe.Object, seen: set[str]) -> None:
        if obj.path in seen:
            return
        seen.add(obj.path)
        if obj.docstring is not None:
            obj.docstring.value = self._rewrite(obj, obj.docstring.value)
        for member in obj.members.values():
            if not member.is_alias:
                self._visit(member, seen)  # type: ignore[arg-type]

    def _rewrite(self, obj: griffe.Object, text: str) -> str:
        def role(match: re.Match[str]) -> str:
            shown, target = _split(match["body"])
            identifier = html.escape(_resolve(obj, target), quote=True)
            return (
                f'<autoref identifier="{identifier}" optional hover>'
                f"<code>{html.escape(shown)}</code></autoref>"
            )

        # numpydoc's {"a", "b"} would print as a tuple ('a', 'b'); "a" | "b" reads as the choice
        text = CHOICES.sub(lambda m: m["head"] + " | ".join(m["choices"].split(", ")), text)
        if ">>>" in text and "Examples\n" not in text:
            text = _pycon(text)
        return ROLE.sub(role, text)
