"""``clpc identify --estimator`` and ``--nk auto``: the comparison table and the reason."""

from __future__ import annotations

import json

import numpy as np
from click.testing import CliRunner

import clpc
import clpc.datasets as ds
from clpc.cli import cli
from clpc.lpc.reasons import pct

DRYER = str(ds.path("dryer"))


def run(*args: str):
    return CliRunner().invoke(cli, [str(a) for a in args])


def test_by_default_everything_is_chosen_and_the_table_printed():
    res = run("identify", DRYER, "-u", "u", "-y", "y", "--dt", "0.08")
    assert res.exit_code == 0, res.output
    out = res.output
    assert "estimator comparison" in out
    lib = clpc.identify(ds.load("dryer"))
    s = lib.structure
    for name in ("LPC", "ARX", "OE"):
        assert f"{name:<8} na={s.na} nb={s.nb} nk={s.nk}" in out
    assert out.count("<- chosen") == 1
    assert "reason:" in out and "errors-in-variables" in out
    assert "structures screened: 660" in out
    chosen = next(r for r in lib.table if r["chosen"])
    line = next(x for x in out.splitlines() if "<- chosen" in x)
    assert line.strip().startswith(chosen["estimator"].upper())
    assert f"free run {chosen['free_run']:.1f} %" in line


def test_json_matches_the_library():
    args = ("--estimator", "arx", "--order", "2", "--json")
    res = run("identify", DRYER, "-u", "u", "-y", "y", *args)
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout)
    lib = clpc.identify(ds.load("dryer"), estimator="arx", order=2)
    comp = summary["comparison"]
    assert comp["structure"] == vars(lib.structure) and comp["estimators"] == ["arx"]
    assert comp["screened"] == 6 and "as asked" in comp["reason"]  # na = nb = 2, nk 0..5
    assert summary["structure"]["nk"] == lib.nk
    np.testing.assert_allclose(summary["equations"][0]["den"], lib.model.den)


def test_estimator_lpc_is_the_paper_estimator_alone():
    res = run("identify", DRYER, "-u", "u", "-y", "y", "--estimator", "lpc", "--order", "2")
    assert res.exit_code == 0 and "estimator comparison" not in res.output
    assert "LPC" in res.output and "nk=" in res.output
    # its delay scan (--nk auto, the default) is printed with the library's numbers
    scan = clpc.select_delay(ds.load("dryer"), delays=range(6), estimator=clpc.LPC(order=2))
    line = next(x for x in res.output.splitlines() if x.startswith("delay selection"))
    for d, fit in zip(scan.delays, scan.validation_fit, strict=True):
        assert f"nk={d}: {pct(fit)}" in line
    assert line.endswith(f"-> nk={scan.best}")


def test_bad_combinations_are_refused():
    res = run("identify", DRYER, "-u", "u", "-y", "y", "--estimator", "oe", "--method", "paper")
    assert res.exit_code == 2 and "applies to LPC alone" in res.output
    res = run("identify", DRYER, "-u", "u", "-y", "y", "--nk", "soon")
    assert res.exit_code == 2 and "int >= 0 or 'auto'" in res.output
    res = run("identify", DRYER, "-u", "u", "-y", "y", "--estimator", "n4sid")
    assert res.exit_code == 2
    args = ("--estimator", "arx", "--criterion", "bic")
    res = run("identify", DRYER, "-u", "u", "-y", "y", *args)
    assert res.exit_code == 2 and "applies to LPC alone" in res.output
