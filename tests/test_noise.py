import numpy as np
import pytest

import clpc
from clpc import DataError
from clpc.lpc.noise import estimate_noise_variances

DEN = np.array([1.0, -1.5, 0.7])
NUM = np.array([0.2, 0.5, 0.1])


def eiv(seed, n=50_000, su=0.3, sy=0.1):
    rng = np.random.default_rng(seed)
    u0 = rng.standard_normal(n)
    y0 = clpc.simulate_arx(DEN, NUM, u0)
    scale = y0.std()
    return u0 + su * rng.standard_normal(n), y0 / scale + sy * rng.standard_normal(n), scale


@pytest.mark.parametrize("seed", [0, 1])
def test_noise_variances_recovered_and_make_weighted_lpc_consistent(seed):
    u, y, scale = eiv(seed)
    est = estimate_noise_variances(u, y, order=2)
    assert est.converged and est.reliable and not est.clamped
    assert est.order_agreement < 1.1 and "agrees" in est.reason
    assert est.output_variance == pytest.approx(0.01, rel=0.1)
    assert est.input_variance == pytest.approx(0.09, rel=0.1)
    weighted = clpc.LPC(order=2, noise_ratio=est.ratio).fit(u, y)
    plain = clpc.LPC(order=2, method="paper").fit(u, y)
    true = np.concatenate([DEN, NUM / scale])
    err_w = np.linalg.norm(np.concatenate([weighted.den, weighted.num]) - true)
    err_p = np.linalg.norm(np.concatenate([plain.den, plain.num]) - true)
    assert err_w < 0.01 < err_p


def test_noise_estimate_validation():
    with pytest.raises(ValueError, match="extra_lags"):
        estimate_noise_variances(np.ones(100), np.arange(100.0), extra_lags=0)
    with pytest.raises(DataError, match="one input and one output"):
        estimate_noise_variances(np.ones((100, 2)), np.arange(100.0))


def test_unreliable_estimates_say_why():
    # the dryer record at N = 2: the equations ask for a negative input variance (clamped),
    # and the ratio moves by orders of magnitude at N = 3: not a white-noise EIV record
    from clpc import datasets

    data = datasets.load("dryer")
    est = estimate_noise_variances(data, order=2)
    assert est.clamped and not est.reliable
    assert est.order_agreement > 1e3
    assert "floor" in est.reason and "factor" in est.reason
