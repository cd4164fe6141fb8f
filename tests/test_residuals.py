"""Residual analysis (clpc.residual_analysis) and verdicts that cite the evidence."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy import signal, stats

import clpc
import clpc.datasets as ds
from clpc.model.residuals import RIDGE, _bartlett, _correlations, _quadratic

DEN = np.array([1.0, -1.5, 0.7])
NUM = np.array([0.0, 1.0, 0.5])


def record(seed: int, n: int = 1000) -> tuple[np.ndarray, np.ndarray]:
    """A colored input and white noise in the output equation (the ARX model is right)."""
    rng = np.random.default_rng(seed)
    u = signal.lfilter([1.0], [1.0, -0.5], rng.standard_normal(n))
    return u, clpc.simulate_arx(DEN, NUM, u, 0.5 * rng.standard_normal(n))


def test_bounds_hold_about_95_percent_of_lags_for_a_correct_model():
    inside_auto, inside_cross, white, indep = [], [], [], []
    for seed in range(100):
        u, y = record(seed)
        res = clpc.residual_analysis(clpc.ARX(order=2, assess=False).fit(u, y), u, y, level=0.95)
        inside_auto.append(np.mean(np.abs(res.autocorrelation[0, 1:]) <= res.auto_band))
        inside_cross.append(np.mean(np.abs(res.cross_correlation[0, 0]) <= res.cross_band[0, 0]))
        white.append(res.whiteness[0].passed)
        indep.append(res.independence[0].passed)
    assert 0.93 <= np.mean(inside_auto) <= 0.97
    assert 0.93 <= np.mean(inside_cross) <= 0.99  # in-sample LS zeroes lags nk..nk+nb
    assert np.mean(white) >= 0.90 and np.mean(indep) >= 0.90  # tests of size 5 %


def test_too_low_an_order_is_flagged():
    for seed in range(10):
        u, y = record(seed)
        res = clpc.residual_analysis(clpc.ARX(order=1, assess=False).fit(u, y), u, y)
        assert not res.passed
        assert not res.independence[0].passed
        assert "FAILED" in str(res)


def test_missing_delay_on_the_dryer_is_flagged_and_the_right_one_is_better():
    data = ds.load("dryer")
    res0 = clpc.residual_analysis(clpc.LPC(order=2, assess=False).fit(data), data.u, data.y)
    res3 = clpc.residual_analysis(clpc.LPC(order=2, nk=3, assess=False).fit(data), data.u, data.y)
    assert not res0.independence[0].passed
    assert res3.independence[0].statistic < 0.25 * res0.independence[0].statistic
    # the cross-correlation peaks at the missing delay (3 samples)
    assert res0.cross_lags[np.argmax(res0.cross_correlation[0, 0])] == 3


def test_statistics_match_direct_formulas():
    u, y = record(3, n=300)
    m = clpc.ARX(order=2, assess=False).fit(u, y)
    res = clpc.residual_analysis(m, u, y, max_lag=10)
    e = y[2:] - m.predict(u, y)[2:]
    e = e - e.mean()
    uc = u[2:] - u[2:].mean()
    n = e.size
    np.testing.assert_allclose(res.residuals[:, 0], e, atol=1e-12)
    rho = [np.sum(e[k:] * e[: n - k]) / np.sum(e * e) for k in range(11)]
    np.testing.assert_allclose(res.autocorrelation[0], rho, atol=1e-12)
    q = n * (n + 2) * sum(rho[k] ** 2 / (n - k) for k in range(1, 11))  # Ljung-Box
    assert res.whiteness[0].statistic == pytest.approx(q, rel=1e-10)
    assert res.whiteness[0].threshold == pytest.approx(stats.chi2.ppf(0.99, 10))
    cross = [
        np.sum(e[max(t, 0) :] * uc[: n - t] if t >= 0 else e[: n + t] * uc[-t:])
        / np.sqrt(np.sum(e * e) * np.sum(uc * uc))
        for t in range(-10, 11)
    ]
    np.testing.assert_allclose(res.cross_correlation[0, 0], cross, atol=1e-12)


def test_bartlett_covariance_is_the_double_sum():
    rng = np.random.default_rng(4)
    e, u = rng.standard_normal(200), signal.lfilter([1.0], [1, -0.8], rng.standard_normal(200))
    m = 4
    rho_e, rho_u = _correlations(e, e, 2 * m), _correlations(u, u, 2 * m)
    want = np.array(
        [
            [sum(rho_e[2 * m + k] * rho_u[2 * m + k + b - a] for k in range(-m, m + 1))
             for b in range(m + 1)]
            for a in range(m + 1)
        ]
    )  # fmt: skip
    np.testing.assert_allclose(_bartlett(rho_e, rho_u, m), want, atol=1e-12)
    # white residuals: P is the input's correlation matrix
    delta = np.zeros_like(rho_e)
    delta[2 * m] = 1.0
    toeplitz = rho_u[2 * m + np.arange(m + 1)[None, :] - np.arange(m + 1)[:, None]]
    np.testing.assert_allclose(_bartlett(delta, rho_u, m), toeplitz, atol=1e-12)


def test_output_error_models_use_simulation_errors():
    u, y = record(5)
    m = clpc.ARX(order=2, assess=False).fit(u, y)
    oe = replace(m, info={**m.info, "noise_model": "output-error"})
    res = clpc.residual_analysis(oe, u, y)
    assert res.kind == "simulation"
    sim = oe.simulate(u[2:], y_init=y[:2], u_init=u[:2])
    np.testing.assert_allclose(res.residuals[:, 0], (y[2:] - sim) - (y[2:] - sim).mean())
    assert clpc.residual_analysis(m, u, y).kind == "prediction"


def test_invalid_arguments_are_refused():
    u, y = record(6, n=200)
    m = clpc.ARX(order=2, assess=False).fit(u, y)
    with pytest.raises(ValueError, match="level"):
        clpc.residual_analysis(m, u, y, level=95)
    with pytest.raises(ValueError, match="kind"):
        clpc.residual_analysis(m, u, y, kind="free")
    with pytest.raises(ValueError, match="max_lag"):
        clpc.residual_analysis(m, u, y, max_lag=0)
    with pytest.raises(ValueError, match="shapes"):
        clpc.residual_analysis(m, u[:100], y)
    with pytest.raises(ValueError, match="at least 20"):
        clpc.residual_analysis(m, u[:15], y[:15])


def test_residual_figure():
    pytest.importorskip("matplotlib")
    from clpc.plotting import plot_residuals

    data = ds.load("industrial_dryer")
    m = clpc.LPC(order=2, assess=False).fit(data)
    res = clpc.residual_analysis(m, data.u, data.y)
    fig = plot_residuals(res)
    assert len(fig.axes) == 3 * (1 + 3)
    assert fig.axes[1].get_title().startswith("independence of y1_drybulb from u1_fuel")
    fig2 = plot_residuals(res, ax=fig.axes)  # draws on the given axes
    assert fig2 is fig
    with pytest.raises(ValueError, match="needs 12 axes"):
        plot_residuals(res, ax=fig.axes[:2])


# ---------------------------------------------------------------------------- verdicts
def test_dryer_default_fit_is_not_called_good():
    data = ds.load("dryer")
    verdict = clpc.LPC(order=2).fit(data).verdict()
    text = str(verdict)
    assert verdict.determined  # the eigenvalue structure alone ...
    assert verdict.adequate is False  # ... but the evidence says otherwise
    assert verdict.heldout_fit is not None and verdict.heldout_fit < 60.0
    assert text.startswith("the model does NOT describe the record well")
    assert "identifiability only, not a good fit" in text
    assert f"free run {verdict.heldout_fit:.1f} %" in text
    assert "residuals correlated with the input" in text


def test_a_correct_model_is_called_adequate():
    rng = np.random.default_rng(7)
    u0 = rng.standard_normal(3000)
    y0 = clpc.simulate_arx(DEN, NUM, u0)
    u, y = u0 + 0.02 * rng.standard_normal(3000), y0 + 0.02 * rng.standard_normal(3000)
    verdict = clpc.LPC(order=2, nk=1, nb=1).fit(u, y).verdict()
    assert verdict.adequate is True and verdict.heldout_fit > 95.0
    assert str(verdict).startswith("the model describes the record")
    arx = clpc.ARX(order=2, nk=1, nb=1).fit(*record(8))
    assert arx.verdict().adequate is True
    assert "no eigenvalue statistics (least squares has no eigenvalue" in str(arx.verdict())
    oe = clpc.OE(order=2, nk=1, nb=1).fit(*record(8))
    assert "no eigenvalue statistics (output error has no eigenvalue" in str(oe.verdict())


def test_evidence_round_trips_through_model_files(tmp_path):
    data = ds.load("dryer")
    m = clpc.LPC(order=2).fit(data)
    clpc.save_model(m, tmp_path / "m.json")
    loaded = clpc.load_model(tmp_path / "m.json")
    assert str(loaded.verdict()) == str(m.verdict())


def test_identify_report_shows_verdict_uncertainty_and_residuals(tmp_path):
    pytest.importorskip("matplotlib")
    from click.testing import CliRunner

    from clpc.cli import cli

    out = tmp_path / "r"
    lpc = ("--estimator", "lpc", "--order", "2", "--nk", "0")  # LPC's N = 2 misses the dryer
    args = ["identify", str(ds.path("dryer")), "-u", "u", "-y", "y", "--report", str(out), *lpc]
    res = CliRunner().invoke(cli, args)
    assert res.exit_code == 0, res.output
    assert f"wrote {out / 'report.html'}" in res.output
    assert "residual tests" in res.output and "parameters (+- 1 sigma): den1" in res.output
    page = (out / "report.html").read_text()
    for heading in ("Result: the model", "Parameters and their uncertainty", "Residual analysis"):
        assert f"<h2>{heading}</h2>" in page
    assert (out / "residuals.png").stat().st_size > 0 and (out / "bode.png").stat().st_size > 0
    assert "the model does NOT describe the record well" in page


def test_quadratic_form_is_the_ridged_solve_and_survives_an_indefinite_matrix():
    rng = np.random.default_rng(11)
    a = rng.standard_normal((6, 6))
    pd, r = a @ a.T + np.eye(6), rng.standard_normal(6)
    eps = RIDGE * pd.diagonal().max()
    want = r @ np.linalg.solve(pd + eps * np.eye(6), r)
    assert _quadratic(pd, r) == pytest.approx(want, rel=1e-10)
    indefinite = np.diag([1.0, 1.0, -0.5])  # the eigenvalue -0.5 is clipped at eps
    got = _quadratic(indefinite, np.array([0.0, 0.0, 1.0]))
    assert got == pytest.approx(1.0 / (RIDGE * 1.0), rel=1e-10)


def test_each_output_is_judged_on_its_own_held_out_fit():
    data = ds.load("cd_player_arm")
    m = clpc.LPC(order=2).fit(data)
    held = m.info["heldout"]
    split = held["split"]
    refit = clpc.LPC(order=2, assess=False, uncertainty=False).fit(data[:split])
    sim = refit.simulate(data.u)
    val = data.y[split:, 1]  # output y2 alone, against a direct computation
    want = 100 * (1 - np.linalg.norm(val - sim[split:, 1]) / np.linalg.norm(val - val.mean()))
    assert m.verdict(1).heldout_fit == pytest.approx(want, rel=1e-12)
    assert m.verdict(0).heldout_fit == -np.inf  # y1's equation is unstable: its free run diverges
    assert "free run diverges" in str(m.verdict(0))
