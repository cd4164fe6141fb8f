"""The package's layers: no import runs back up, no import cycle, no old flat module path.

Every ``import`` in ``src/clpc`` (module level and inside functions) is parsed with ``ast``;
each module belongs to the layer of its longest matching prefix in ``LAYERS``.

The paper's application ``src/clpc_paper`` sits beside the library: it imports clpc's public
API only (``PUBLIC``), and the library imports it in one place, the ``clpc demo`` command
(``PAPER_ENTRY``), inside the command's function.
"""

from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import pytest

import clpc
import clpc_paper

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
    ("clpc.plotting", "clpc.report"),
    ("clpc.workflows",),
    ("clpc.distributed",),  # fleets and long records on Dask, over the workflows
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


# ================================================================= the paper's application
PAPER = Path(clpc_paper.__file__).resolve().parent

#: (module, function): the one place the library imports clpc_paper, inside the command
PAPER_ENTRY = ("clpc.cli.info", "demo")

#: what clpc_paper may import: ``clpc`` (names in ``clpc.__all__``) and these subpackages
#: (names in their ``__all__``); nothing deeper, nothing private
PUBLIC = (
    "clpc",
    "clpc.appraiser",
    "clpc.datasets",
    "clpc.multimodel",
    "clpc.plotting",
    "clpc.report",
)


def _sites(source: str, name: str, package: bool) -> list[tuple[str, tuple[str, ...], str]]:
    """Every import in ``source``: (absolute module, names taken from it, enclosing function).

    ``import a.b`` gives ``("a.b", (), fn)``; ``from a import x, y`` gives ``("a", ("x", "y"),
    fn)``; ``fn`` is the innermost function around the import ("" at module level).
    """
    base = name.split(".") if package else name.split(".")[:-1]
    found: list[tuple[str, tuple[str, ...], str]] = []

    def visit(node: ast.AST, fn: str) -> None:
        for child in ast.iter_child_nodes(node):
            inner = child.name if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)) else fn
            if isinstance(child, ast.Import):
                found.extend((a.name, (), fn) for a in child.names)
            elif isinstance(child, ast.ImportFrom):
                mod = child.module or ""
                if child.level:
                    mod = ".".join(base[: len(base) - child.level + 1] + ([mod] if mod else []))
                found.append((mod, tuple(a.name for a in child.names), fn))
            visit(child, inner)

    visit(ast.parse(source), "")
    return found


def _top(module: str) -> str:
    return module.split(".")[0]


def _library_uses_of_paper(name: str, source: str, package: bool = False) -> list[str]:
    """Imports of clpc_paper by library module ``name`` outside ``PAPER_ENTRY``."""
    return [
        f"{name}{'.' + fn if fn else ''} imports {mod}"
        for mod, _, fn in _sites(source, name, package)
        if _top(mod) == "clpc_paper" and (name, fn) != PAPER_ENTRY
    ]


def _public_names(module: str) -> set[str]:
    return set(getattr(importlib.import_module(module), "__all__", ()))


def _private_uses(name: str, source: str, package: bool = False) -> list[str]:
    """Imports of the library by clpc_paper module ``name`` that are not public API."""
    bad = []
    for mod, names, _ in _sites(source, name, package):
        if _top(mod) != "clpc":
            continue
        kept = names
        if mod not in PUBLIC:
            bad.append(f"{name} imports {mod}")
            continue
        allowed = _public_names(mod) | {
            p.rpartition(".")[2] for p in PUBLIC if p.startswith(mod + ".")
        }
        bad.extend(
            f"{name} imports {mod}.{n}" for n in kept if n not in allowed or n.startswith("_")
        )
    return bad


