"""``clpc multimodel`` (issue 18): fit, save, draw, and refuse bad options."""

from __future__ import annotations

import json

import numpy as np
from click.testing import CliRunner

import clpc
from clpc.cli.app import cli
from clpc_paper.plants.crank_servo import crank_commands, simulate_crank_servo


def test_multimodel_command_saves_a_model_that_simulates_the_same(tmp_path):
    rec = simulate_crank_servo(crank_commands(12, seed=1), seed=2)
    data = tmp_path / "crank.csv"
    np.savetxt(
        data,
        np.column_stack([rec.command, rec.position]),
        delimiter=",",
        header="command,position",
        comments="",
    )
    model, fig = tmp_path / "mm.json", tmp_path / "mm.png"
    args = ["multimodel", str(data), "-u", "command", "-y", "position", "--dt", "0.01"]
    res = CliRunner().invoke(cli, [*args, "--save", str(model), "--figure", str(fig), "--json"])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert out["n_models"] >= 3 and out["centre_source"] == "windows"
    fits = out["fit_on_record"]
    assert fits["multimodel"]["free_run"] > fits["global_least_squares"]["free_run"] + 5
    assert fig.stat().st_size > 10_000
    back = clpc.MultiModel.load(model)
    direct = clpc.MultiModel().fit(rec.command, rec.position, dt=0.01)
    assert np.array_equal(back.simulate(rec.command), direct.simulate(rec.command))
    text = CliRunner().invoke(cli, [*args, "--models", "2"])
    assert text.exit_code == 0 and "2 local model(s)" in text.output
    bad = CliRunner().invoke(cli, [*args, "--schedule", "q"])
    assert bad.exit_code != 0 and "schedule must be" in bad.output
