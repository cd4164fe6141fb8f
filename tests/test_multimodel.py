"""Multi-models (issue 18): the crank servo, MultiModel, operating-point diagnostics."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import clpc
from clpc import datasets
from clpc.analysis.operating_point import operating_point_diagnostics
from clpc.lpc.heldout import fit_percent
from clpc.multimodel import simulate_time_varying
from clpc.multimodel.local import fit_local, weighted_lpc
from clpc.multimodel.validity import validity
from clpc_paper.plants.crank_servo import (
    CrankParameters,
    crank_commands,
    crank_operating_point,
    simulate_crank_servo,
)

NONLINEAR = CrankParameters()
CONTROL = CrankParameters(velocity_integrator=10.0)


def _records(params: CrankParameters, seed: int, n_levels: int = 30):
    ident = simulate_crank_servo(crank_commands(n_levels, seed=seed), seed=seed + 1, params=params)
    val = simulate_crank_servo(crank_commands(15, seed=seed + 10), seed=seed + 11, params=params)
    return ident, val


def _free_run(model, u, y, na=2):
    sim = model.simulate(u[na:], y_init=y[:na], u_init=u[:na])
    return fit_percent(y[na:], sim)


@pytest.fixture(scope="module")
def nonlinear():
    ident, val = _records(NONLINEAR, 1)
    mm = clpc.MultiModel().fit(ident.command, ident.position, dt=0.01)
    return ident, val, mm


def test_crank_rests_where_the_closed_form_says():
    levels = np.repeat([0.0, 1.0, 2.0, 2.8], 300)  # 3 s per level, no dither
    prm = CrankParameters(position_noise_std=0.0, resolution=0.0, coulomb_friction=0.0)
    rec = simulate_crank_servo(levels, params=prm, seed=0)
    rest, gain, poles = crank_operating_point(np.array([0.0, 1.0, 2.0, 2.8]), prm)
    np.testing.assert_allclose(rec.true_position[299::300], rest, atol=1e-6)
    # r = y + (m g r / (Kv Kp)) sin y, and the local gain is its inverse slope
    a = prm.gravity_torque / (prm.velocity_gain * prm.position_gain)
    np.testing.assert_allclose(rest + a * np.sin(rest), [0.0, 1.0, 2.0, 2.8], atol=1e-12)
    np.testing.assert_allclose(gain, 1.0 / (1.0 + a * np.cos(rest)), rtol=1e-12)
    assert gain[0] == pytest.approx(0.671, abs=1e-3) and poles.shape == (4, 2)


def test_crank_engines_agree_and_inputs_are_checked():
    cmd = crank_commands(2, hold=1.0, seed=3)
    fast = simulate_crank_servo(cmd, seed=4)
    slow = simulate_crank_servo(cmd, seed=4, engine="python")
    np.testing.assert_allclose(fast.position, slow.position, rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match="controller_rate"):
        simulate_crank_servo(cmd, sample_time=0.0015)
    with pytest.raises(ValueError, match="velocity_gain"):
        CrankParameters(velocity_gain=0.0)


def test_multimodel_beats_global_least_squares_on_the_crank_servo(nonlinear):
    ident, val, mm = nonlinear
    ls = clpc.ARX(order=2).fit(ident.command, ident.position, dt=0.01)
    gain = _free_run(mm, val.command, val.position) - _free_run(ls, val.command, val.position)
    assert gain >= 10.0, gain
    assert mm.diagnostics["centre_source"] == "windows"
    assert mm.n_models >= 3


@pytest.mark.parametrize("case", ["control", "arx"])
def test_no_harm_where_there_is_nothing_to_gain(case):
    if case == "control":
        ident, val = _records(CONTROL, 5)
        u, y, vu, vy = ident.command, ident.position, val.command, val.position
    else:
        rng = np.random.default_rng(7)
        u = rng.standard_normal(6000)
        x = clpc.simulate_arx([1, -1.5, 0.7], [0, 0.5, 0.3], u)
        y = x + 0.05 * rng.standard_normal(u.size)
        vu = rng.standard_normal(3000)
        vy = clpc.simulate_arx([1, -1.5, 0.7], [0, 0.5, 0.3], vu)
    mm = clpc.MultiModel().fit(u, y, dt=0.01)
    # the global fit: the better of one global LPC and one global least-squares model
    best = max(
        _free_run(est.fit(u, y, dt=0.01), vu, vy) for est in (clpc.LPC(order=2), clpc.ARX(order=2))
    )
    assert abs(_free_run(mm, vu, vy) - best) <= 1.0


def test_validity_sums_to_one_and_one_step_is_the_blended_equation(nonlinear):
    _ident, val, mm = nonlinear
    psi = np.linspace(-5, 10, 301)
    phi = mm.validity(psi)
    np.testing.assert_allclose(phi.sum(axis=1), 1.0, rtol=0, atol=1e-12)
    assert np.all(phi >= 0)
    u, y = val.command[:2000], val.position[:2000]
    # independent reference: every local LinearModel's own one-step prediction, blended by
    # the validities of the measured y(n-1)
    local = np.stack([m.predict(u, y, k=1) for m in mm.local_models], axis=1)
    w = validity(y[1:-1], mm.centres, mm.widths)
    ref = (w * local[2:]).sum(axis=1)
    np.testing.assert_allclose(mm.predict(u, y, k=1)[2:], ref, rtol=0, atol=1e-12)
    # k steps: the free run of a k-sample stretch equals the k-step prediction at its end
    k, n = 10, 1500
    pred = mm.predict(u, y, k=k)
    sim = mm.simulate(
        u[n - k + 1 : n + 1], y_init=y[n - k - 1 : n - k + 1], u_init=u[n - k - 1 : n - k + 1]
    )
    assert pred[n] == pytest.approx(sim[-1], abs=1e-12)


def test_json_round_trip_is_exact(nonlinear, tmp_path):
    _, val, mm = nonlinear
    path = tmp_path / "mm.json"
    mm.save(path)
    back = clpc.MultiModel.load(path)
    a = mm.simulate(val.command, y_init=val.position[:2])
    b = back.simulate(val.command, y_init=val.position[:2])
    assert np.array_equal(a, b)
    assert back.diagnostics["centre_source"] == mm.diagnostics["centre_source"]
    old = mm.to_dict()
    old["settings"]["engine"] = "auto"  # written while the free run had an engine setting
    assert np.array_equal(
        clpc.MultiModel.from_dict(old).simulate(val.command, y_init=val.position[:2]), a
    )
    with pytest.raises(ValueError, match="format"):
        clpc.MultiModel.from_dict(json.loads('{"format": "other"}'))


def test_linearisation(nonlinear):
    _, _, mm = nonlinear
    # the local DC gain follows the closed form of the crank (0.67 at the bottom, 1 at
    # horizontal): loose, since the local models blend neighbours
    rest, gain, _ = crank_operating_point(np.array([0.0, np.pi / 2 + 0.49]))
    got = [float(mm.linearize(r).dc_gain()[0, 0]) for r in rest]
    np.testing.assert_allclose(got, gain, rtol=0.15)


def test_unstable_local_lpc_is_replaced_and_flagged():
    # the cascaded tanks (real data): local LPC models of the low levels come out unstable
    est, _ = datasets.load("cascaded_tanks")
    u, y = est.u[:, 0], est.y[:, 0]
    mm = clpc.MultiModel(estimator="lpc", n_models=4).fit(u, y, dt=est.dt)
    replaced = mm.diagnostics["replaced"]
    assert replaced
    s = mm.structure
    rows = np.column_stack([y[2:], y[1:-1], y[:-2], u[2:], u[1:-1], u[:-2]])
    for i, model in enumerate(mm.local_models):
        w = mm.validity(y[1:-1])[:, i]
        theta, _c, _ = weighted_lpc(rows, w, s, 1)
        unguarded = np.max(np.abs(np.roots(theta[:3] / theta[0])))
        assert (i in replaced) == (unguarded > 1.0 + 5e-3), (i, unguarded)
        assert model.info["replaced"] == (i in replaced)
        if i in replaced:  # refitted by weighted least squares: stable, and flagged
            assert model.info["estimator"] == "least-squares"
            assert np.max(np.abs(model.poles())) < 1.0
            ls = fit_local(rows, w, s, 1, estimator="ls")
            np.testing.assert_array_equal(model.theta, ls.theta)


def test_cascaded_tanks_no_worse_than_least_squares():
    est, val = datasets.load("cascaded_tanks")
    u, y, vu, vy = est.u[:, 0], est.y[:, 0], val.u[:, 0], val.y[:, 0]
    mm = clpc.MultiModel().fit(u, y, dt=est.dt)
    ls = clpc.ARX(order=2).fit(u, y, dt=est.dt)
    assert _free_run(mm, vu, vy) >= _free_run(ls, vu, vy) - 2.0


def test_operating_point_diagnostics_and_steady_state_warning(nonlinear):
    ident, _, _ = nonlinear
    trace = clpc.CLPC(order=2, window_size=201, cluster_size=12).run(
        ident.command, ident.position, dt=0.01
    )
    rep = operating_point_diagnostics(trace, ident.command, ident.position)
    assert rep.multimodel_recommended and rep.windows_local
    assert "multi-model is recommended" in rep.verdict
    with pytest.warns(UserWarning, match="MODELS CHANGE WITH THE OUTPUT LEVEL"):
        trace.steady_state_model()
    mm = clpc.MultiModel.from_trace(trace, ident.command, ident.position)
    assert mm.diagnostics["windows"] == "the CLPC trace's trusted windows"
    # a linear plant: no recommendation, no warning
    rng = np.random.default_rng(2)
    u = rng.standard_normal(6000)
    y = clpc.simulate_arx([1, -1.5, 0.7], [0, 0.5, 0.3], u) + 0.01 * rng.standard_normal(6000)
    lin = clpc.CLPC(order=2, window_size=201, cluster_size=12).run(u, y, dt=0.01)
    assert not operating_point_diagnostics(lin, u, y).multimodel_recommended


def test_oscillating_windows_take_centres_from_the_samples():
    # every window sweeps the whole range: window means cannot isolate operating points
    t = np.arange(8000) * 0.01
    u = np.sin(2 * np.pi * 1.0 * t) + 0.05 * np.random.default_rng(1).standard_normal(t.size)
    y = clpc.simulate_arx([1, -0.5], [0, 0.5], u) + 0.1 * np.tanh(3 * u)
    mm = clpc.MultiModel(order=1, n_models=3).fit(u, y, dt=0.01)
    assert mm.diagnostics["centre_source"] == "samples"
    assert "cannot isolate" in mm.diagnostics["centre_reason"]


def test_time_varying_free_run_matches_a_constant_model():
    rng = np.random.default_rng(3)
    u = rng.standard_normal(500)
    den, num = np.array([1.0, -1.2, 0.5]), np.array([0.0, 0.4, 0.2])
    ref = clpc.simulate_arx(den, num, u)
    t = u.size
    y = simulate_time_varying(np.tile(den, (t, 1)), np.tile(num, (t, 1)), np.zeros(t), u, ref[:2])
    np.testing.assert_allclose(y, ref, rtol=0, atol=1e-12)


def test_bad_arguments_are_refused():
    with pytest.raises(ValueError, match="schedule"):
        clpc.MultiModel(schedule="z").fit(np.ones(100), np.arange(100.0), dt=1.0)
    with pytest.raises(ValueError, match="estimator"):
        clpc.MultiModel(estimator="svm")
    with pytest.raises(ValueError, match="not fitted"):
        clpc.MultiModel().simulate(np.ones(10))


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda d: d.pop("structure"), "no 'structure' field"),
        (lambda d: d["local_models"][0].pop("theta"), "local model 0 has no 'theta'"),
        (lambda d: d["local_models"][1]["theta"].__setitem__(0, "x"), "must hold numbers"),
        (lambda d: d["local_models"][1]["theta"].__setitem__(0, float("nan")), "must be finite"),
        (lambda d: d["centres"].__setitem__(0, float("inf")), "centres must be finite"),
        (lambda d: d["widths"].__setitem__(0, -1.0), "widths must be positive"),
        (lambda d: d.__setitem__("dt", 0.0), "dt > 0"),
        (lambda d: d["centres"].pop(), "same (nonzero) length"),
    ],
)
def test_load_refuses_a_damaged_file_with_what_is_wrong(tmp_path, edit, message):
    # issue 28 item 7: MultiModel.load validated barely (a KeyError; a NaN theta simulated to
    # all-NaN); every field is now checked before use
    rng = np.random.default_rng(4)
    u = rng.uniform(-1, 1, 3000)
    y = clpc.simulate_arx([1, -0.5], [0, 0.5], u) + 0.2 * u**2
    path = tmp_path / "mm.json"
    clpc.MultiModel(order=1, n_models=3).fit(u, y, dt=0.01).save(path)
    doc = json.loads(path.read_text())
    edit(doc)
    path.write_text(json.dumps(doc))
    with pytest.raises(ValueError, match=re.escape(message)):
        clpc.MultiModel.load(path)


def test_kstep_prediction_memory_does_not_grow_with_k():
    # issue 28 item 2: MultiModel.predict(k) kept k full-length arrays; only the last na
    # (or the schedule's lag) steps are needed
    import tracemalloc

    rng = np.random.default_rng(5)
    u = rng.uniform(-1, 1, 40_000)
    y = clpc.simulate_arx([1, -1.2, 0.5], [0, 0.5, 0.2], u) + 0.2 * u**2
    mm = clpc.MultiModel(order=2, n_models=3).fit(u, y, dt=0.01)

    def peak(k: int) -> int:
        tracemalloc.start()
        mm.predict(u, y, k=k)
        top = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        return top

    assert peak(200) < 1.5 * peak(3)  # a list of k arrays: about 60x here


def test_kstep_prediction_of_one_local_model_is_its_linear_prediction():
    # one local model: validity 1 everywhere, so the multi-model is that linear model and
    # its k-step predictor must agree with LinearModel.predict (filters, a separate code path)
    rng = np.random.default_rng(6)
    u = rng.standard_normal(3000)
    y = clpc.simulate_arx([1, -1.2, 0.5], [0, 0.5, 0.2], u) + 0.01 * rng.standard_normal(3000)
    mm = clpc.MultiModel(order=2, n_models=1).fit(u, y, dt=0.01)
    (local,) = mm.local_models
    for k in (1, 4, 9):
        start = mm.structure.max_lag + k
        np.testing.assert_allclose(
            mm.predict(u, y, k=k)[start:], local.predict(u, y, k=k)[start:], rtol=1e-9, atol=1e-12
        )


def test_figure_of_an_integrating_plant_draws_its_integrating_gain(tmp_path):
    # issue 28 item 7: on an integrator the local DC gains are huge numbers of either sign
    # (poles just inside or outside z = 1); the figure draws (1 - z^-1) G at z = 1 instead
    pytest.importorskip("matplotlib")
    from clpc.plotting.multimodel import integrating_gain, plot_multimodel

    rng = np.random.default_rng(3)
    n, dt = 20_000, 0.01
    u = np.repeat(rng.uniform(-1, 1, n // 50), 50) + 0.05 * rng.standard_normal(n)
    y = np.zeros(n)
    for k in range(1, n):  # velocity (2 + u) u: its slope in u is 2 + 2u
        y[k] = y[k - 1] + dt * (2.0 + u[k - 1]) * u[k - 1]
    y += 1e-3 * rng.standard_normal(n)
    mm = clpc.MultiModel(order=1, schedule="u").fit(u, y, dt=dt)
    assert all(m.stability == "integrating" for m in mm.local_models)
    assert max(abs(float(m.dc_gain()[0, 0])) for m in mm.local_models) > 1e3  # meaningless
    inner = mm.centres[1:-1]
    gains = np.array([integrating_gain(m) for m in mm.local_models])[1:-1]
    np.testing.assert_allclose(gains, 2.0 + 2.0 * inner, atol=0.1)
    # the closed form on an exact integrator: y(n) = y(n-1) + b u(n-1) gives b / dt
    theta = np.array([[1.0, -1.0, 0.0, -0.3]])  # [a; b] with G = -B/A = 0.3 z^-1 / (1 - z^-1)
    exact = clpc.LinearModel(
        theta=theta, structure=clpc.Structure(1, 1), n_inputs=1, mode="siso", c=np.zeros(1), dt=0.5
    )
    np.testing.assert_allclose(exact.numerators[0, 0], [0.0, 0.3])
    assert integrating_gain(exact) == pytest.approx(0.6, rel=1e-12)
    plot_multimodel(mm, tmp_path / "mm.png")
    assert (tmp_path / "mm.png").stat().st_size > 10_000
