"""``clpc identify --estimator`` and ``--nk auto``: the comparison table and the reason."""

from __future__ import annotations

import json

import numpy as np
from click.testing import CliRunner

import clpc
import clpc.datasets as ds
from clpc.cli import cli

DRYER = str(ds.path("dryer"))


def run(*args: str):
    return CliRunner().invoke(cli, [str(a) for a in args])


def test_estimator_auto_prints_the_table_and_the_reason():
    res = run("identify", DRYER, "-u", "u", "-y", "y", "--dt", "0.08", "--estimator", "auto")
    assert res.exit_code == 0, res.output
    out = res.output
    assert "estimator comparison" in out
    for name in ("LPC N=2 nk=0", "ARX N=2 nk=0", "OE  N=2 nk=0"):
        assert name in out
    assert out.count("<- chosen") == 1
    assert "reason:" in out and "errors-in-variables" in out
    lib = clpc.identify(ds.load("dryer"), estimator="auto")
    chosen = next(r for r in lib.table if r["chosen"])
    line = next(x for x in out.splitlines() if "<- chosen" in x)
    assert line.strip().startswith(chosen["estimator"].upper())
    assert f"free run {chosen['free_run']:.1f} %" in line


def test_nk_auto_json_matches_the_library():
    res = run("identify", DRYER, "-u", "u", "-y", "y", "--nk", "auto", "--json")
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout)
    lib = clpc.identify(ds.load("dryer"), estimator="lpc", nk="auto")
    comp = summary["comparison"]
    assert comp["nk"] == lib.nk and comp["estimators"] == ["lpc"]
    assert [d["nk"] for d in comp["delays"]] == [0, 1, 2, 3, 4]
    assert summary["structure"]["nk"] == lib.nk
    np.testing.assert_allclose(summary["equations"][0]["den"], lib.model.den)


def test_without_estimator_the_output_is_unchanged():
    res = run("identify", DRYER, "-u", "u", "-y", "y")
    assert res.exit_code == 0 and "estimator comparison" not in res.output


def test_bad_combinations_are_refused():
    res = run("identify", DRYER, "-u", "u", "-y", "y", "--estimator", "oe", "--method", "paper")
    assert res.exit_code == 1 and "applies to LPC alone" in res.output
    res = run("identify", DRYER, "-u", "u", "-y", "y", "--nk", "soon")
    assert res.exit_code == 2 and "int >= 0 or 'auto'" in res.output
    res = run("identify", DRYER, "-u", "u", "-y", "y", "--estimator", "n4sid")
    assert res.exit_code == 2
    args = ("--estimator", "arx", "--order", "auto", "--criterion", "bic")
    res = run("identify", DRYER, "-u", "u", "-y", "y", *args)
    assert res.exit_code == 1 and "held-out data only" in res.output


def test_order_auto_with_an_estimator_lists_every_order():
    args = ("--estimator", "arx", "--order", "auto", "--max-order", "3", "--json")
    res = run("identify", DRYER, "-u", "u", "-y", "y", *args)
    assert res.exit_code == 0, res.output
    comp = json.loads(res.stdout)["comparison"]
    assert sorted({r["order"] for r in comp["table"]}) == [1, 2, 3]
    assert comp["estimators"] == ["arx"]
    lib = clpc.identify(ds.load("dryer"), estimator="arx", order="auto", max_order=3)
    assert comp["order"] == lib.order and "as asked" in comp["reason"]