def _paper_modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PAPER.rglob("*.py")):
        parts = list(path.relative_to(PAPER.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def test_the_library_imports_the_paper_only_in_the_demo_command():
    bad = [
        use
        for path in sorted(SRC.rglob("*.py"))
        for use in _library_uses_of_paper(
            _module_name(path), path.read_text(encoding="utf-8"), path.name == "__init__.py"
        )
    ]
    assert bad == []


def test_the_demo_command_imports_the_paper():
    module, fn = PAPER_ENTRY
    path = SRC.joinpath(*module.split(".")[1:]).with_suffix(".py")
    sites = _sites(path.read_text(encoding="utf-8"), module, False)
    assert any(_top(mod) == "clpc_paper" and where == fn for mod, _, where in sites)


def test_the_paper_imports_public_api_only():
    bad = [
        use
        for name, path in _paper_modules().items()
        for use in _private_uses(name, path.read_text(encoding="utf-8"), path.name == "__init__.py")
    ]
    assert bad == []


def test_the_plants_do_not_import_the_experiment():
    bad = [
        f"{name} imports {mod}"
        for name, path in _paper_modules().items()
        if name.startswith("clpc_paper.plants")
        for mod, _, _ in _sites(path.read_text(encoding="utf-8"), name, path.name == "__init__.py")
        if _top(mod) == "clpc_paper"
        and not mod.startswith("clpc_paper.plants")
        and mod != "clpc_paper.checks"
    ]
    assert bad == []


def test_architecture_md_names_every_paper_module():
    doc = (Path(__file__).resolve().parent.parent / "docs" / "architecture.md").read_text(
        encoding="utf-8"
    )
    start = doc.index("## The paper's application")
    section = doc[start : doc.index("\n## ", start)]
    named = set(re.findall(r"`([\w/]+\.py)`", section))
    files = {p.relative_to(PAPER).as_posix() for p in PAPER.rglob("*.py")}
    assert sorted(files - named) == []  # every module is named
    assert sorted(named - files) == []  # every module named exists


def test_no_paper_module_is_over_300_lines():
    sizes = {
        name: len(path.read_text(encoding="utf-8").splitlines())
        for name, path in _paper_modules().items()
    }
    assert {name: n for name, n in sizes.items() if n > 300} == {}


def test_the_paper_checks_see_a_violation():
    # the checks themselves must be able to fail
    assert _library_uses_of_paper("clpc.lpc.arx", "import clpc_paper.plants\n")
    assert _library_uses_of_paper(
        "clpc.report.track", "def f():\n    from clpc_paper import demo\n"
    )
    module, fn = PAPER_ENTRY
    assert _library_uses_of_paper(module, "from clpc_paper.demo import run_demo\n")
    assert not _library_uses_of_paper(module, f"def {fn}():\n    from clpc_paper import demo\n")
    paper = "clpc_paper.experiment.run"
    assert _private_uses(paper, "from clpc.lpc.estimator import LPC\n")
    assert _private_uses(paper, "from clpc.core import checks\n")
    assert _private_uses(paper, "import clpc._moved\n")
    assert _private_uses(paper, "from clpc import _moved\n")
    assert _private_uses(paper, "from clpc import core\n")
    assert _private_uses(paper, "from clpc.appraiser import convergence\n")
    assert _private_uses(paper, "from clpc.core.polynomials import monic\n")
    plant = "clpc_paper.plants.servo_loop"
    assert _private_uses(plant, "from clpc.core import checks\n")
    assert _private_uses(paper, "from ..x import y\n") == []
    assert _private_uses(paper, "from clpc import LPC, plotting\nimport clpc\n") == []
    assert _private_uses(paper, "from clpc.plotting import plot_multimodel\n") == []


def test_no_library_module_converts_markdown():
    # clpc's own reports (track, identify) are built as HTML directly (clpc.report.html);
    # the experiment's report.md -> report.html converter lives in clpc_paper
    assert not any(m.endswith(".markdown") for m in GRAPH), sorted(GRAPH)


def test_old_flat_module_paths_are_gone():
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("clpc.solve")


def test_architecture_md_names_every_library_module():
    # docs/architecture.md's "Modules" section has one row per module of src/clpc
    doc = (Path(__file__).resolve().parent.parent / "docs" / "architecture.md").read_text(
        encoding="utf-8"
    )
    start = doc.index("## Modules")
    section = doc[start : doc.index("\n## ", start + 1)]
    named = set(re.findall(r"`([\w/]+\.py)`", section))
    files = {p.relative_to(SRC).as_posix() for p in SRC.rglob("*.py")}
    assert sorted(files - named) == []  # every module is named
    assert sorted(named - files) == []  # every module named exists
