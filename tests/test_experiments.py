"""IOData tools (detrend, filter, resample, frames, slicing) and fits of several experiments
at once, against scipy and an explicit lag-row reference."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

import clpc
from clpc.data import DataError, IOData

DEN, NUM = [1.0, -1.5, 0.7], [0.0, 0.5, 0.2]


def _experiment(n, seed, offset=0.0, dt=0.01):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n) + offset
    y = clpc.simulate_arx(DEN, NUM, u) + 0.02 * rng.standard_normal(n)
    return IOData(u, y, dt=dt)


@pytest.fixture(scope="module")
def two():
    return _experiment(700, 1), _experiment(500, 2, offset=4.0)


def _rows(data, na, nb, nk):
    """Lag rows [y(n)..y(n-na), u(n-nk)..u(n-nk-nb)] written out sample by sample."""
    start = max(na, nk + nb)
    u, y = data.u[:, 0], data.y[:, 0]
    return np.array(
        [
            [y[n - i] for i in range(na + 1)] + [u[n - nk - i] for i in range(nb + 1)]
            for n in range(start, data.n_samples)
        ]
    )


def test_lpc_fits_several_experiments_without_crossing_a_boundary(two):
    d1, d2 = two
    rows = np.vstack([_rows(d1, 2, 2, 1), _rows(d2, 2, 2, 1)])  # per experiment, then stacked
    centered = rows - rows.mean(axis=0)
    ref = np.linalg.svd(centered)[2][-1]
    ref = ref / np.linalg.norm(ref) * np.sign(ref[0])
    model = clpc.LPC(order=2, nk=1, method="paper", cancel=False).fit([d1, d2])
    np.testing.assert_allclose(np.ravel(model.theta), ref, atol=1e-10)
    assert np.atleast_1d(model.info["n_rows"])[0] == rows.shape[0] == (700 - 3) + (500 - 3)
    # the naive join (one record) has 3 more rows, which straddle the boundary
    joined = clpc.LPC(order=2, nk=1, method="paper", cancel=False).fit(
        np.concatenate([d1.u, d2.u]), np.concatenate([d1.y, d2.y])
    )
    assert np.atleast_1d(joined.info["n_rows"])[0] == rows.shape[0] + 3
    assert not np.allclose(np.ravel(joined.theta), ref, atol=1e-6)


def test_arx_fits_several_experiments(two):
    d1, d2 = two
    rows = np.vstack([_rows(d1, 2, 2, 1), _rows(d2, 2, 2, 1)])
    centered = rows - rows.mean(axis=0)
    x, *_ = np.linalg.lstsq(centered[:, 1:], -centered[:, 0], rcond=None)
    ref = np.concatenate([[1.0], x])
    model = clpc.ARX(order=2, nk=1).fit(IOData.concat([d1, d2]))
    np.testing.assert_allclose(np.ravel(model.theta), ref / np.linalg.norm(ref), atol=1e-12)
    np.testing.assert_allclose(model.den, DEN, atol=0.02)


def test_concat_split_slice_and_errors(two):
    d1, d2 = two
    both = IOData.concat([d1, d2])
    assert both.experiments == (700, 500) and both.n_experiments == 2
    assert [p.n_samples for p in both.split()] == [700, 500]
    np.testing.assert_array_equal(both.split()[1].u, d2.u)
    assert both[650:760].experiments == (50, 60)
    assert both[:700].experiments == (700,)
    assert both.time[700] == 0.0 and both.time[699] == pytest.approx(6.99)
    with pytest.raises(DataError, match=r"dt = 0\.02 s"):
        IOData.concat([d1, _experiment(100, 3, dt=0.02)])
    with pytest.raises(DataError, match="same channels"):
        IOData.concat([d1, IOData(d2.u, d2.y, dt=0.01, input_names=["v"])])
    with pytest.raises(DataError, match="summing to 5"):
        IOData(np.ones(5), np.ones(5), experiments=[2, 2])
    with pytest.raises(DataError, match="step 1"):
        both[::2]


def test_detrend_filter_resample_per_experiment(two):
    d1, d2 = two
    both = IOData.concat([d1, d2])
    lin = both.detrend("linear")
    np.testing.assert_allclose(lin.y[700:, 0], signal.detrend(d2.y[:, 0]), atol=1e-12)
    assert abs(both.detrend().u[:700].mean()) < 1e-12
    sos = signal.butter(4, 5.0, fs=100.0, output="sos")
    low = both.filter(5.0)
    np.testing.assert_allclose(low.u[700:, 0], signal.sosfiltfilt(sos, d2.u[:, 0]), atol=1e-12)
    causal = both.filter(5.0, zero_phase=False)
    np.testing.assert_allclose(causal.y[:700, 0], signal.sosfilt(sos, d1.y[:, 0]), atol=1e-12)
    # zero phase adds no delay: the filtered signal lines up with the original
    lags = np.arange(-20, 21)
    corr = [np.dot(low.u[50:650, 0], d1.u[50 + k : 650 + k, 0]) for k in lags]
    assert lags[int(np.argmax(corr))] == 0
    with pytest.raises(DataError, match="Nyquist"):
        both.filter(60.0)
    half = both.resample(0.02)
    assert half.dt == 0.02 and half.experiments == (350, 250)
    np.testing.assert_allclose(half.u[:350, 0], signal.resample_poly(d1.u[:, 0], 1, 2), atol=1e-12)
    with pytest.raises(DataError, match="not a fraction"):
        both.resample(0.01 * np.pi)


def test_frames_round_trip(two):
    pytest.importorskip("pandas")
    d1, d2 = two
    both = IOData.concat([d1, d2])
    frame = both.to_frame()
    assert list(frame.columns) == ["time", "experiment", "u", "y"]
    back = IOData.from_frame(frame, "u", "y", experiment="experiment")
    assert back.experiments == both.experiments and back.dt == pytest.approx(0.01)
    np.testing.assert_array_equal(back.y, both.y)
    with pytest.raises(DataError, match=r"columns \['v'\]"):
        IOData.from_frame(frame, "v", "y")


def test_clpc_refuses_a_record_of_several_experiments(two):
    with pytest.raises(DataError, match=r"IOData\.split"):
        clpc.CLPC(order=2, window_size=101).run(list(two))
    part = IOData.concat(list(two)).split()[0]
    assert len(clpc.CLPC(order=2, window_size=101).run(part)) > 0
