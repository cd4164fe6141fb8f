"""Metrics against hand computations: fit % (MATLAB compare NRMSE), RMSE, VAF, k-step fit,
Ljung-Box whiteness."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal, stats

from clpc import fit_percent, kstep_fit, rmse, simulate_arx, vaf, whiteness_test
from clpc.analysis.metrics import WhitenessResult

Y = [1.0, 2.0, 4.0, 3.0, 5.0]
Y_HAT = [1.5, 2.0, 3.0, 3.5, 4.0]


def test_fit_percent_by_hand():
    # MATLAB compare: 100 * (1 - ||y - y_hat|| / ||y - mean(y)||)
    err = math.sqrt(0.25 + 0 + 1 + 0.25 + 1)  # sqrt(2.5)
    ref = math.sqrt(4 + 1 + 1 + 0 + 4)  # mean 3 -> sqrt(10)
    assert fit_percent(Y, Y_HAT) == pytest.approx(100 * (1 - err / ref), rel=1e-14)
    assert fit_percent(Y, Y) == 100.0
    assert fit_percent(Y, [3.0] * 5) == pytest.approx(0.0, abs=1e-12)  # as good as the mean
    assert fit_percent(Y, [0.0] * 5) < 0


def test_fit_percent_constant_reference():
    assert fit_percent([2.0, 2.0, 2.0], [2.0, 2.0, 2.0]) == 100.0
    assert fit_percent([2.0, 2.0, 2.0], [2.0, 2.5, 2.0]) == -np.inf


def test_rmse_by_hand():
    assert rmse(Y, Y_HAT) == pytest.approx(math.sqrt(2.5 / 5), rel=1e-14)
    assert rmse(Y, Y) == 0.0


def test_vaf_by_hand():
    e = np.array(Y) - np.array(Y_HAT)  # [-0.5, 0, 1, -0.5, 1], mean 0.2
    var_e = sum((v - 0.2) ** 2 for v in e) / 5
    var_y = 10 / 5
    assert vaf(Y, Y_HAT) == pytest.approx(100 * (1 - var_e / var_y), rel=1e-14)
    # a constant offset error is "accounted for" by VAF but not by fit %
    shifted = np.array(Y) + 1.0
    assert vaf(Y, shifted) == pytest.approx(100.0)
    assert fit_percent(Y, shifted) < 100.0


def test_vaf_constant_reference():
    # regression: a constant y used to give 100 whatever the model did
    assert vaf([2.0, 2.0, 2.0], [3.0, 3.0, 3.0]) == 100.0  # constant error: all "accounted"
    assert vaf([2.0, 2.0, 2.0], [2.0, 2.5, 2.0]) == -np.inf


def test_per_channel_for_2d():
    y = np.column_stack([Y, np.array(Y) * 10])
    y_hat = np.column_stack([Y_HAT, np.array(Y) * 10])
    for metric in (fit_percent, rmse, vaf):
        out = metric(y, y_hat)
        assert isinstance(out, np.ndarray) and out.shape == (2,)
        assert out[0] == pytest.approx(metric(Y, Y_HAT), rel=1e-14)
    assert fit_percent(y, y_hat)[1] == 100.0
    assert isinstance(fit_percent(Y, Y_HAT), float)


@pytest.mark.parametrize("metric", [fit_percent, rmse, vaf])
def test_validation(metric):
    with pytest.raises(ValueError, match=r"same shape; got \(5,\) and \(4,\)"):
        metric(Y, Y_HAT[:4])
    with pytest.raises(ValueError, match=r"same shape; got \(5,\) and \(5, 1\)"):
        metric(Y, np.array(Y_HAT)[:, None])
    with pytest.raises(ValueError, match="y and y_hat are empty"):
        metric([], [])
    with pytest.raises(ValueError, match=r"must be finite; a diverging .* gives inf/NaN"):
        metric(Y, [1.0, np.inf, 3.0, 4.0, 5.0])
    with pytest.raises(ValueError, match="must be finite"):
        metric([1.0, np.nan, 3.0, 4.0, 5.0], Y)


# ----------------------------------------------------------------------------- k-step fit


def test_kstep_fit_equals_fit_of_the_prediction(make_model):
    model = make_model([1.0, -0.8], [0.0, 1.0], nk=1)
    gen = np.random.default_rng(31)
    u = gen.standard_normal(400)
    # equation-error noise: the one-step predictor is the optimal one for it
    y = simulate_arx([1.0, -0.8], [0.0, 1.0], u, noise=0.3 * gen.standard_normal(400))
    for k in (1, 4):
        pred = model.predict(u, y, k=k)
        start = 1 + k - 1  # max_lag, then the k - 1 predictions that see newer outputs
        assert kstep_fit(model, u, y, k=k) == pytest.approx(fit_percent(y[start:], pred[start:]))
    assert kstep_fit(model, u, y, k=1) > kstep_fit(model, u, y, k=4)
    # an exact model predicts noise-free data perfectly at any horizon
    clean = model.simulate(u)
    assert kstep_fit(model, u, clean, k=10) == pytest.approx(100.0, abs=1e-9)


# ----------------------------------------------------------------------------- whiteness


def naive_ljung_box(e, lags):
    e = np.asarray(e, float)
    n = len(e)
    m = math.fsum(e) / n
    d = [v - m for v in e]
    c0 = math.fsum(v * v for v in d)
    q = 0.0
    rho = []
    for k in range(1, lags + 1):
        r = math.fsum(d[t] * d[t - k] for t in range(k, n)) / c0
        rho.append(r)
        q += r * r / (n - k)
    return n * (n + 2) * q, np.array(rho)


def test_ljung_box_statistic_equals_naive_loop():
    e = np.random.default_rng(32).standard_normal(500) + 3.0
    res = whiteness_test(e, lags=15)
    q, rho = naive_ljung_box(e, 15)
    assert isinstance(res, WhitenessResult)
    assert res.statistic == pytest.approx(q, rel=1e-10)
    np.testing.assert_allclose(res.autocorrelation, rho, atol=1e-12)
    assert res.p_value == pytest.approx(stats.chi2.sf(q, 15), rel=1e-9)
    assert res.lags == 15


def test_white_noise_is_not_rejected():
    verdicts = [
        whiteness_test(np.random.default_rng(seed).standard_normal(2000)).is_white
        for seed in range(5)
    ]
    # 5 % level: with these fixed seeds none is (wrongly) rejected
    assert all(verdicts)


def test_ar1_is_rejected():
    for seed in range(5):
        w = np.random.default_rng(seed).standard_normal(2000)
        ar1 = signal.lfilter([1.0], [1.0, -0.5], w)
        res = whiteness_test(ar1)
        assert not res.is_white and res.p_value < 1e-6
        assert res.autocorrelation[0] == pytest.approx(0.5, abs=0.06)


def test_whiteness_validation():
    e = np.random.default_rng(33).standard_normal(30)
    with pytest.raises(ValueError, match=r"need 1 <= lags < len\(residuals\) - 1; got lags=0"):
        whiteness_test(e, lags=0)
    with pytest.raises(ValueError, match="got lags=29, len=30"):
        whiteness_test(e, lags=29)
    with pytest.raises(ValueError, match="residuals are constant: whiteness is undefined"):
        whiteness_test(np.full(30, 2.0))
