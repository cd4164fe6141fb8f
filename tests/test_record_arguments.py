"""An IOData stands for ``u, y`` wherever a function asks for measured inputs and outputs."""

from __future__ import annotations

import numpy as np
import pytest

import clpc


@pytest.fixture(scope="module")
def data():
    rng = np.random.default_rng(5)
    u = rng.standard_normal(900)
    y = clpc.simulate_arx([1, -1.5, 0.7], [0.5, 0.2, 0.1], u) + 0.05 * rng.standard_normal(900)
    return clpc.IOData(u, y, dt=0.01)


@pytest.fixture(scope="module")
def model(data):
    return clpc.LPC(order=2).fit(data)


def test_simulate_and_predict_take_a_record(data, model):
    np.testing.assert_array_equal(model.simulate(data), model.simulate(data.u))
    assert model.simulate(data).shape == data.y.shape
    np.testing.assert_array_equal(model.predict(data, k=4), model.predict(data.u, data.y, k=4))
    np.testing.assert_array_equal(model.infer_input(data), model.infer_input(data.y[:, 0]))


def test_a_record_and_y_together_are_refused_with_a_hint(data, model):
    with pytest.raises(clpc.DataError, match=r"not both.*by keyword \(e\.g\. k=10\)"):
        model.predict(data, 4)  # k given in y's place
    with pytest.raises(clpc.DataError, match="y is missing"):
        model.predict(data.u)
    with pytest.raises(clpc.DataError, match="y is missing"):
        clpc.residual_analysis(model, data.u)


def test_residual_analysis_and_kstep_fit_take_a_record(data, model):
    by_record = clpc.residual_analysis(model, data)
    by_arrays = clpc.residual_analysis(model, data.u, data.y)
    np.testing.assert_array_equal(by_record.residuals, by_arrays.residuals)
    assert [t.statistic for t in by_record.tests] == [t.statistic for t in by_arrays.tests]
    np.testing.assert_array_equal(
        clpc.kstep_fit(model, data, k=5), clpc.kstep_fit(model, data.u, data.y, k=5)
    )


def test_operating_point_diagnostics_takes_a_record(data):
    trace = clpc.CLPC(order=2, window_size=201, cluster_size=12, dt=data.dt).run(data)
    by_record = clpc.operating_point_diagnostics(trace, data)
    by_arrays = clpc.operating_point_diagnostics(trace, data.u[:, 0], data.y[:, 0])
    np.testing.assert_array_equal(by_record.dc_gain, by_arrays.dc_gain)
    assert by_record.verdict == by_arrays.verdict


def test_a_multimodel_simulates_and_predicts_a_record(data):
    mm = clpc.MultiModel(order=2, n_models=2).fit(data)
    np.testing.assert_array_equal(mm.simulate(data), mm.simulate(data.u))
    np.testing.assert_array_equal(mm.predict(data, k=3), mm.predict(data.u, data.y, k=3))


def test_several_experiments_run_one_by_one(data, model):
    parts = [data[:400], data[400:]]
    both = clpc.IOData.concat(parts)
    np.testing.assert_array_equal(
        model.simulate(both), np.vstack([model.simulate(p.u) for p in parts])
    )
    np.testing.assert_array_equal(
        model.predict(both, k=3), np.vstack([model.predict(p.u, p.y, k=3) for p in parts])
    )
    # the stacked run differs from one run across the boundary
    assert not np.array_equal(model.simulate(both), model.simulate(data.u))
    with pytest.raises(clpc.DataError, match="one experiment"):
        model.simulate(both, y_init=np.zeros(2))
    with pytest.raises(clpc.DataError, match=r"holds 2: .*data\.split\(\)"):
        clpc.residual_analysis(model, both)
