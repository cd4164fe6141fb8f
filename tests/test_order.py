"""Order selection: the paper's Remark 1, AIC and BIC on a known order-3 system."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

import clpc
from clpc import LPC, OrderSelection, select_order

ORDERS = range(1, 7)


@pytest.fixture(scope="module")
def order3():
    """Order-3 system (poles 0.8, 0.5 +- 0.4j), output std = input std for white input."""
    den = np.poly([0.8, 0.5 + 0.4j, 0.5 - 0.4j]).real
    num = np.array([0.3, 0.6, -0.2, 0.1])
    h = signal.lfilter(num, den, np.r_[1.0, np.zeros(3000)])
    return den, num / np.sqrt(h @ h)


def record(system, seed, sigma, n=2000):
    """White input; equal white noise (std ``sigma``, 40 dB at 0.01) on input and output."""
    den, num = system
    gen = np.random.default_rng(seed)
    u0 = gen.standard_normal(n)
    y0 = signal.lfilter(num, den, u0)
    return u0 + sigma * gen.standard_normal(n), y0 + sigma * gen.standard_normal(n)


@pytest.mark.parametrize("method", ["paper", "robust"])
def test_remark1_chooses_the_true_order(order3, method):
    for seed in range(4):
        u, y = record(order3, seed, 0.01)
        sel = select_order(u, y, orders=ORDERS, criterion="remark1", estimator=LPC(method=method))
        assert sel.best == 3, (seed, sel.noise_variance)


@pytest.mark.parametrize("criterion", ["aic", "bic"])
@pytest.mark.parametrize("method", ["paper", "robust"])
def test_information_criteria_never_underfit(order3, method, criterion):
    """AIC/BIC pick 3 or more; with errors in variables they usually pick more.

    Why: beyond the true order the near-null subspace has ``N - 2`` dimensions and LPC
    takes the minimum of the noise's quadratic form over it, which lies below the noise
    variance by ``O(1/sqrt(n))`` (relative), while the penalty per extra order is
    ``O(log(n)/n)``; so the likelihood keeps "improving" a little faster than the penalty.
    (Measured here: BIC picks 4-6, AIC 4-6; Remark 1 with a 10 % threshold picks 3.)
    """
    for seed in range(4):
        u, y = record(order3, seed, 0.01)
        sel = select_order(u, y, orders=ORDERS, criterion=criterion, estimator=LPC(method=method))
        var = sel.noise_variance
        assert sel.best >= 3
        assert var[2] < var[1] / 3 < var[0] / 30  # the sharp drop at the true order
        assert np.all(var[3:] > 0.85 * var[2])  # and (almost) flat beyond it


def test_table_shapes_and_frame(order3):
    u, y = record(order3, 0, 0.01)
    sel = select_order(u, y, orders=[4, 2, 3, 2], criterion="bic")
    assert isinstance(sel, OrderSelection)
    assert sel.orders.tolist() == [2, 3, 4]  # sorted, duplicates dropped
    for col in (sel.J, sel.log_likelihood, sel.aic, sel.bic, sel.noise_variance):
        assert col.shape == (3,) and np.all(np.isfinite(col))
    # free parameters: p - 1 (unit norm) + c + sigma^2, with p = 2N + 2
    assert sel.n_params.tolist() == [7, 9, 11]
    n = 2000 - 4
    np.testing.assert_allclose(sel.aic, 2 * sel.n_params - 2 * sel.log_likelihood)
    np.testing.assert_allclose(sel.bic, sel.n_params * np.log(n) - 2 * sel.log_likelihood)
    assert sel.best == int(sel.orders[np.argmin(sel.bic)]) and sel.criterion == "bic"
    frame = sel.to_frame()
    assert frame.index.name == "order" and frame.index.tolist() == [2, 3, 4]
    assert list(frame.columns) == [
        "J",
        "log_likelihood",
        "aic",
        "bic",
        "noise_variance",
        "n_params",
    ]


def test_all_orders_use_the_same_rows(order3):
    u, y = record(order3, 1, 0.05, n=600)
    sel = select_order(u, y, orders=[1, 2, 5], estimator=LPC(method="paper"))
    # order 1 is fitted on the rows order 5 can use: drop 5 - 1 leading samples
    for i, order in enumerate([1, 2, 5]):
        skip = 5 - order
        model = LPC(order=order, method="paper").fit(u[skip:], y[skip:])
        assert model.info["n_rows"] == 595
        np.testing.assert_allclose(sel.J[i], model.info["J"], rtol=1e-12)
        np.testing.assert_allclose(sel.noise_variance[i], model.info["noise_variance"], rtol=1e-12)


def test_paper_j_never_increases_with_order(order3):
    # nested lag matrices: the smallest eigenvalue can only fall (Cauchy interlacing)
    u, y = record(order3, 2, 0.05)
    sel = select_order(u, y, orders=ORDERS, estimator=LPC(method="paper"))
    assert np.all(np.diff(sel.J) <= 1e-9 * np.abs(sel.J[:-1]))


def test_remark1_threshold(order3):
    u, y = record(order3, 0, 0.01)
    strict = select_order(u, y, orders=ORDERS, criterion="remark1", min_improvement=0.999)
    assert strict.best == 1
    loose = select_order(u, y, orders=ORDERS, criterion="remark1", min_improvement=0.0)
    assert loose.best >= 3


def test_mimo_counts_parameters_per_output(rich_input):
    u = rich_input(800, seed=40, m=2)
    y = np.column_stack(
        [
            signal.lfilter([1.0], [1.0, -0.5], u[:, 0]),
            signal.lfilter([0.0, 1.0], [1.0, 0.3], u[:, 1]),
        ]
    )
    sel = select_order(u, y, orders=[1, 2], estimator=LPC(mimo="paired"))
    assert sel.n_params.tolist() == [2 * 5, 2 * 7]
    assert sel.best == 1  # noise-free order-1 pairs


def test_settings_of_the_estimator_are_kept(order3):
    u, y = record(order3, 3, 0.01)
    sel = select_order(u, y, orders=[2, 3], estimator=LPC(nk=1, na=5, method="paper"))
    # na/nb are replaced by the order; nk and the method are kept. With nk = 1 the largest
    # max_lag is 1 + 3 = 4 and order 2 (max_lag 3) drops one leading sample.
    ref = LPC(order=2, nk=1, method="paper").fit(u[1:], y[1:])
    np.testing.assert_allclose(sel.J[0], ref.info["J"], rtol=1e-12)
    assert sel.n_params.tolist() == [7, 9]


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"criterion": "mdl"}, "criterion must be .* or 'validation'; got 'mdl'"),
        ({"orders": [0, 1]}, r"orders must be ints >= 1; got \[0, 1\]"),
        ({"orders": []}, r"orders must be ints >= 1; got \[\]"),
    ],
)
def test_validation(kwargs, pattern):
    u = np.random.default_rng(41).standard_normal(100)
    with pytest.raises(ValueError, match=pattern):
        select_order(u, u, **kwargs)


def test_exported():
    assert clpc.select_order is select_order


def test_validation_criterion_picks_the_predictive_order():
    rng = np.random.default_rng(21)
    u = rng.standard_normal(6000)
    y0 = clpc.simulate_arx([1.0, -1.5, 0.7, -0.1], [0.2, 0.5, 0.1, 0.05], u)
    y = y0 + 0.05 * rng.standard_normal(6000)
    sel = clpc.select_order(u, y, orders=[1, 2, 3, 4, 5], criterion="validation")
    assert sel.validation_fit is not None and sel.validation_fit.shape == (5,)
    # order 1 and 2 miss dynamics: their held-out 10-step fit is clearly worse than order 3
    assert sel.validation_fit[2] > sel.validation_fit[0] + 1.0
    assert sel.best >= 3
    with pytest.raises(ValueError, match="validation_fraction"):
        clpc.select_order(u, y, criterion="validation", validation_fraction=1.5)


def test_select_delay_finds_the_dead_time():
    rng = np.random.default_rng(22)
    u = rng.standard_normal(6000)
    y = clpc.simulate_arx([1.0, -1.2, 0.5], [0, 0, 0, 0.4, 0.3], u) + 0.02 * rng.standard_normal(
        6000
    )
    sel = clpc.select_delay(u, y, delays=range(0, 6), estimator=LPC(na=2, nb=1))
    assert sel.best == 3
    assert sel.validation_fit[3] > sel.validation_fit[0] + 10.0
    with pytest.raises(ValueError, match="delays must be ints >= 0"):
        clpc.select_delay(u, y, delays=[-1])


# ---------------------------------------------------------------- held-out validation
def test_validation_is_the_default_and_rejects_unstable_candidates():
    from clpc import datasets

    data = datasets.load("ballbeam")
    sel = select_order(data, orders=range(1, 6))
    assert sel.criterion == "validation"
    assert len(sel.stability) == 5 and "unstable" in sel.stability  # orders 2.. diverge
    assert sel.stability[list(sel.orders).index(sel.best)] != "unstable"
    assert "rejected" in sel.reason and f"order {sel.best}" in sel.reason
    assert np.all(np.isfinite(sel.free_run_fit[np.array(sel.stability) == "stable"]))


def test_horizon_is_one_dominant_time_constant(rich_input):
    from clpc.lpc.heldout import horizon

    u = rich_input(3000, seed=41)
    slow = select_order(u, signal.lfilter([0.0, 0.1], [1.0, -0.97], u), orders=[1, 2])
    fast = select_order(u, signal.lfilter([0.0, 1.0], [1.0, -0.3], u), orders=[1, 2])
    assert slow.horizon == round(-1 / np.log(0.97))  # 33 samples
    assert fast.horizon == 2  # the shortest horizon
    model = LPC(order=1).fit(u, signal.lfilter([0.0, 1.0], [1.0, -0.999], u))
    assert horizon(model, 1000) == 100  # capped at a tenth of the held-out part


def test_every_candidate_unstable_is_said(monkeypatch, rich_input):
    from clpc.lpc import heldout

    u = rich_input(2000, seed=42)
    y = signal.lfilter([0.0, 1.0], [1.0, -0.5], u)
    monkeypatch.setattr(heldout, "stability", lambda model: "unstable")
    sel = select_order(u, y, orders=[1, 2, 3])
    assert "every candidate is unstable" in sel.reason and sel.best in (1, 2, 3)
