"""Parameter uncertainty: covariances, intervals and the delta method.

Calibration is checked over 200 fixed seeds against the true parameters; the jackknife
against explicit refits without each segment; least squares against the textbook formula
with an explicit intercept column; the Jacobian covariance against scipy's ``curve_fit``;
the delta method against Monte Carlo spreads.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy import optimize

import clpc
from clpc.lpc import lpc_solve, structure_blocks
from clpc.lpc.regressors import regressors
from clpc.lpc.uncertainty import (
    covariance_from_jacobian,
    least_squares_covariance,
    lpc_jackknife,
    monic_map,
)
from clpc.model import ModelError

DEN = np.array([1.0, -1.5, 0.7])
NUM = np.array([0.5, 1.0, 0.5])
TRUE = np.r_[DEN[1:], NUM]
SEEDS = range(200)


def eiv_record(seed: int, n: int = 1000, noise: float = 0.3) -> tuple[np.ndarray, np.ndarray]:
    """Errors in variables: equal white noise on the measured input and output."""
    rng = np.random.default_rng(seed)
    u0 = rng.standard_normal(n)
    y0 = clpc.simulate_arx(DEN, NUM, u0)
    return u0 + noise * rng.standard_normal(n), y0 + noise * rng.standard_normal(n)


def equation_error_record(seed: int, n: int = 400, noise: float = 0.5) -> tuple[np.ndarray, ...]:
    """Exact input, white noise entering the output equation ``A y = B u + e``."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    return u, clpc.simulate_arx(DEN, NUM, u, noise * rng.standard_normal(n))


def coverage(estimator, record) -> np.ndarray:
    hits = []
    for seed in SEEDS:
        lo, hi = estimator.fit(*record(seed)).confidence_interval(0.95)
        hits.append((lo <= TRUE) & (TRUE <= hi))
    return np.mean(hits, axis=0)


def test_lpc_intervals_are_calibrated_on_errors_in_variables_records():
    cover = coverage(clpc.LPC(order=2, assess=False), eiv_record)
    assert np.all((cover >= 0.90) & (cover <= 0.99)), cover


def test_arx_intervals_are_calibrated_on_output_equation_noise():
    cover = coverage(clpc.ARX(order=2, assess=False), equation_error_record)
    assert np.all((cover >= 0.90) & (cover <= 0.99)), cover


