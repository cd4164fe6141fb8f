"""Evidence on demand: a fit computes no held-out refit, residual test or jackknife until read;
the k-step predictor is a pair of filters (O(T) memory) equal to the step-by-step recursion."""

from __future__ import annotations

import dataclasses
import pickle
import tracemalloc

import numpy as np
import pytest

import clpc
from clpc.lpc import assessment
from clpc.lpc.regressors import regressors, siso_regressor
from clpc.model.evidence import FitInfo
from clpc.model.simulation import forced


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(3)
    u = rng.standard_normal(3000)
    y = clpc.simulate_arx([1, -1.5, 0.7], [0.5, 0.2, 0.1], u) + 0.05 * rng.standard_normal(3000)
    return clpc.IOData(u, y + 2.0, dt=0.01)


@pytest.mark.parametrize("estimator", [clpc.LPC, clpc.ARX, clpc.OE])
def test_fit_computes_no_evidence_until_it_is_read(estimator, record, monkeypatch):
    calls = []
    real = assessment.heldout_evidence
    monkeypatch.setattr(assessment, "heldout_evidence", lambda *a: calls.append(1) or real(*a))
    model = estimator(order=2).fit(record)
    assert isinstance(model.info, FitInfo) and "assessment" in model.info.pending
    assert "heldout" not in dict(model.info) and calls == []
    first = model.info["heldout"]
    assert calls == [1] and "residual_test" in dict(model.info)
    assert model.info["heldout"] is first and calls == [1]  # computed once
    refit = estimator(order=2, assess=False, uncertainty=False).fit
    now = assessment.assess(estimator(order=2, assess=False).fit(record), record, refit)
    assert first["free_run"] == pytest.approx(now.info["heldout"]["free_run"], abs=1e-9)
    assert model.info["residual_test"]["white"] == now.info["residual_test"]["white"]


def test_the_lpc_jackknife_runs_when_the_covariance_is_read(record, monkeypatch):
    model = clpc.LPC(order=2).fit(record)
    assert "covariance" in model.info.pending and "covariance" not in dict(model.info)
    lo, hi = model.confidence_interval(0.95)
    assert "covariance" not in model.info.pending and np.all(lo < hi)
    assert model.info["covariance_method"].startswith("block jackknife")
    bare = clpc.LPC(order=2, uncertainty=False, assess=False).fit(record)
    # the input's excitation (cheap, from the record) is the only evidence still offered
    assert bare.info.pending == ("excitation",) and "covariance" not in bare.info
    with pytest.raises(clpc.ModelError, match="no parameter covariance"):
        bare.covariance  # noqa: B018


def test_evidence_belongs_to_the_coefficients_it_was_computed_for(record):
    model = clpc.LPC(order=2).fit(record)
    assert model.info["heldout"]["free_run"] > 90
    same = dataclasses.replace(model, dt=0.02)  # same coefficients: evidence kept
    # the covariance and the excitation were never read
    assert sorted(same.info.pending) == ["covariance", "excitation"]
    assert same.info["heldout"] is model.info["heldout"]
    worse = dataclasses.replace(model, theta=model.theta * [1, 1, 1.2, 1, 1, 1])
    assert worse.record is model.record and "assessment" in worse.info.pending
    assert "residual_test" not in dict(worse.info)
    own = worse.info["residual_test"]["whiteness_Q"]
    assert own > 10 * model.info["residual_test"]["whiteness_Q"]


def test_pickling_keeps_what_was_computed_and_drops_the_record(record):
    model = clpc.LPC(order=2).fit(record)
    bare = pickle.loads(pickle.dumps(model))
    assert bare.record is None and "heldout" not in bare.info
    np.testing.assert_array_equal(bare.theta, model.theta)
    full = pickle.loads(pickle.dumps(model.assess()))
    assert full.info["heldout"] == model.info["heldout"]
    np.testing.assert_array_equal(full.info["covariance"], model.info["covariance"])


def _recursive_predict(model, u, y, k):
    """Reference: the step-by-step recursion (outputs measured before max_lag kept)."""
    u2, y2 = u.reshape(len(u), -1), y.reshape(len(y), -1)
    start, na = model.structure.max_lag, model.structure.na
    x = forced(model, u2, None) + model.intercept[None, :]
    dens, n = model.denominators, y2.shape[0]
    preds = [y2]
    for step in range(1, k + 1):
        acc = x[start:].copy()
        for lag in range(1, na + 1):
            acc -= dens[:, lag][None, :] * preds[max(step - lag, 0)][start - lag : n - lag]
        cur = y2.copy()
        cur[start:] = acc
        preds.append(cur)
    return preds[k]


@pytest.mark.parametrize("settings", [{"order": 2}, {"order": 3, "nk": 2}, {"na": 1, "nb": 3}])
@pytest.mark.parametrize("k", [1, 2, 5, 63, 64, 65, 400, 2999, 3000, 4000])
def test_kstep_prediction_equals_the_recursion(settings, k, record):
    model = clpc.LPC(**settings).fit(record)
    got = model.predict(record.u[:, 0], record.y[:, 0], k=k)
    want = _recursive_predict(model, record.u[:, 0], record.y[:, 0], k)[:, 0]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.max(np.abs(want)))


def test_kstep_prediction_of_a_miso_model_per_output():
    data = clpc.datasets.load("cd_player_arm")
    model = clpc.LPC(order=2).fit(data)
    for k in (1, 7, 100):
        want = _recursive_predict(model, data.u, data.y, k)
        np.testing.assert_allclose(
            model.predict(data.u, data.y, k=k), want, rtol=0, atol=1e-12 * np.abs(want).max()
        )


def test_kstep_prediction_memory_does_not_grow_with_k():
    rng = np.random.default_rng(0)
    n = 200_000
    u = rng.standard_normal(n)
    y = clpc.simulate_arx([1, -1.9, 0.905], [0.01, 0.005, 0.0], u) + 0.01 * rng.standard_normal(n)
    model = clpc.ARX(order=2).fit(u, y)
    peaks = []
    for k in (10, 5_000):
        tracemalloc.start()
        model.predict(u, y, k=k)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    # k arrays of n samples would be 8 GB at k = 5000; the filters need a few n-long arrays
    assert max(peaks) < 40 * 8 * n, peaks


def test_regressors_equal_the_paper_lag_matrix(record):
    structure = clpc.LPC(order=3, nk=1).structure()
    got = regressors(record, structure, "siso")
    want = siso_regressor(record.y[:, 0], record.u[:, 0], structure)
    np.testing.assert_array_equal(got[0], want)
    assert got[0].flags.f_contiguous


def test_evidence_whose_computation_fails_stays_pending(record):
    model = clpc.LPC(order=2).fit(record)
    calls = []

    def flaky(fitted):
        calls.append(1)
        if len(calls) == 1:
            raise KeyboardInterrupt  # e.g. the user stops a slow jackknife
        return {"covariance_note": "computed on the second read"}

    info = FitInfo({}, model, model.record.with_producer("covariance", flaky))
    with pytest.raises(KeyboardInterrupt):
        info["covariance_note"]
    assert "covariance" in info.pending
    assert info["covariance_note"] == "computed on the second read" and calls == [1, 1]
