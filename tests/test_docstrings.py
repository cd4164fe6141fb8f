"""Every public function and method documents every parameter (numpydoc ``Parameters``).

In the spirit of python-control's ``tests/docstrings_test.py``: the public API is every name in
``__all__`` of ``clpc`` and of its public subpackages; a function (or a public method of a public
class, or a class's constructor) fails when its signature has a parameter its docstring's
``Parameters`` section does not name, or when the section names one it does not have.
"""

from __future__ import annotations

import importlib
import inspect
import re
from collections.abc import Callable, Iterator
from typing import Any

import pytest

PACKAGES = (
    "clpc",
    "clpc.appraiser",
    "clpc.datasets",
    "clpc.io",
    "clpc.multimodel",
    "clpc.plotting",
    "clpc.report",
)

#: a section heading of a numpydoc docstring, underlined
_SECTION = re.compile(r"^(\s*)([A-Z][A-Za-z ]+)\n\1-{3,}\s*$", re.M)


def documented(
    doc: str, sections: tuple[str, ...] = ("Parameters", "Other Parameters")
) -> set[str] | None:
    """Names in the ``sections`` of a numpydoc docstring; None without any of them."""
    doc = inspect.cleandoc(doc)
    heads = list(_SECTION.finditer(doc))
    names: set[str] | None = None
    for i, head in enumerate(heads):
        if head.group(2).strip() not in sections:
            continue
        end = heads[i + 1].start() if i + 1 < len(heads) else len(doc)
        names = names or set()
        for line in doc[head.end() : end].splitlines():
            if line and not line[0].isspace():
                field = line.split(" : ")[0].strip()
                names.update(n.strip().lstrip("*") for n in field.split(","))
    return names


def variadic(fn: Callable[..., Any]) -> set[str]:
    """Names of ``*args``/``**kwargs``: documenting them is allowed, not required."""
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return set()
    var = (inspect.Parameter.VAR_POSITIONAL, inspect.Parameter.VAR_KEYWORD)
    return {name for name, p in sig.parameters.items() if p.kind in var}


def wanted(fn: Callable[..., Any]) -> set[str]:
    """Parameters a caller passes (no ``self``/``cls``, no ``*args``/``**kwargs``)."""
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return set()
    skip = (inspect.Parameter.VAR_POSITIONAL, inspect.Parameter.VAR_KEYWORD)
    return {
        name
        for name, p in sig.parameters.items()
        if name not in ("self", "cls") and p.kind not in skip and not name.startswith("_")
    }


def public_callables() -> Iterator[tuple[str, Callable[..., Any], str]]:
    """(qualified name, callable, docstring that must document it), each once."""
    seen: set[int] = set()
    for package in PACKAGES:
        module = importlib.import_module(package)
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name)
            if id(obj) in seen or not callable(obj) or inspect.ismodule(obj):
                continue
            seen.add(id(obj))
            if inspect.isclass(obj):
                # the class docstring documents the constructor (numpydoc's convention)
                yield f"{package}.{name}", obj, obj.__doc__ or ""
                # methods a clpc base class gives it (e.g. ``MultiModel``'s file methods) too
                members: dict[str, Any] = {}
                for base in reversed(obj.__mro__):
                    if base.__module__.split(".")[0] == "clpc":
                        members.update(vars(base))
                for attr, member in members.items():
                    fn = (
                        member.__func__
                        if isinstance(member, (classmethod, staticmethod))
                        else member
                    )
                    if attr.startswith("_") or not inspect.isfunction(fn):
                        continue
                    yield f"{package}.{name}.{attr}", fn, fn.__doc__ or ""
            elif inspect.isfunction(obj):
                yield f"{package}.{name}", obj, obj.__doc__ or ""


CASES = list(public_callables())


@pytest.mark.parametrize(("name", "fn", "doc"), CASES, ids=[c[0] for c in CASES])
def test_every_parameter_is_documented(name, fn, doc):
    want = wanted(fn)
    if inspect.isclass(fn):
        want = (
            wanted(fn.__init__)
            if "__init__" in vars(fn) or hasattr(fn, "__dataclass_fields__")
            else want
        )
    if not want:
        return
    assert doc.strip(), f"{name} has parameters {sorted(want)} but no docstring"
    # a class documents its constructor's parameters, or a (data)class's fields as attributes
    sections = ("Parameters", "Other Parameters") + (("Attributes",) if inspect.isclass(fn) else ())
    got = documented(doc, sections)
    assert got is not None, f"{name}: no 'Parameters' section for {sorted(want)}"
    assert sorted(want - got) == [], f"{name}: undocumented parameters"
    extra = got - want - variadic(fn.__init__ if inspect.isclass(fn) else fn)
    assert sorted(extra) == [], f"{name}: documented parameters it does not have"


def test_the_parser_reads_numpydoc():
    doc = """Do it.

    Parameters
    ----------
    u, y : ndarray
        Data.
    dt : float, optional
        Sample time.
    **kwargs
        More.

    Returns
    -------
    x : float
    """
    assert documented(doc) == {"u", "y", "dt", "kwargs"}
    assert documented("Nothing.") is None
