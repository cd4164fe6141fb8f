"""The excitation-aware (robust) solution on records built to contain the paper's failure."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

import clpc
from clpc import LPC, ModelError

DEN = np.array([1.0, -1.5, 0.7])
NUM = np.array([0.2, 0.5, 0.1])


SCALES = [1.0, 1e-3, 1e3]  # the input in other units: the protections must not depend on them


@pytest.mark.parametrize("k", SCALES)
def test_collinear_inputs_paper_fails_robust_recovers(k):
    # two inputs that are always equal: u1 - u2 = 0 is a relation of the input alone
    rng = np.random.default_rng(0)
    n = 4000
    w = rng.standard_normal(n)
    u = k * np.column_stack([w, w])
    y = clpc.simulate_arx(DEN, NUM, w) + 0.01 * rng.standard_normal(n)
    paper = LPC(order=2, method="paper", mimo="miso").fit(u, y)
    assert abs(paper.theta[0]) < 1e-6  # the input-only relation won: no y(n) at all
    with pytest.raises(ModelError, match="a0 of output 0 is about 0"):
        _ = paper.denominators
    robust = LPC(order=2, mimo="miso").fit(u, y)
    np.testing.assert_allclose(robust.denominators[0], DEN, atol=2e-3)
    # the input part is the minimum-norm split: the two numerators sum to the true one
    np.testing.assert_allclose(k * robust.numerators[0].sum(axis=0), NUM, atol=3e-3)
    np.testing.assert_allclose(k * robust.numerators[0, 0], k * robust.numerators[0, 1], atol=1e-9)
    verdict = clpc.fit_verdict(robust)
    assert not verdict.persistently_exciting and not verdict.determined
    assert "not persistently exciting of order 3" in str(verdict)


@pytest.mark.parametrize("k", SCALES)
def test_ramp_input_paper_picks_the_input_relation(k):
    # the paper's command: a ramp that saturates; its second difference is zero
    rng = np.random.default_rng(1)
    n = 3000
    ramp = np.clip((np.arange(n) - 500) / 800.0, 0.0, 1.0)
    u = k * (ramp + 1e-5 * rng.standard_normal(n))
    y = clpc.simulate_arx(DEN, NUM, ramp) + 1e-3 * rng.standard_normal(n)
    if k == 1.0:  # the literal eigenvector picks the input's own relation
        th = LPC(order=2, method="paper").fit(u, y).theta
        second_difference = np.array([0, 0, 0, 1, -2, 1]) / np.sqrt(6)
        assert abs(th @ second_difference) > 0.99
    robust = LPC(order=2).fit(u, y)
    assert robust.info["a0_weight"] > 0.1  # it determines y(n), in any units
    if k == 1.0:  # equal noise levels: the input's relation is as near-null as the system's
        assert robust.info["n_input_relations"] >= 1  # the input is not exciting
        assert not robust.info["determined"]
    # what it identified does explain the data
    assert clpc.kstep_fit(robust, u, y, k=1) > 95.0


@pytest.mark.parametrize("k", SCALES)
def test_order_larger_than_the_system(k):
    rng = np.random.default_rng(2)
    n = 20000
    den1, num1 = np.array([1.0, -0.8]), np.array([0.5, 0.3])
    u0 = rng.standard_normal(n)
    y0 = signal.lfilter(num1, den1, u0)
    u = u0 + 0.05 * rng.standard_normal(n)
    y = y0 + 0.05 * rng.standard_normal(n)
    robust = LPC(order=3).fit(k * u, y)
    verdict = clpc.fit_verdict(robust)
    # the extra factors common to A and B are cancelled and the verdict says so
    assert robust.info["cancelled"] == 2 and robust.structure.na == 1
    assert "order larger than the data support" in str(verdict)
    assert robust.is_stable
    if k == 1.0:  # equal noise: the extra relations are equally small (near-null subspace)
        assert robust.info["n_null"] >= 2
    kept = LPC(order=3, cancel=False).fit(k * u, y)
    assert kept.structure.na == 3 and kept.info.get("cancelled", 0) == 0
    freqs = np.linspace(0.01, 0.45, 50)
    _, h_true = signal.freqz(num1, den1, worN=freqs, fs=1.0)
    _, h_rob = robust.frequency_response(freqs)
    assert np.max(np.abs(k * h_rob - h_true) / np.abs(h_true)) < 0.05
    # the free-run simulation follows the noise-free output
    assert clpc.fit_percent(y0, robust.simulate(k * u0, include_offset=False)) > 95.0


def test_robust_equals_paper_on_well_excited_data():
    rng = np.random.default_rng(3)
    u = rng.standard_normal(5000)
    y = clpc.simulate_arx(DEN, NUM, u)
    a = LPC(order=2, method="paper").fit(u, y)
    b = LPC(order=2).fit(u, y)
    np.testing.assert_allclose(a.den, b.den, atol=1e-10)
    np.testing.assert_allclose(a.num, b.num, atol=1e-10)
    assert b.info["determined"] and b.info["n_null"] == 1


def test_std_scaling_is_unit_free():
    rng = np.random.default_rng(4)
    u = rng.standard_normal(5000)
    y = clpc.simulate_arx(DEN, NUM, u) + 0.1 * rng.standard_normal(5000)
    base = LPC(order=2, scaling="std").fit(u, y)
    scaled = LPC(order=2, scaling="std").fit(1000.0 * u, y)
    np.testing.assert_allclose(scaled.num, base.num / 1000.0, rtol=1e-9)
    np.testing.assert_allclose(scaled.den, base.den, rtol=1e-9)


def test_model_carries_its_verdict():
    rng = np.random.default_rng(5)
    u = rng.standard_normal(3000)
    y = clpc.simulate_arx(DEN, NUM, u) + 0.01 * rng.standard_normal(3000)
    model = LPC(order=2).fit(u, y)
    assert model.verdict().determined
    assert "the data determine the parameters" in str(model.verdict())
