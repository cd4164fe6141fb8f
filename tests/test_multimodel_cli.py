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


def test_compare_validates_a_saved_multimodel(tmp_path):
    # issue 28 item 7: `clpc compare` could not validate a multi-model; its fit % must be
    # the one of the multi-model's own free run and k-step prediction on the same data
    from clpc.analysis.metrics import fit_percent

    rng = np.random.default_rng(8)
    u = rng.uniform(-1, 1, 3000)
    y = clpc.simulate_arx([1, -0.5], [0, 0.5], u) + 0.2 * u**2
    model = tmp_path / "mm.json"
    mm = clpc.MultiModel(order=1, n_models=3).fit(u[:2000], y[:2000], dt=0.01)
    mm.save(model)
    data = tmp_path / "val.csv"
    np.savetxt(data, np.column_stack([u, y]), delimiter=",", header="u,y", comments="")
    args = ["compare", str(model), str(data), "-u", "u", "-y", "y", "--dt", "0.01", "--json"]
    start = mm.warmup
    free = CliRunner().invoke(cli, args)
    assert free.exit_code == 0, free.output
    sim = mm.simulate(u[start:], y_init=y[:start], u_init=u[:start])
    assert json.loads(free.stdout)["fit"]["y"] == float(fit_percent(y[start:], sim))
    k = CliRunner().invoke(cli, [*args, "--k", "4"])
    first = start + 3
    pred = mm.predict(u, y, k=4)
    assert json.loads(k.stdout)["fit"]["y"] == float(fit_percent(y[first:], pred[first:]))
    bare = CliRunner().invoke(cli, ["compare", str(model), str(data), "--dt", "0.01"])
    assert bare.exit_code == 2 and "names no columns" in bare.output
    other_rate = CliRunner().invoke(cli, [*args[:-3], "--dt", "0.02"])
    assert other_rate.exit_code == 1 and "dt = 0.01 s" in other_rate.output
