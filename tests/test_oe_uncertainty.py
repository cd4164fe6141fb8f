"""OE models carry a covariance, a noise model and verdict evidence; predict honours it."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from click.testing import CliRunner
from scipy import signal

import clpc
import clpc.datasets as ds
from clpc.cli import cli
from clpc.lpc import comparison
from clpc.lpc.simulation_error import MIN_SEGMENT, SEGMENTS
from clpc.model import ModelError
from clpc.report.summaries import model_summary
from clpc.report.text import estimator_name, format_model_summary

DEN = np.array([1.0, -1.5, 0.7])
NUM = np.array([0.5, 1.0, 0.5])
TRUE = np.r_[DEN[1:], NUM]


def _output_noise(seed: int, n: int, sd: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """Exact white input, white noise added to the output of a known 2nd-order system."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    return u, signal.lfilter(NUM, DEN, u) + sd * rng.standard_normal(n)


def test_oe_intervals_are_calibrated_on_output_noise_records():
    # 200 fixed seeds, short records (N = 200): each true parameter inside its 95 % interval
    # in 90-99 % of the records (benchmarks/uncertainty.py: 0.952-0.970 over 1000 seeds)
    hits = []
    for seed in range(200):
        u, y = _output_noise(seed, 200)
        lo, hi = clpc.OE(order=2, assess=False).fit(u, y).confidence_interval(0.95)
        hits.append((lo <= TRUE) & (TRUE <= hi))
    cover = np.mean(hits, axis=0)
    assert np.all((cover >= 0.90) & (cover <= 0.99)), cover


