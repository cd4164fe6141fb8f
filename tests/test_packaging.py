"""Packaging: one source of the version, no empty extras."""

from __future__ import annotations

import importlib.metadata
import sys
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


@pytest.mark.skipif(sys.version_info < (3, 11), reason="tomllib")
def test_pyproject_reads_the_version_from_the_package_and_has_no_empty_extra():
    import tomllib

    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert "version" not in meta["project"]
    assert meta["project"]["dynamic"] == ["version"]
    assert meta["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "clpc._version.__version__"}
    extras = meta["project"]["optional-dependencies"]
    assert all(extras.values()), [name for name, deps in extras.items() if not deps]
