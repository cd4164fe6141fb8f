"""Packaging: one source of the version, no empty extras."""

from __future__ import annotations

import ast
import importlib.metadata
import re
import tomllib
from pathlib import Path

import pytest

import clpc

ROOT = Path(__file__).resolve().parents[1]


def test_the_version_is_the_installed_metadata_version():
    try:
        installed = importlib.metadata.version("clpc")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("clpc is not installed (run from the source tree)")
    assert clpc.__version__ == installed


def test_pyproject_reads_the_version_from_the_package_and_has_no_empty_extra():
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert "version" not in meta["project"]
    assert meta["project"]["dynamic"] == ["version"]
    assert meta["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "clpc._version.__version__"}
    extras = meta["project"]["optional-dependencies"]
    assert all(extras.values()), [name for name, deps in extras.items() if not deps]


def test_metadata_names_the_license_holder_the_pythons_and_the_addresses():
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text())
    meta = pyproject["project"]
    license_text = (ROOT / "LICENSE").read_text()
    holder = re.search(r"Copyright \(c\) \d{4} (.+)", license_text)
    assert holder is not None
    assert meta["authors"] == [{"name": holder.group(1).strip()}] == meta["maintainers"]
    # the license is the SPDX expression with its file; setuptools refuses a classifier beside it
    assert meta["license"] == "MIT" and license_text.startswith("MIT License")
    assert meta["license-files"] == ["LICENSE"]
    classifiers = meta["classifiers"]
    assert not [c for c in classifiers if c.startswith("License ::")]
    # the Pythons named start at the lowest one requires-python admits, as ruff and mypy assume
    lowest = tuple(int(p) for p in meta["requires-python"].removeprefix(">=").split("."))
    named = [
        tuple(int(p) for p in c.rsplit(" ", 1)[1].split("."))
        for c in classifiers
        if re.fullmatch(r"Programming Language :: Python :: 3\.\d+", c)
    ]
    assert named and min(named) == lowest
    assert pyproject["tool"]["ruff"]["target-version"] == "py{}{}".format(*lowest)
    assert pyproject["tool"]["mypy"]["python_version"] == "{}.{}".format(*lowest)
    assert {"Homepage", "Documentation", "Source"} <= set(meta["urls"]) and meta["keywords"]


def test_no_page_installs_clpc_from_an_index():
    """No package index serves clpc: every install line installs the source tree."""
    pages = [ROOT / "README.md", *(ROOT / "docs").rglob("*.md"), *(ROOT / "docs").rglob("*.in")]
    pages += list((ROOT / "src").rglob("*.py"))
    from_index = re.compile(r"pip install\s+(-\S+\s+)*['\"]?clpc\b")
    offenders = [str(p.relative_to(ROOT)) for p in pages if from_index.search(p.read_text())]
    assert offenders == []


def test_the_peers_of_the_benchmark_are_never_dependencies_of_the_package():
    """``benchmarks/peers.py``'s tools: an extra for that script, imported by no package file."""
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    peers = {"sippy_unipi", "nfoursid", "sysidentpy"}
    assert set(meta["project"]["optional-dependencies"]["peers"]) == peers
    deps = meta["project"]["dependencies"]
    named = {d.split(">")[0].split("=")[0].split("[")[0].strip() for d in deps}
    assert not named & peers
    for package in ("clpc", "clpc_paper"):
        for path in (ROOT / "src" / package).rglob("*.py"):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Import):
                    roots = {a.name.split(".")[0] for a in node.names}
                elif isinstance(node, ast.ImportFrom) and not node.level:
                    roots = {(node.module or "").split(".")[0]}
                else:
                    continue
                assert not roots & peers, f"{path.relative_to(ROOT)} imports {roots & peers}"
