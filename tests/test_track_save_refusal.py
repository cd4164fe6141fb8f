"""``clpc track --save`` refuses an unstable steady-state model (issue 28, item 4)."""

from __future__ import annotations

import numpy as np
from click.testing import CliRunner
from scipy import signal

from clpc.cli import cli
from clpc.core.polynomials import UNIT_CIRCLE_TOL


def _record(path, pole: float) -> None:
    rng = np.random.default_rng(4)
    u = rng.standard_normal(800)
    den = np.real(np.poly([pole, 0.5]))
    y = signal.lfilter([0.0, 0.5, 0.2], den, u) + 1e-3 * rng.standard_normal(u.size)
    np.savetxt(path, np.c_[u, y], delimiter=",", header="u,y", comments="")


def test_save_refuses_an_unstable_steady_state_model(tmp_path):
    csv, out, model = tmp_path / "unstable.csv", tmp_path / "run", tmp_path / "m.json"
    _record(csv, 1.02)
    args = ["track", str(csv), "-u", "u", "-y", "y", "--out", str(out), "--save", str(model)]
    res = CliRunner().invoke(cli, args)
    assert res.exit_code == 1, res.output
    last = res.output.strip().splitlines()[-1]
    assert last.startswith("Error: not saved to")
    assert "unstable" in last and "1.02" in last and f"{1 + UNIT_CIRCLE_TOL:g}" in last
    assert not model.exists()
    assert (out / "report.html").exists() and (out / "trace.csv").exists()


def test_save_keeps_a_stable_steady_state_model(tmp_path):
    csv, out, model = tmp_path / "stable.csv", tmp_path / "run", tmp_path / "m.json"
    _record(csv, 0.9)
    args = ["track", str(csv), "-u", "u", "-y", "y", "--out", str(out), "--save", str(model)]
    res = CliRunner().invoke(cli, args)
    assert res.exit_code == 0, res.output
    assert model.exists()
