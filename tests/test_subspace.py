"""Subspace identification (PO-MOESP): exact on noise-free data (SISO and 2x2), consistent
under output noise, O(T) memory, and a LinearModel like every other estimator's."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from scipy import signal

import clpc
from clpc.data import DataError
from clpc.lpc.subspace import Subspace

# two lightly damped modes: 0.98 e^{+-0.3j} (damping ~0.07) and 0.95 e^{+-1.2j}
_POLES = [0.98 * np.exp(0.3j), 0.95 * np.exp(1.2j)]
DEN = np.real(np.poly(np.r_[_POLES, np.conj(_POLES)]))
NUM = np.array([0.0, 0.5, -0.3, 0.2, 0.1])  # strictly proper (D = 0)
GRID = np.linspace(0.0, np.pi, 400, endpoint=False)

# 2 inputs, 2 outputs, 4 states (a lightly damped pair and two real modes)
A2 = np.array([[0.9, 0.3, 0, 0], [-0.3, 0.9, 0, 0], [0, 0, 0.7, 0.1], [0, 0, 0, 0.5]])
B2 = np.array([[1.0, 0.0], [0.5, -0.4], [0.0, 1.0], [0.3, 0.8]])
C2 = np.array([[1.0, 0.0, 0.6, -0.2], [0.0, 0.7, 0.0, 1.0]])
D2 = np.zeros((2, 2))

FAST = {"uncertainty": False, "assess": False}


def _siso(seed: int, n: int, snr_db: float | None = None):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = signal.lfilter(NUM, DEN, u)
    if snr_db is not None:
        y = y + rng.standard_normal(n) * np.std(y) * 10 ** (-snr_db / 20)
    return u, y


def _response_error(model: clpc.LinearModel, num=NUM, den=DEN, output=0, input=0) -> float:
    _, truth = signal.freqz(num, den, worN=GRID)
    _, est = signal.freqz(model.numerators[output, input], model.denominators[output], worN=GRID)
    return float(np.max(np.abs(est - truth) / np.abs(truth)))


# ----------------------------------------------------------------------- noise-free: exact
def test_noise_free_siso_is_recovered_exactly():
    u, y = _siso(0, 3000)
    model = Subspace(order=4, **FAST).fit(u, y)
    assert model.structure == clpc.Structure(4, 3, 1)  # D = 0: b0 multiplies u(n-1)
    assert _response_error(model) < 1e-8
    np.testing.assert_allclose(model.den, DEN, atol=1e-10)
    np.testing.assert_allclose(model.num, NUM, atol=1e-10)
    assert np.linalg.norm(model.theta) == pytest.approx(1.0)
    assert model.theta[0] > 0
    assert model.info["bd_form"] == "simulation error"


def test_auto_order_picks_four_on_noise_free_data():
    u, y = _siso(1, 3000)
    model = Subspace(**FAST).fit(u, y)
    assert model.info["order"] == 4
    assert model.structure.na == 4
    assert _response_error(model) < 1e-8
    sv = np.asarray(model.info["singular_values"])
    assert sv[0] == 1.0 and sv[4] < 1e-10 < sv[3]  # the gap after the 4th
    assert "order 4" in model.info["order_reason"]
    assert set(model.info["order_scores"]) >= {"3", "4", "5"}


def test_auto_model_is_the_fixed_order_model():
    u, y = _siso(13, 2500, snr_db=25.0)
    auto = Subspace(**FAST).fit(u, y)
    fixed = Subspace(order=auto.info["order"], **FAST).fit(u, y)
    np.testing.assert_array_equal(auto.theta, fixed.theta)
    assert auto.info["horizon"] == fixed.info["horizon"] == 10
    assert fixed.info["order_reason"] == "order 4 given"


def test_simulate_reproduces_dlsim_of_the_state_space_model():
    # a record from rest with no offset: the model's free run (offset included) is dlsim's
    u, y = _siso(2, 2000)
    model = Subspace(order=4, **FAST).fit(u, y)
    ss = model.info["state_space"]
    _, y_ss, _ = signal.dlsim((ss["A"], ss["B"], ss["C"], ss["D"], 1.0), u)
    np.testing.assert_allclose(model.simulate(u, include_offset=False), y_ss[:, 0], atol=1e-9)
    np.testing.assert_allclose(model.simulate(u), y, atol=1e-9 * np.max(np.abs(y)))
    assert abs(model.intercept[0]) < 1e-10


def test_noise_free_mimo_numerators_are_exact():
    rng = np.random.default_rng(3)
    u = rng.standard_normal((3000, 2))
    _, y, _ = signal.dlsim((A2, B2, C2, D2, 1.0), u)
    y = y + np.array([3.0, -1.0])  # operating point
    model = Subspace(order=4, **FAST).fit(u, y)
    assert model.mode == "miso" and model.n_outputs == 2 and model.n_inputs == 2
    den = np.poly(A2)
    for j in range(2):
        np.testing.assert_allclose(model.denominators[j], den, atol=1e-10)
        for i in range(2):
            num, _ = signal.ss2tf(A2, B2[:, i : i + 1], C2[j : j + 1], D2[j : j + 1, i : i + 1])
            np.testing.assert_allclose(model.numerators[j, i], num[0], atol=1e-10)
            assert _response_error(model, num[0], den, j, i) < 1e-8
    # the offset: the steady state of the free run is the operating point
    np.testing.assert_allclose(model.simulate(u)[500:], y[500:], atol=1e-9)
    poles = np.sort_complex(np.linalg.eigvals(A2))
    np.testing.assert_allclose(np.sort_complex(model.poles(1)), poles, atol=1e-9)
    assert Subspace(**FAST).fit(u, y).info["order"] == 4


def test_delay_and_feedthrough():
    rng = np.random.default_rng(4)
    u = rng.standard_normal(3000)
    den = np.real(np.poly([0.9, 0.5 + 0.3j, 0.5 - 0.3j]))
    num = np.array([0.3, 0.5, -0.2, 0.1])  # b0 = D != 0
    y = signal.lfilter(np.r_[0.0, 0.0, num], den, u)  # two samples of pure delay
    model = Subspace(order=3, nk=2, feedthrough=True, **FAST).fit(u, y)
    assert model.structure == clpc.Structure(3, 3, 2)
    np.testing.assert_allclose(model.num, np.r_[0.0, 0.0, num], atol=1e-10)
    np.testing.assert_allclose(model.simulate(u), y, atol=1e-10)
    ss = model.info["state_space"]
    assert ss["nk"] == 2 and abs(ss["D"][0, 0] - 0.3) < 1e-10
    # without feedthrough, nk = 1: one more state holds u(t-2), the model's b0 is at lag 2
    strict = Subspace(order=4, nk=1, **FAST).fit(u, y)
    assert strict.structure == clpc.Structure(4, 3, 2)
    assert _response_error(strict, np.r_[0.0, 0.0, num], den) < 1e-8


def test_integrator_gets_its_drift_from_the_constant_input():
    rng = np.random.default_rng(5)
    u = rng.standard_normal(3000) + 0.3  # a nonzero mean drives the integrator
    den, num = np.poly([1.0, 0.8]), np.array([0.0, 1.0, 0.5])
    y = signal.lfilter(num, den, u)
    model = Subspace(order=2, **FAST).fit(u, y)
    np.testing.assert_allclose(model.den, den, atol=1e-10)
    np.testing.assert_allclose(model.num, num, atol=1e-9)
    assert model.stability == "integrating"
    assert Subspace(**FAST).fit(u, y).info["order"] == 2


def test_unstable_data_stable_model_or_the_equation_error_form():
    rng = np.random.default_rng(6)
    u = rng.standard_normal(1200)
    den, num = np.poly([1.02, 0.5]), np.array([0.0, 1.0, 0.5])  # grows 1.02^1200 ~ 2e10
    y = signal.lfilter(num, den, u)
    model = Subspace(order=2, stable=False, **FAST).fit(u, y)
    assert model.info["bd_form"] == "equation error"
    assert model.info["state_space"]["a_form"] == "shift"
    np.testing.assert_allclose(model.den, den, atol=1e-5)
    np.testing.assert_allclose(model.num, num, atol=1e-5)
    # by default the poles are kept inside the unit circle (Maciejowski's shift)
    model = Subspace(order=2, **FAST).fit(u, y)
    assert model.info["state_space"]["a_form"] == "stabilised shift (Maciejowski)"
    assert model.is_stable


def test_several_experiments_and_paired_mode():
    u, y = _siso(7, 3000)
    parts = [clpc.IOData(u[:1400], y[:1400]), clpc.IOData(u[1400:], y[1400:])]
    model = Subspace(order=4, **FAST).fit(parts)
    assert _response_error(model) < 1e-8
    assert np.asarray(model.info["state_space"]["x0"]).shape == (2, 4)
    assert Subspace(**FAST).fit(parts).info["order"] == 4
    # paired: output j on input j only (two SISO systems)
    rng = np.random.default_rng(8)
    u2 = rng.standard_normal((2500, 2))
    y2 = np.c_[signal.lfilter(NUM, DEN, u2[:, 0]), signal.lfilter([0, 1.0], [1, -0.6], u2[:, 1])]
    paired = Subspace(mimo="paired", **FAST).fit(u2, y2)
    assert paired.mode == "paired" and paired.info["order"] == 4
    assert [r[:7] for r in paired.info["order_reason"]] == ["order 4", "order 1"]
    assert _response_error(paired) < 1e-8
    # the first-order pair is written at order 4 with poles and zeros at z = 0
    np.testing.assert_allclose(paired.denominators[1], [1, -0.6, 0, 0, 0], atol=1e-10)
    np.testing.assert_allclose(paired.numerators[1, 1], [0, 1.0, 0, 0, 0], atol=1e-10)


# ------------------------------------------------------------------- noisy: consistency
def test_noisy_estimate_is_consistent():
    # output noise at 20 dB SNR; the response error falls about as 1/sqrt(T) (sqrt(10) = 3.2)
    errors = {}
    for n in (2000, 20000):
        errs = []
        for seed in range(4):
            u, y = _siso(100 + seed, n, snr_db=20.0)
            model = Subspace(order=4, **FAST).fit(u, y)
            _, truth = signal.freqz(NUM, DEN, worN=GRID)
            _, est = signal.freqz(model.num, model.den, worN=GRID)
            errs.append(np.linalg.norm(est - truth) / np.linalg.norm(truth))
        errors[n] = float(np.mean(errs))
    assert errors[2000] / errors[20000] > 2.0
    assert errors[20000] < 0.01  # ~0.003 measured
    # the order is still found, and the poles are close to the truth
    u, y = _siso(200, 20000, snr_db=20.0)
    model = Subspace(**FAST).fit(u, y)
    assert model.info["order"] == 4
    truth = np.sort_complex(np.roots(DEN))
    np.testing.assert_allclose(np.sort_complex(model.poles()), truth, atol=0.01)


# ----------------------------------------------------------------------------- memory
def test_memory_is_linear_with_a_small_constant():
    n = 200_000
    u, y = _siso(9, n, snr_db=30.0)
    data = clpc.IOData(u, y)  # the record itself is not counted
    record = data.u.nbytes + data.y.nbytes
    peaks = {}
    for order in (4, "auto"):
        tracemalloc.start()
        try:
            model = Subspace(order=order, **FAST).fit(data)
            peaks[order] = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        assert model.info["order"] == 4
    assert max(peaks.values()) < 3 * record + 8 * 2**20, peaks


# -------------------------------------------------------------------------- interface
def test_model_interface_like_other_estimators(tmp_path):
    u, y = _siso(10, 3000, snr_db=30.0)
    data = clpc.IOData(u, y + 2.0, dt=0.01, input_names=["v"], output_names=["pos"])
    model = clpc.Subspace(order=4).fit(data)
    assert isinstance(model, clpc.LinearModel) and model.dt == 0.01
    assert model.input_names == ("v",) and model.output_names == ("pos",)
    assert model.simulate(u).shape == (3000,)
    pred = model.predict(u, y + 2.0, k=5)
    assert pred.shape == (3000,) and clpc.fit_percent(y[100:] + 2.0, pred[100:]) > 90
    poles = np.sort_complex(np.roots(DEN))
    np.testing.assert_allclose(np.sort_complex(model.poles()), poles, atol=0.02)
    gain = float(np.sum(NUM) / np.sum(DEN))
    assert model.dc_gain()[0, 0] == pytest.approx(gain, rel=0.02)
    assert model.is_stable
    assert model.to_scipy().dt == 0.01
    # no covariance, and it says why; the verdict and the summary name the estimator
    assert "closed-form" in model.info["covariance_note"]
    assert model.info["method"] == "subspace"
    assert "subspace identification has no eigenvalue" in str(model.verdict())
    from clpc.report.text import estimator_name

    assert estimator_name(model.info) == "subspace (PO-MOESP)"
    # the evidence on demand: a refit at the fitted order on the first two thirds
    model.assess()
    assert model.info["heldout"]["free_run"] > 90
    path = tmp_path / "subspace.json"
    clpc.save_model(model, path)
    back = clpc.load_model(path)
    np.testing.assert_array_equal(back.theta, model.theta)
    np.testing.assert_allclose(back.simulate(u), model.simulate(u))
    np.testing.assert_allclose(back.info["state_space"]["A"], model.info["state_space"]["A"])
    assert back.info["order_reason"] == model.info["order_reason"]


def test_same_model_from_arrays_and_from_iodata():
    u, y = _siso(11, 1500, snr_db=25.0)
    a = Subspace(order=4, **FAST).fit(u, y, dt=0.5)
    b = Subspace(order=4, **FAST).fit(clpc.IOData(u, y, dt=0.5))
    np.testing.assert_array_equal(a.theta, b.theta)
    assert a.dt == b.dt == 0.5


# ------------------------------------------------------------------------- validation
def test_clear_errors():
    u, y = _siso(12, 3000)
    with pytest.raises(DataError, match="needs horizon >= 5"):
        Subspace(order=4, **FAST).fit(u[:25], y[:25])
    with pytest.raises(DataError, match="first two thirds"):
        Subspace(**FAST).fit(u[:60], y[:60])
    with pytest.raises(DataError, match="Hankel columns"):
        Subspace(order=2, horizon=60, **FAST).fit(u[:300], y[:300])
    with pytest.raises(ValueError, match="horizon=3 is too small for order 4"):
        Subspace(order=4, horizon=3, **FAST).fit(u, y)
    bad = y.copy()
    bad[7] = np.nan
    with pytest.raises(DataError, match=r"finite|NaN"):
        Subspace(order=2, **FAST).fit(u, bad)
    with pytest.raises(DataError, match="constant channel"):
        Subspace(order=2, **FAST).fit(np.ones(3000), y)
    with pytest.raises(ValueError, match="order must be"):
        Subspace(order="best", **FAST).fit(u, y)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="order must be an int"):
        Subspace(order=0, **FAST).fit(u, y)
    with pytest.raises(ValueError, match="feedthrough"):
        Subspace(order=2, feedthrough="no", **FAST).fit(u, y)  # type: ignore[arg-type]
    with pytest.raises(DataError, match="mode 'siso'"):
        Subspace(order=2, mimo="siso", **FAST).fit(np.c_[u, u[::-1]], y)
