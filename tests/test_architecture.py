"""The package's layers: no import runs back up, no import cycle, no old flat module path.

Every ``import`` in ``src/clpc`` (module level and inside functions) is parsed with ``ast``;
each module belongs to the layer of its longest matching prefix in ``LAYERS``.
"""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

import clpc

SRC = Path(clpc.__file__).resolve().parent

#: bottom to top; a module may import its own layer or any layer below it
LAYERS: list[tuple[str, ...]] = [
    ("clpc._version", "clpc._schema", "clpc.core"),
    ("clpc.data",),
    ("clpc.model",),
    ("clpc.lpc",),
    ("clpc.appraiser",),
    ("clpc.analysis",),
    ("clpc.multimodel",),
    ("clpc.io", "clpc.datasets"),
    ("clpc.plants",),
    ("clpc.plotting", "clpc.report"),
    ("clpc.experiment",),
    ("clpc.workflows",),
    ("clpc.cli", "clpc.__main__"),
    ("clpc",),  # the package facade re-exports everything
]


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _layer(name: str) -> int:
    best, best_len = -1, -1
    for level, prefixes in enumerate(LAYERS):
        for prefix in prefixes:
            if (name == prefix or name.startswith(prefix + ".")) and len(prefix) > best_len:
                best, best_len = level, len(prefix)
    return best


def _imports(path: Path, name: str) -> set[str]:
    """Absolute names of the clpc modules that ``path`` imports (relative ones resolved)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.split(".")[0] == "clpc")
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            if mod.split(".")[0] != "clpc":
                continue
            for alias in node.names:  # `from clpc.x import y` may import module clpc.x.y
                sub = f"{mod}.{alias.name}"
                found.add(sub if _is_module(sub) else mod)
    return found


def _is_module(name: str) -> bool:
    rel = Path(*name.split(".")[1:]) if "." in name else Path()
    return (SRC / rel).with_suffix(".py").exists() or (SRC / rel / "__init__.py").exists()


def _graph() -> dict[str, set[str]]:
    graph = {}
    for path in sorted(SRC.rglob("*.py")):
        name = _module_name(path)
        graph[name] = {m for m in _imports(path, name) if m != name}
    return graph


GRAPH = _graph()


def test_every_module_has_a_layer():
    assert [m for m in GRAPH if _layer(m) < 0] == []


def test_no_import_runs_back_up():
    upward = [
        f"{mod} (layer {_layer(mod)}) imports {dep} (layer {_layer(dep)})"
        for mod, deps in GRAPH.items()
        for dep in deps
        if _layer(dep) > _layer(mod)
    ]
    assert upward == []


def _parents(name: str) -> set[str]:
    """Importing ``a.b.c`` runs ``a/__init__`` and ``a/b/__init__`` first."""
    parts = name.split(".")
    return {".".join(parts[:i]) for i in range(2, len(parts))}


def test_no_import_cycle():
    # edges: module -> what it imports (package facades excluded: they only re-export)
    edges = {m: {d for d in deps if d != "clpc"} for m, deps in GRAPH.items() if m != "clpc"}
    state: dict[str, int] = {}
    cycles: list[list[str]] = []

    def visit(node: str, stack: list[str]) -> None:
        state[node] = 1
        for dep in sorted(edges.get(node, ())):
            if dep in _parents(node):
                continue  # a submodule naming its own package's facade is no cycle of code
            if state.get(dep) == 1:
                cycles.append([*stack[stack.index(dep) :], dep])
            elif dep not in state:
                visit(dep, [*stack, dep])
        state[node] = 2

    for start in sorted(edges):
        if start not in state:
            visit(start, [start])
    assert cycles == []


def test_the_layer_check_sees_a_violation():
    # the check itself must be able to fail: a synthetic upward import is caught
    assert _layer("clpc.lpc.solve") < _layer("clpc.cli.commands")
    assert _layer("clpc.core.rules") == 0


def test_only_the_experiment_converts_markdown():
    # clpc's own reports (track, identify) are built as HTML directly (clpc.report.html);
    # clpc.report.markdown is kept for clpc.experiment's report.md -> report.html alone and
    # leaves with the experiment
    users = sorted(m for m, deps in GRAPH.items() if "clpc.report.markdown" in deps)
    assert users and all(m.startswith("clpc.experiment.") for m in users), users


def test_old_flat_module_paths_are_gone():
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("clpc.solve")
