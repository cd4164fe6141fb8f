"""The demo's crank-servo part (issue 18): the claim judged on the plant and its control."""

from __future__ import annotations

import json

from clpc.core.jsonable import jsonable
from clpc_paper.experiment.nonlinear import (
    CLAIM_MARGIN,
    nonlinear_claim,
    run_nonlinear,
    section_nonlinear,
)


def test_nonlinear_part_judges_the_claim_on_the_plant_and_its_control(tmp_path):
    result = jsonable(run_nonlinear(tmp_path, seed=0, quick=True))
    json.dumps(result)  # JSON-safe
    claim = nonlinear_claim(result)
    assert claim["nonlinear"]["verdict"] == "reproduced"
    # the negative control shows no gain, as the claim says it should
    assert claim["control"]["verdict"] == "reproduced"
    assert claim["control"]["criterion"].startswith("no gain: on no record")
    for rec, row in result["nonlinear"]["fits"].items():
        best_global = max(row["global_lpc"]["free_run"], row["global_ls"]["free_run"])
        assert row["multimodel"]["free_run"] >= best_global + 10.0, rec
        # the steady-state average of windows at different operating points is the worst
        assert row["clpc_steady_state"]["free_run"] < best_global
    for row in result["control"]["fits"].values():
        best_global = max(row["global_lpc"]["free_run"], row["global_ls"]["free_run"])
        assert abs(row["multimodel"]["free_run"] - best_global) < CLAIM_MARGIN
    assert result["nonlinear"]["operating_point"]["multimodel_recommended"]
    assert result["nonlinear"]["steady_state_warning"]
    for name in result["figures"].values():
        assert (tmp_path / name).stat().st_size > 10_000
    summary = {"nonlinear_servo": result, "claims": [claim]}
    text = "\n".join(section_nonlinear(summary))
    assert "multi-model is recommended" in text and "figN_nonlinear_multimodel.png" in text
    assert section_nonlinear({"claims": []}) == []


def test_verdict_table_shows_the_crank_servo_verdicts() -> None:
    from clpc_paper.experiment.markdown import verdict_table

    claim = {
        "paper": "clusters identify better than one global fit (crank servo)",
        "figures": [],
        "nonlinear": {"verdict": "reproduced", "criterion": "margin 2 points"},
        "control": {"verdict": "not reproduced", "criterion": "margin 2 points"},
    }
    row = verdict_table({"claims": [claim]}).splitlines()[-1]
    assert "nonlinear: reproduced" in row
    assert "control: not reproduced" in row
    assert "margin 2 points" in row