def _segments(n: int, s: int) -> list[int]:
    """Segment starts of OE's simulation error (clpc.lpc.simulation_error, its stated rule)."""
    k = max(1, min(SEGMENTS, (n - s) // MIN_SEGMENT))
    return [s + int(np.round(i * (n - s) / k)) for i in range(k)] + [n]


def _runs(n: int, s: int) -> list[tuple[int, int]]:
    """(first, end) of each free run: one over the whole record, then each later segment."""
    b = _segments(n, s)
    return [(b[0], n)] + [(b[i], b[i + 1]) for i in range(1, len(b) - 1)]


def _simulation_error(model, u, y, p, k, starts):
    """Free-run errors of every run of the model with monic parameters ``p = [a1, a2, b0, b1, b2]``.

    ``starts[i]``: the two start values ``y(b_i - 2), y(b_i - 1)`` of run ``i``.
    """
    theta = np.r_[1.0, p[:2], -p[2:]]
    scale = np.linalg.norm(theta)
    m = replace(model, theta=theta / scale, c=k / scale)
    return np.concatenate(
        [
            y[first:end] - m.simulate(u[first:end], y_init=starts[i], u_init=u[first - 2 : first])
            for i, (first, end) in enumerate(_runs(y.size, 2))
        ]
    )


def test_oe_covariance_equals_a_finite_difference_recomputation():
    # independent of OE's analytic Jacobian, its reflection parametrisation and monic_map:
    # C = s^2 (J^T J)^-1 J^T (P - G S)(P - G S)^T J (J^T J)^-1 + (first start's sandwich):
    # J and G (the errors' response to each run's measured start values) by differences;
    # P: each error row's noise sample (a sample in two runs counts twice); S: the start
    # values of a later run are noise samples themselves
    u, y = _output_noise(3, 300)
    model = clpc.OE(order=2, assess=False).fit(u, y)
    p0, k0 = np.r_[model.den[1:], model.num], float(model.intercept[0])
    runs = _runs(y.size, 2)
    assert len(runs) == 4  # the whole record and three later segments
    starts = np.array([y[first - 2 : first] for first, _ in runs])
    r0 = _simulation_error(model, u, y, p0, k0, starts)
    h = 1e-6
    cols = []
    for i in range(6):
        step = np.eye(6)[i] * h
        plus = _simulation_error(model, u, y, p0 + step[:5], k0 + step[5], starts)
        minus = _simulation_error(model, u, y, p0 - step[:5], k0 - step[5], starts)
        cols.append((plus - minus) / (2 * h))
    jac = np.column_stack(cols)
    g = np.zeros((r0.size, starts.size))  # linear in the start values: one-sided is exact
    for c in range(starts.size):
        g[:, c] = -(
            _simulation_error(
                model, u, y, p0, k0, starts + np.eye(starts.size)[c].reshape(starts.shape)
            )
            - r0
        )
    times = np.concatenate([np.arange(first, end) for first, end in runs]) - 2
    pick = np.eye(y.size - 2)[times]  # P: error row <- its noise sample (times 2 .. T-1)
    sel = np.zeros((starts.size, y.size - 2))  # S: start value (run i, lag) <- noise sample
    for i in range(1, len(runs)):
        for lag in range(2):
            sel[2 * i + lag, runs[i][0] - 2 + lag - 2] = 1.0
    dof = y.size - 2 - 6  # the noise variance from the first run: every sample once
    s2 = float(r0[: y.size - 2] @ r0[: y.size - 2]) / dof
    inv = np.linalg.inv(jac.T @ jac)
    w = jac.T @ (pick - g @ sel)
    h0 = inv @ jac.T @ g[:, :2]
    cov = s2 * inv @ w @ w.T @ inv + s2 * h0 @ h0.T
    np.testing.assert_allclose(model.info["covariance"], cov[:5, :5], rtol=1e-4)
    assert model.info["covariance_dof"] == dof
    assert model.info["noise_model"] == "output-error"


def test_oe_model_has_verdict_summary_and_simulation_residuals():
    u, y = _output_noise(1, 600)
    model = clpc.OE(order=2).fit(u, y)
    assert model.info["covariance_method"] == "Jacobian of the simulation error"
    held = model.info["heldout"]
    assert held["free_run"] > 80 and held["kstep"] > 80  # a correct model, 0.5 noise
    assert model.info["residual_test"]["kind"] == "simulation"
    verdict = model.verdict()
    assert verdict.heldout_fit == held["free_run"] and verdict.adequate is True
    text = str(verdict)
    assert "held-out fit" in text and "free run" in text and "residuals" in text
    summary = model.summary()
    assert "y = num(z)/den(z) u + e" in summary and "+-" in summary
    assert clpc.residual_analysis(model, u, y).kind == "simulation"


def test_oe_miso_and_delay_covariance():
    rng = np.random.default_rng(4)
    u = rng.standard_normal((800, 2))
    y = signal.lfilter([0.0, 1.0, 0.5], DEN, u[:, 0]) + signal.lfilter(
        [0.0, 0.3, -0.2], DEN, u[:, 1]
    )
    y = y + 0.3 * rng.standard_normal(800)
    model = clpc.OE(na=2, nb=1, nk=1).fit(u, y[:, None])
    cov = model.info["covariance"]
    assert cov.shape == (8, 8)  # a1 a2, (b0 b1 b2) per input; single output: no output axis
    std = np.sqrt(np.diag(cov))
    assert std[2] == 0 and std[5] == 0  # the delayed b0 of each input is fixed at 0
    assert np.all(std[[0, 1, 3, 4, 6, 7]] > 0)
    lo, hi = model.confidence_interval(0.99)
    truth = np.r_[DEN[1:], 0.0, 1.0, 0.5, 0.0, 0.3, -0.2]
    assert np.all((lo <= truth) & (truth <= hi))
    assert model.info["heldout"]["free_run"] > 80


def test_predict_of_an_output_error_model_is_the_free_run():
    u, y = _output_noise(2, 400)
    oe = clpc.OE(order=2, assess=False, uncertainty=False).fit(u, y)
    free = oe.simulate(u[2:], y_init=y[:2], u_init=u[:2])
    for k in (1, 5):
        pred = oe.predict(u, y, k=k)
        np.testing.assert_array_equal(pred[:2], y[:2])
        np.testing.assert_allclose(pred[2:], free, rtol=0, atol=1e-12)
    # the same coefficients as an equation-error model: the ARX recursion, which differs
    ee = replace(oe, info={k: v for k, v in oe.info.items() if k != "noise_model"})
    one = ee.predict(u, y, k=1)
    manual = -oe.den[1] * y[1:-1] - oe.den[2] * y[:-2] + signal.lfilter(oe.num, [1.0], u)[2:]
    np.testing.assert_allclose(one[2:], manual + oe.intercept[0], atol=1e-12)
    assert np.max(np.abs(one[2:] - free)) > 0.1
    bad = replace(oe, info={**oe.info, "noise_model": "colored"})
    with pytest.raises(ModelError, match="noise_model"):
        bad.predict(u, y)


def _two_outputs(seed: int) -> clpc.IOData:
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((600, 2))
    y = np.column_stack(
        [
            signal.lfilter([0.5, 0.2], [1, -0.6], u[:, 0]),
            signal.lfilter([1.0, 0.0], [1, -0.3], u[:, 1]),
        ]
    )
    return clpc.as_iodata(u, y + 0.1 * rng.standard_normal(y.shape))


def test_identify_mix_keeps_covariance_noise_model_and_evidence():
    data = _two_outputs(6)
    model = comparison.final_model(data, ("arx", "oe"), clpc.Structure(1, 1, 0), None)
    arx = clpc.ARX(order=1, assess=False).fit(data)
    oe = clpc.OE(order=1, assess=False).fit(data)
    assert model.info["noise_model"] == ["equation-error", "output-error"]
    np.testing.assert_allclose(model.info["covariance"][0], arx.info["covariance"][0])
    np.testing.assert_allclose(model.info["covariance"][1], oe.info["covariance"][1])
    np.testing.assert_array_equal(
        model.info["covariance_dof"], [arx.info["covariance_dof"][0], oe.info["covariance_dof"][1]]
    )
    # predict: output 0 the equation-error recursion, output 1 the free run
    pred = model.predict(data.u, data.y, k=3)
    np.testing.assert_allclose(pred[:, 0], arx.predict(data.u, data.y, k=3)[:, 0], atol=1e-12)
    np.testing.assert_allclose(pred[:, 1], oe.predict(data.u, data.y, k=3)[:, 1], atol=1e-12)
    assert model.info["heldout"]["free_run"] > 80
    assert model.info["residual_test"]["kind"] == "prediction"
    assert len(model.info["residual_test"]["white"]) == 2
    assert "held-out fit" in str(model.verdict(1))
    text = format_model_summary(model_summary(model))
    assert text.startswith("identify: ARX, OE model")


def test_identify_returns_the_model_with_its_evidence():
    u, y = _output_noise(5, 600)
    result = clpc.identify(u, y, estimator="oe")
    model = result.model
    assert model.info["noise_model"] == "output-error"
    lo, hi = model.confidence_interval()
    s = result.structure
    assert lo.shape == (s.na + s.nb + 1,) and np.all(lo < hi)  # a1..a_na, b0..b_nb
    assert "free_run" in model.info["heldout"]


@pytest.mark.parametrize(
    ("make", "name"),
    [
        (lambda: clpc.LPC(order=2), "LPC"),
        (lambda: clpc.ARX(order=2), "ARX (least squares)"),
        (lambda: clpc.OE(order=2), "OE (output error)"),
    ],
)
def test_text_summary_names_the_estimator(make, name):
    u, y = _output_noise(8, 300)
    summary = model_summary(make().fit(u, y))
    assert estimator_name(summary) == name
    assert format_model_summary(summary).startswith(f"{name} model  na=2")


def test_estimator_name_of_other_methods():
    assert estimator_name({"method": "clpc-steady-state"}) == "CLPC"
    assert (
        estimator_name({"method": "identify", "estimators": ["oe", "lpc"]}) == "identify: OE, LPC"
    )
    assert estimator_name({"method": None}) == "linear"


def test_rank_deficient_fits_keep_the_model_and_say_why_there_is_no_covariance():
    # two identical inputs: the regressors (and OE's Jacobian) are exactly rank deficient
    rng = np.random.default_rng(9)
    u1 = rng.standard_normal(300)
    u = np.column_stack([u1, u1])
    y = signal.lfilter([0.0, 1.0], [1.0, -0.5], u1) + 0.1 * rng.standard_normal(300)
    for est in (clpc.ARX(order=1, assess=False), clpc.OE(order=1, assess=False)):
        model = est.fit(u, y[:, None])
        assert "covariance" not in model.info
        assert "rank deficient" in model.info["covariance_note"]
        with pytest.raises(ModelError, match="no parameter covariance"):
            model.confidence_interval()
    # badly scaled but well determined regressors (condition number ~1e7) keep theirs
    v = np.column_stack([u1, 1e7 * rng.standard_normal(300)])
    assert "covariance" in clpc.ARX(order=1, assess=False).fit(v, y[:, None]).info


def test_cli_names_the_estimator_in_the_summary_and_the_report(tmp_path):
    args = ["identify", str(ds.path("dryer")), "-u", "u", "-y", "y", "--nk", "3", "--order", "2"]
    res = CliRunner().invoke(cli, [*args, "--estimator", "oe", "--report", str(tmp_path / "r")])
    assert res.exit_code == 0, res.output
    assert "\nOE (output error) model  na=2 nb=2 nk=3  method=output-error" in res.output
    assert "parameters (+- 1 sigma): den1" in res.output  # the OE covariance reaches the CLI
    html = (tmp_path / "r" / "report.html").read_text()
    assert "identify report (OE (output error) model)" in html
    plain = CliRunner().invoke(cli, [*args, "--estimator", "lpc"])
    assert plain.exit_code == 0 and plain.output.startswith("LPC model  na=2")
