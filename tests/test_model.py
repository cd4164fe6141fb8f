"""LinearModel: simulate, predict, infer_input, analysis and export against naive loops,
scipy.signal and python-control."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest
from scipy import signal

import clpc
from clpc import LPC, LinearModel, ModelError
from clpc.lpc.regressors import Structure

# a stable, minimum-phase system with a delay: poles |p| = 0.84, zeros of 0.5 + 0.3z + 0.1z^2
DEN = np.array([1.0, -1.5, 0.7])
NUM_MP = np.array([0.5, 0.3, 0.1])  # zeros -0.3 +- 0.33j, |z| = 0.45
NUM_NMP = np.array([0.2, 1.0])  # zero at -5: non-minimum phase


def naive_simulate(model, u, y_init, u_init, offset=True):
    """y(n) = -sum a_i y(n-i) + sum num_i u(n-i) + intercept, one sample at a time."""
    a, b = model.den, model.num
    ue = np.r_[u_init, u]
    ye = list(y_init)
    for n in range(len(u)):
        idx = len(u_init) + n
        v = sum(b[i] * ue[idx - i] for i in range(len(b)) if idx - i >= 0)
        v -= sum(a[i] * ye[-i] for i in range(1, len(a)))
        ye.append(v + (model.intercept[0] if offset else 0.0))
    return np.array(ye[len(y_init) :])


def naive_predict(model, u, y, k):
    """y_hat(n | n-k): measured outputs up to n-k, the model for n-k+1 .. n."""
    a, b = model.den, model.num
    start = model.structure.max_lag
    out = y.astype(float).copy()
    for n in range(start, len(y)):
        guess = {}
        for t in range(max(n - k + 1, start), n + 1):
            v = sum(b[i] * u[t - i] for i in range(len(b))) + model.intercept[0]
            v -= sum(a[i] * guess.get(t - i, y[t - i]) for i in range(1, len(a)))
            guess[t] = v
        out[n] = guess[n]
    return out


@pytest.fixture
def model_delay(make_model):
    return make_model(DEN, np.r_[0.0, NUM_MP], nk=1, intercept=0.25, dt=0.01)


@pytest.fixture
def record(model_delay):
    gen = np.random.default_rng(21)
    u = gen.standard_normal(300)
    y = model_delay.simulate(u) + 0.05 * gen.standard_normal(300)
    return u, y


def test_fixture_conventions(model_delay):
    np.testing.assert_allclose(model_delay.den, DEN)
    np.testing.assert_allclose(model_delay.num, np.r_[0.0, NUM_MP])
    np.testing.assert_allclose(model_delay.intercept, [0.25])
    assert model_delay.is_siso and model_delay.n_outputs == 1
    assert "na=2, nb=2, nk=1" in repr(model_delay)


# ----------------------------------------------------------------------------- simulate


def test_simulate_equals_lfilter(model_delay, record):
    u, _ = record
    got = model_delay.simulate(u, include_offset=False)
    np.testing.assert_allclose(
        got, signal.lfilter(model_delay.num, model_delay.den, u), rtol=0, atol=1e-12
    )
    assert got.shape == u.shape


def test_simulate_with_offset_and_zero_state_equals_naive_loop(model_delay, record):
    u, _ = record
    np.testing.assert_allclose(
        model_delay.simulate(u),
        naive_simulate(model_delay, u, [0.0, 0.0], [0.0] * 3),
        atol=1e-12,
    )


def test_simulate_with_initial_conditions_equals_naive_loop(model_delay, record):
    u, _ = record
    y_init = np.array([0.3, -0.2])  # y(-2), y(-1)
    u_init = np.array([0.1, 0.5, -0.4])  # u(-3), u(-2), u(-1)
    got = model_delay.simulate(u, y_init=y_init, u_init=u_init)
    np.testing.assert_allclose(got, naive_simulate(model_delay, u, y_init, u_init), atol=1e-12)
    # longer histories: only the most recent samples count
    longer = model_delay.simulate(u, y_init=np.r_[9.0, y_init], u_init=np.r_[9.0, u_init])
    np.testing.assert_array_equal(longer, got)
    no_off = model_delay.simulate(u, y_init=y_init, u_init=u_init, include_offset=False)
    np.testing.assert_allclose(
        no_off, naive_simulate(model_delay, u, y_init, u_init, False), atol=1e-12
    )


def test_simulate_validation(model_delay, record):
    u, _ = record
    with pytest.raises(ValueError, match="y_init must hold the last 2 outputs before u"):
        model_delay.simulate(u, y_init=[1.0])
    with pytest.raises(ValueError, match="u_init must hold the last 3 inputs before u"):
        model_delay.simulate(u, u_init=[1.0])
    with pytest.raises(ValueError, match=r"u must have shape \(n_samples,\) or \(n_samples, 1\)"):
        model_delay.simulate(np.zeros((10, 2)))
    bad = u.copy()
    bad[5] = np.nan
    with pytest.raises(ValueError, match="u must be finite; the first non-finite sample is at 5"):
        model_delay.simulate(bad)


# ----------------------------------------------------------------------------- predict


@pytest.mark.parametrize("k", [1, 2, 5, 17])
def test_predict_equals_naive_k_step_loop(model_delay, record, k):
    u, y = record
    got = model_delay.predict(u, y, k=k)
    np.testing.assert_allclose(got, naive_predict(model_delay, u, y, k), atol=1e-12)
    start = model_delay.structure.max_lag
    np.testing.assert_array_equal(got[:start], y[:start])


def test_one_step_predictor_is_the_equation(model_delay, record):
    u, y = record
    pred = model_delay.predict(u, y, k=1)
    n = np.arange(3, len(y))
    eq = (
        -DEN[1] * y[n - 1]
        - DEN[2] * y[n - 2]
        + NUM_MP[0] * u[n - 1]
        + NUM_MP[1] * u[n - 2]
        + NUM_MP[2] * u[n - 3]
        + 0.25
    )
    np.testing.assert_allclose(pred[3:], eq, atol=1e-12)


def test_long_horizon_prediction_is_the_simulation_from_measured_initial_conditions(
    model_delay, record
):
    u, y = record
    start = model_delay.structure.max_lag
    sim = model_delay.simulate(u[start:], y_init=y[start - 2 : start], u_init=u[:start])
    np.testing.assert_allclose(model_delay.predict(u, y, k=len(y))[start:], sim, atol=1e-10)
    # and a stable model forgets the measured outputs: k = 60 is already that simulation
    late = slice(start + 120, None)
    far = model_delay.predict(u, y, k=60)
    np.testing.assert_allclose(far[late], sim[late.start - start :], atol=1e-3)


@pytest.mark.parametrize("k", [0, -1, 1.5, True, "2"])
def test_predict_bad_k(model_delay, record, k):
    u, y = record
    with pytest.raises(ValueError, match=r"k must be an int in the range \[1, inf\); got"):
        model_delay.predict(u, y, k=k)


def test_predict_length_mismatch(model_delay, record):
    u, y = record
    with pytest.raises(ValueError, match=r"same length; got len\(u\)=300, len\(y\)=299"):
        model_delay.predict(u, y[:-1])


# ----------------------------------------------------------------------------- infer_input


@pytest.mark.parametrize(("nk", "intercept"), [(0, 0.0), (0, 0.4), (2, -1.3)])
def test_infer_input_inverts_simulate(make_model, nk, intercept):
    model = make_model(DEN, np.r_[np.zeros(nk), NUM_MP], nk=nk, intercept=intercept)
    u = np.random.default_rng(22).standard_normal(400)
    y = model.simulate(u)
    u_hat = model.infer_input(y, y_init=np.zeros(2))
    assert u_hat.shape == (400 - nk,)
    np.testing.assert_allclose(u_hat, u[: 400 - nk], atol=1e-9)


def test_infer_input_default_rest_initial_condition(make_model):
    # from rest at y(-1) = y(-2) = y(0): y[0] repeated is the documented default
    model = make_model(DEN, NUM_MP, intercept=0.2)
    y_rest = 0.2 / DEN.sum()  # equilibrium with u = 0
    u = np.r_[0.0, np.random.default_rng(23).standard_normal(200)]
    y = model.simulate(u, y_init=[y_rest, y_rest])
    np.testing.assert_allclose(model.infer_input(y), u, atol=1e-9)


def test_infer_input_refuses_b0_zero(make_model):
    model = make_model(DEN, np.r_[0.0, NUM_MP], nk=0)  # b0 = 0 but nk = 0
    with pytest.raises(ModelError, match=r"b0 is about 0 .* increase nk by one and refit"):
        model.infer_input(np.ones(50))


def test_infer_input_refuses_non_minimum_phase(make_model):
    model = make_model(DEN, NUM_NMP)
    y = model.simulate(np.random.default_rng(24).standard_normal(100))
    with pytest.raises(
        ModelError,
        match=r"the inverse model is unstable: num\(z\) has zeros "
        r"\[-5\.0\] on or outside the unit circle",
    ):
        model.infer_input(y)
    u_hat = model.infer_input(y, y_init=[0.0, 0.0], allow_unstable=True)
    assert u_hat.shape == (100,)


def test_infer_input_validation(make_model):
    model = make_model(DEN, NUM_MP)
    with pytest.raises(ValueError, match="y_init must hold the last 2 outputs before y"):
        model.infer_input(np.ones(20), y_init=[0.0])


# ----------------------------------------------------------------------------- analysis


def test_poles_zeros_stability_and_dc_gain(model_delay, make_model):
    p = model_delay.poles()
    np.testing.assert_allclose(
        np.sort_complex(p),
        np.sort_complex([0.75 - np.sqrt(0.1375) * 1j, 0.75 + np.sqrt(0.1375) * 1j]),
        atol=1e-12,
    )
    np.testing.assert_allclose(np.abs(p), np.sqrt(0.7), atol=1e-12)
    z = model_delay.zeros()
    np.testing.assert_allclose(np.sort_complex(z), np.sort_complex(np.roots(NUM_MP)), atol=1e-12)
    assert model_delay.is_stable
    np.testing.assert_allclose(model_delay.dc_gain(), [[NUM_MP.sum() / DEN.sum()]], rtol=1e-12)
    unstable = make_model([1.0, -2.1, 1.1], [1.0])  # poles 1.1 and 1.0
    assert not unstable.is_stable
    first_order = make_model([1.0, 0.5], [2.0])
    assert first_order.zeros().size == 0
    np.testing.assert_allclose(first_order.poles(), [-0.5])


def test_dc_gain_of_an_integrator(make_model):
    integ = make_model([1.0, -1.0], [0.0, 0.5], nk=1)
    assert integ.dc_gain()[0, 0] == np.inf
    assert make_model([1.0, -1.0], [0.0, -0.5], nk=1).dc_gain()[0, 0] == -np.inf


def test_dc_gain_of_a_paired_model_has_zero_cross_gains():
    # regression: the zero cross-channel numerators used to make inf * 0 (RuntimeWarning)
    theta = np.array([[1.0, -1.0, -0.5], [1.0, -0.5, -1.0]])
    paired = LinearModel(
        theta=theta, structure=Structure(1, 0), n_inputs=2, mode="paired", c=np.zeros(2)
    )
    gain = paired.dc_gain()
    assert gain[0, 0] == np.inf and gain[0, 1] == 0.0
    np.testing.assert_allclose(gain[1], [0.0, 2.0])


def test_dc_gain_matches_the_step_response(model_delay):
    step = model_delay.simulate(np.ones(400), include_offset=False)
    np.testing.assert_allclose(step[-1], model_delay.dc_gain()[0, 0], rtol=1e-9)


def test_frequency_response(model_delay):
    f, h = model_delay.frequency_response(32)
    assert f[-1] < 50.0 and f[0] == 0.0  # dt = 0.01: Nyquist 50 Hz
    np.testing.assert_allclose(h[0], model_delay.dc_gain()[0, 0], rtol=1e-12)
    zinv = np.exp(-2j * np.pi * f * 0.01)
    num = sum(c * zinv**i for i, c in enumerate(model_delay.num))
    den = sum(c * zinv**i for i, c in enumerate(model_delay.den))
    np.testing.assert_allclose(h, num / den, rtol=1e-10)


def test_a0_zero_has_no_monic_form():
    model = LinearModel(
        theta=np.array([0.0, -1.0, 0.5, 0.5]),
        structure=Structure(1, 1),
        n_inputs=1,
        mode="siso",
        c=[0.0],
    )
    with pytest.raises(
        ModelError, match=r"a0 of output 0 is about 0 .* the monic transfer function does not exist"
    ):
        model.den  # noqa: B018
    with pytest.raises(ModelError, match="a0 of output 0 is about 0"):
        model.simulate(np.ones(5))


def test_siso_only_accessors_refuse_mimo():
    theta = np.ones((2, 5)) / np.sqrt(5)
    mimo = LinearModel(
        theta=theta, structure=Structure(1, 0), n_inputs=3, mode="miso", c=np.zeros(2)
    )
    with pytest.raises(
        ModelError,
        match=r"num is defined for single-input single-output models; "
        r"this model has 3 input\(s\) and 2 output\(s\)",
    ):
        mimo.num  # noqa: B018
    with pytest.raises(ModelError, match="infer_input is defined for single-input"):
        mimo.infer_input(np.ones(10))


def test_mimo_simulate_and_predict_shapes(rich_input):
    u = rich_input(500, seed=25, m=2)
    y = np.column_stack(
        [
            signal.lfilter([0.0, 1.0], [1.0, -0.5], u[:, 0]) + u[:, 1],
            signal.lfilter([0.0, 0.3], [1.0, 0.2], u[:, 1]),
        ]
    )
    model = LPC(order=1, mimo="paired").fit(u, y)
    assert model.simulate(u).shape == (500, 2)
    assert model.predict(u, y, k=3).shape == (500, 2)
    miso = LPC(order=1).fit(u, y)
    np.testing.assert_allclose(miso.simulate(u, include_offset=False), y, atol=1e-9)


# ----------------------------------------------------------------------------- export


def test_to_scipy_step_response_equals_simulate(model_delay):
    sys = model_delay.to_scipy()
    assert isinstance(sys, signal.dlti) and sys.dt == 0.01
    _, (step,) = sys.step(n=60)  # (scipy may return n - 1 points: float time grid)
    n = step.shape[0]
    np.testing.assert_allclose(
        step[:, 0], model_delay.simulate(np.ones(n), include_offset=False), atol=1e-12
    )
    _, (imp,) = sys.impulse(n=30)
    n = imp.shape[0]
    np.testing.assert_allclose(
        imp[:, 0],
        model_delay.simulate(np.r_[1.0, np.zeros(n - 1)], include_offset=False),
        atol=1e-12,
    )


def test_to_scipy_does_not_warn_for_a_delayed_model(model_delay):
    # regression: the leading zero of a delayed numerator made scipy warn (BadCoefficients)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sys = model_delay.to_scipy()
    np.testing.assert_allclose(sys.num, model_delay.num[1:])


def test_to_scipy_with_na_less_than_nb(make_model):
    model = make_model([1.0, -0.5], [0.0, 0.0, 1.0, 0.5], nk=2)
    _, (step,) = model.to_scipy().step(n=20)
    n = step.shape[0]
    np.testing.assert_allclose(
        step[:, 0], model.simulate(np.ones(n), include_offset=False), atol=1e-12
    )


def test_to_control_poles_and_dcgain(model_delay):
    control = pytest.importorskip("control")
    sys = model_delay.to_control()  # the inputs alone by default: a 1x1 system
    assert sys.dt == 0.01 and (sys.noutputs, sys.ninputs) == (1, 1)
    assert np.shape(control.dcgain(sys)) == ()
    # the padded export may add poles at z = 0 (pure delays); the others are the model's
    poles = np.asarray(sys.poles())
    nonzero = poles[np.abs(poles) > 1e-9]
    np.testing.assert_allclose(
        np.sort_complex(nonzero), np.sort_complex(model_delay.poles()), atol=1e-10
    )
    np.testing.assert_allclose(control.dcgain(sys), model_delay.dc_gain()[0, 0], rtol=1e-10)
    _, yout = control.step_response(sys, T=np.arange(40) * 0.01)
    np.testing.assert_allclose(
        np.ravel(yout), model_delay.simulate(np.ones(40), include_offset=False), atol=1e-10
    )


def _stable_miso():
    theta = np.array([[1.0, -0.5, 0.3, 0.2], [1.0, 0.2, -1.0, 0.1]])
    return LinearModel(
        theta=theta,
        structure=Structure(1, 0),
        n_inputs=2,
        mode="miso",
        c=np.array([0.4, -0.3]),
        input_names=("left", "right"),
        output_names=("speed", "angle"),
        dt=0.1,
    )


def test_to_control_mimo():
    pytest.importorskip("control")
    miso = _stable_miso()
    sys = miso.to_control()
    assert (sys.noutputs, sys.ninputs) == (2, 2) and sys.input_labels == ["left", "right"]
    gain = np.asarray(sys.dcgain()).reshape(2, 2)
    np.testing.assert_allclose(gain, miso.dc_gain(), rtol=1e-10)


@pytest.mark.parametrize("which", ["siso_delay", "miso"])
def test_to_control_keeps_names_and_offset(which, model_delay):
    control = pytest.importorskip("control")
    model = _stable_miso() if which == "miso" else model_delay
    model = replace(model, c=model.c + 0.25)  # a nonzero offset for both
    sys = model.to_control(include_offset=True)
    assert sys.input_labels == [*model.input_names, "offset"]
    assert sys.output_labels == list(model.output_names)
    n = 80
    u = np.random.default_rng(4).standard_normal((n, model.n_inputs))
    resp = control.forced_response(sys, np.arange(n) * model.dt, np.vstack([u.T, np.ones(n)]))
    np.testing.assert_allclose(
        np.atleast_2d(resp.outputs).T, model.simulate(u).reshape(n, -1), rtol=1e-10, atol=1e-12
    )
    # without the offset input (the default): the deviation model
    dev = control.forced_response(model.to_control(), np.arange(n) * model.dt, u.T)
    np.testing.assert_allclose(
        np.atleast_2d(dev.outputs).T,
        model.simulate(u, include_offset=False).reshape(n, -1),
        rtol=1e-10,
        atol=1e-12,
    )


def test_exports_are_public():
    assert clpc.LinearModel is LinearModel and issubclass(ModelError, ValueError)