def test_jackknife_replicates_are_refits_without_each_segment():
    u, y = eiv_record(1, n=600)
    data = clpc.as_iodata(u, y)
    s = clpc.Structure(2, 2, 0)
    mats = regressors(data, s, "siso")
    blocks = structure_blocks(s, 1)
    n_blocks = 10
    edges = np.arange(n_blocks + 1) * (mats.shape[1] // n_blocks)
    edges[-1] = mats.shape[1]
    lmap = monic_map(s, 1, "siso")

    def to_monic(theta, j):
        return (theta[:, 1:] / theta[:, :1]) @ lmap.T

    reps = []  # the reference: an SVD solve of the remaining rows, segment by segment
    for a, b in itertools.pairwise(edges):
        rest = np.delete(mats, np.s_[a:b], axis=1)
        reps.append(to_monic(lpc_solve(rest, n_output_cols=3, blocks=blocks).theta, 0)[0])
    dev = np.array(reps) - np.mean(reps, axis=0)
    expected = (n_blocks - 1) / n_blocks * dev.T @ dev

    def solve(scatter, mean, rows):
        from clpc.lpc.solve import solve_scatter

        return solve_scatter(scatter, mean, rows, n_output_cols=3, blocks=blocks).theta

    got = lpc_jackknife(mats, solve, to_monic, n_blocks)[0]
    np.testing.assert_allclose(got, expected, rtol=1e-7, atol=1e-14)


def test_least_squares_covariance_is_the_textbook_formula_with_an_intercept():
    rng = np.random.default_rng(3)
    x = rng.standard_normal((200, 3)) + np.array([1.0, -2.0, 5.0])
    y = x @ [0.5, -1.0, 2.0] + 3.0 + rng.standard_normal(200)
    full = np.column_stack([x, np.ones(200)])
    coef, *_ = np.linalg.lstsq(full, y, rcond=None)
    resid = y - full @ coef
    s2 = resid @ resid / (200 - 4)
    expected = s2 * np.linalg.inv(full.T @ full)[:3, :3]
    xc = x - x.mean(axis=0)
    cov, dof = least_squares_covariance(xc, resid)
    assert dof == 196
    np.testing.assert_allclose(cov, expected, rtol=1e-10)


def test_jacobian_covariance_matches_scipy_curve_fit():
    rng = np.random.default_rng(4)
    t = np.linspace(0.0, 4.0, 80)
    y = 2.0 * np.exp(-0.7 * t) + 0.05 * rng.standard_normal(t.size)

    def f(t, a, k):
        return a * np.exp(-k * t)

    popt, pcov = optimize.curve_fit(f, t, y, p0=[1.0, 1.0])
    jac = np.column_stack([np.exp(-popt[1] * t), -popt[0] * t * np.exp(-popt[1] * t)])
    cov, dof = covariance_from_jacobian(jac, y - f(t, *popt))
    assert dof == 78
    np.testing.assert_allclose(cov, pcov, rtol=1e-6)


def test_jacobian_covariance_refuses_rank_deficient_or_short_inputs():
    jac = np.ones((10, 2))
    with pytest.raises(ValueError, match="rank deficient"):
        covariance_from_jacobian(jac, np.zeros(10))
    with pytest.raises(ValueError, match="more rows than parameters"):
        covariance_from_jacobian(np.eye(2), np.zeros(2))


def test_delta_method_std_of_pole_gain_and_response_agrees_with_monte_carlo():
    est = clpc.ARX(order=2, assess=False)
    poles, gains, mags = [], [], []
    p_std, g_std, m_std = [], [], []
    freqs = np.array([0.05, 0.2])
    for seed in range(300):
        m = est.fit(*equation_error_record(seed, n=1000))
        p, sp = m.pole_std()
        i = int(np.argmax(p.imag))
        poles.append([p[i].real, p[i].imag])
        p_std.append(sp[i])
        gains.append(m.dc_gain()[0, 0])
        g_std.append(m.dc_gain_std()[0, 0])
        _, h, sm, _ = m.frequency_response_std(freqs)
        mags.append(np.abs(h))
        m_std.append(sm)
    for mc, delta in (
        (np.std(poles, axis=0), np.mean(p_std, axis=0)),
        (np.std(gains), np.mean(g_std)),
        (np.std(mags, axis=0), np.mean(m_std, axis=0)),
    ):
        ratio = np.atleast_1d(delta / mc)
        assert np.all((ratio > 0.8) & (ratio < 1.25)), ratio


def test_delta_method_is_exact_for_a_linear_function():
    u, y = equation_error_record(5)
    m = clpc.ARX(order=2, assess=False).fit(u, y)
    cov = m.covariance[0]
    weights = np.array([1.0, -2.0, 0.5, 0.0, 3.0])
    from clpc.model.uncertainty import delta_std, parameter_vector

    got = delta_std(lambda s: (s @ weights)[:, None], parameter_vector(m)[0], cov)
    np.testing.assert_allclose(got, np.sqrt(weights @ cov @ weights), rtol=1e-6)


def test_interval_layout_siso_and_miso():
    u, y = eiv_record(6)
    m = clpc.LPC(order=2, nk=1, assess=False).fit(u, y)
    lo, hi = m.confidence_interval()
    assert lo.shape == hi.shape == (np.r_[m.den[1:], m.num].size,)
    assert np.all(lo <= np.r_[m.den[1:], m.num]) and np.all(hi >= np.r_[m.den[1:], m.num])
    assert lo[2] == hi[2] == 0.0  # the delay's structural zero
    lo99, hi99 = m.confidence_interval(0.99)
    assert np.all(hi99 - lo99 >= hi - lo)
    rng = np.random.default_rng(7)
    u2 = rng.standard_normal((800, 2))
    y2 = clpc.simulate_arx(DEN, NUM, u2[:, 0]) + clpc.simulate_arx(DEN, [0, 0.3, 0], u2[:, 1])
    y2 = y2 + 0.1 * rng.standard_normal(800)
    m2 = clpc.ARX(order=2, assess=False).fit(u2, y2)
    lo2, _ = m2.confidence_interval()
    assert lo2.shape == (1, 2 + 2 * 3)
    with pytest.raises(ValueError, match="level"):
        m.confidence_interval(1.5)


def test_reduced_lpc_model_gets_a_covariance_of_its_own_structure():
    rng = np.random.default_rng(2)  # as test_robust: order 3 on a first-order system
    u0 = rng.standard_normal(20000)
    y0 = clpc.simulate_arx([1.0, -0.8], [0.5, 0.3], u0)
    u, y = u0 + 0.05 * rng.standard_normal(20000), y0 + 0.05 * rng.standard_normal(20000)
    m = clpc.LPC(order=3, assess=False).fit(u, y)
    assert m.info["cancelled"] == 2 and m.structure.na == 1
    assert m.covariance.shape == (1, 3, 3)
    assert "reduced order" in m.info["covariance_method"]
    lo, hi = m.confidence_interval()
    assert np.all((lo <= [-0.8, 0.5, 0.3]) & ([-0.8, 0.5, 0.3] <= hi))


def test_models_without_a_covariance_say_why():
    u, y = eiv_record(9, n=40)
    m = clpc.LPC(order=2, assess=False).fit(u, y)
    with pytest.raises(ModelError, match="too few"):
        m.confidence_interval()
    hand = clpc.LinearModel(theta=[[1.0, -0.5, 0.0, -1.0]], structure=clpc.Structure(1, 1, 0),
                            n_inputs=1, mode="siso", c=[0.0])  # fmt: skip
    with pytest.raises(ModelError, match="no parameter covariance"):
        hand.confidence_interval()
    assert "+-" not in hand.summary().split("\n", 2)[2]


def test_summary_shows_coefficients_with_sigma():
    u, y = eiv_record(10)
    m = clpc.LPC(order=2, assess=False).fit(u, y)
    text = m.summary()
    sigma = np.sqrt(np.diag(m.covariance[0]))
    assert "block jackknife over 20 segments" in text
    assert f"den1         {m.den[1]: .6g} +- {sigma[0]:.3g}" in text
    assert "pole 1" in text and "DC gain u -> y" in text


def test_a_jackknife_that_cannot_run_leaves_a_note_not_a_failed_fit():
    rng = np.random.default_rng(2)  # order 3 reduced to 1: a noise_cov of 8 entries no longer fits
    u0 = rng.standard_normal(20000)
    y0 = clpc.simulate_arx([1.0, -0.8], [0.5, 0.3], u0)
    u, y = u0 + 0.05 * rng.standard_normal(20000), y0 + 0.05 * rng.standard_normal(20000)
    m = clpc.LPC(order=3, noise_cov=np.ones(8), assess=False).fit(u, y)
    assert m.structure.na == 1
    assert "the jackknife could not run" in m.info["covariance_note"]
    with pytest.raises(ModelError, match="jackknife could not run"):
        m.confidence_interval()
