"""Fast start: ``import clpc`` and ``clpc --help`` load no heavy module (checked in a child
interpreter by what is in ``sys.modules``, not by a clock); every exported name still works."""

from __future__ import annotations

import subprocess
import sys

import click
import pytest

import clpc
from clpc.cli import cli
from clpc.cli.app import COMMANDS, command_docstring

HEAVY = ("scipy", "scipy.stats", "scipy.signal", "numba", "matplotlib", "pandas", "pyarrow")


def _loaded_after(code: str) -> set[str]:
    probe = f"{code}\nimport sys\nprint(' '.join(sorted(sys.modules)))"
    out = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True
    ).stdout
    return set(out.split())


def test_import_clpc_loads_nothing_heavy():
    loaded = _loaded_after("import clpc")
    assert {m for m in HEAVY if m in loaded} == set()
    assert "clpc.lpc" not in loaded


def test_help_loads_no_command_module():
    code = (
        "import io, contextlib\nfrom clpc.cli import cli\nbuf = io.StringIO()\n"
        "with contextlib.redirect_stdout(buf):\n"
        "    try:\n        cli.main(['--help'], prog_name='clpc')\n"
        "    except SystemExit:\n        pass\n"
        "assert 'identify' in buf.getvalue()"
    )
    loaded = _loaded_after(code)
    assert {m for m in (*HEAVY, "numpy", "clpc.workflows") if m in loaded} == set()


def test_using_a_name_loads_its_module():
    assert "clpc.lpc.estimator" in _loaded_after("import clpc\nclpc.LPC")
    # the metrics module imports scipy.stats only in the function that uses it
    assert "scipy.stats" not in _loaded_after("import clpc\nclpc.vaf")
    used = "import clpc, numpy\nclpc.whiteness_test(numpy.sin(numpy.arange(50.0)))"
    assert "scipy.stats" in _loaded_after(used)


@pytest.mark.parametrize("name", clpc.__all__)
def test_every_exported_name_resolves(name):
    assert getattr(clpc, name) is not None
    assert name in dir(clpc)


def test_unknown_names_raise_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        clpc.nope  # noqa: B018
    assert clpc.lpc.LPC is clpc.LPC  # subpackages load on attribute access


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_help_summary_read_from_source_matches_the_command(name):
    command = cli.get_command(click.Context(cli), name)
    assert command is not None
    assert command_docstring(name)
    summary = click.Command(name, help=command_docstring(name)).get_short_help_str(60)
    assert summary == command.get_short_help_str(60)


def test_batch_fits_and_simulations_compile_nothing():
    # LPC, ARX and OE fits, a model's simulation and prediction run on numpy and LAPACK: in
    # a fresh interpreter no numba dispatcher of clpc has compiled (or loaded) a signature
    code = (
        "import sys, numpy as np, clpc\n"
        "rng = np.random.default_rng(0)\n"
        "u = rng.standard_normal(1500)\n"
        "y = clpc.simulate_arx(np.array([1.0, -1.5, 0.7]), np.array([0.2, 0.5, 0.1]), u)\n"
        "y = y + 0.01 * rng.standard_normal(1500)\n"
        "for est in (clpc.LPC(order=2), clpc.ARX(order=2), clpc.OE(order=2)):\n"
        "    model = est.fit(u, y)\n"
        "    model.simulate(u), model.predict(u, y, k=3)\n"
        "compiled = sorted(\n"
        "    f'{name}.{attr}' for name, mod in list(sys.modules.items())\n"
        "    if name.startswith('clpc') for attr, obj in vars(mod).items()\n"
        "    if hasattr(obj, 'py_func') and getattr(obj, 'signatures', None)\n"
        ")\n"
        "print(' '.join(compiled) or 'none')\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.split() == ["none"]
