"""DataFrames in: the sample time from a time column (with its unit) or a date/duration index."""

from __future__ import annotations

import numpy as np
import pytest

import clpc
from clpc.data.timebase import DEFAULT_TIME_RTOL
from clpc.io import write_table

pd = pytest.importorskip("pandas")

N = 200


@pytest.fixture(scope="module")
def columns():
    rng = np.random.default_rng(2)
    return {"u": rng.standard_normal(N), "y": rng.standard_normal(N)}


def test_dt_from_a_datetime_index_with_or_without_time_zone(columns):
    for tz in (None, "Europe/Berlin"):
        index = pd.date_range("2024-03-31 00:59:59", periods=N, freq="10ms", tz=tz)
        data = clpc.IOData.from_frame(pd.DataFrame(columns, index=index), "u", "y")
        assert data.dt == 0.01 and data.n_samples == N
        np.testing.assert_array_equal(data.u[:, 0], columns["u"])


def test_dt_from_a_timedelta_index(columns):
    index = pd.timedelta_range(start="5s", periods=N, freq="250us")
    assert clpc.IOData.from_frame(pd.DataFrame(columns, index=index), "u", "y").dt == 2.5e-4


def test_a_time_column_in_the_unit_asked_for_or_named(columns):
    frame = pd.DataFrame({**columns, "stamp": 100 + 2.0 * np.arange(N)})
    assert clpc.IOData.from_frame(frame, "u", "y", time_column="stamp").dt == 2.0
    ms = clpc.IOData.from_frame(frame, "u", "y", time_column="stamp", time_unit="ms")
    assert ms.dt == pytest.approx(2e-3, rel=1e-12)
    named = frame.rename(columns={"stamp": "t_us"})
    assert clpc.IOData.from_frame(named, "u", "y", time_column="t_us").dt == pytest.approx(2e-6)
    dates = frame.assign(stamp=pd.date_range("2024-01-01", periods=N, freq="20ms"))
    assert clpc.IOData.from_frame(dates, "u", "y", time_column="stamp").dt == 0.02
    with pytest.raises(clpc.DataError, match="leave time_unit out"):
        clpc.IOData.from_frame(dates, "u", "y", time_column="stamp", time_unit="ms")
    with pytest.raises(clpc.DataError, match="time unit must be one of"):
        clpc.IOData.from_frame(frame, "u", "y", time_column="stamp", time_unit="min")
    with pytest.raises(clpc.DataError, match="'clock' is not in the frame"):
        clpc.IOData.from_frame(frame, "u", "y", time_column="clock")
    with pytest.raises(clpc.DataError, match="time_unit needs sample times"):
        clpc.IOData.from_frame(pd.DataFrame(columns), "u", "y", time_unit="ms")


def test_uneven_sample_times_are_refused_by_the_readers_rule(columns, tmp_path):
    """Jitter just inside the readers' tolerance passes, just outside fails, as load_iodata."""
    signs = np.random.default_rng(0).choice([-1.0, 1.0], N)
    for factor, accepted in ((0.5, True), (2.0, False)):
        # each time off its grid point by +-a: steps off by up to 2a = factor * rtol * dt
        t = np.arange(N) * 0.01 + signs * factor * DEFAULT_TIME_RTOL * 0.01 / 2
        frame = pd.DataFrame({**columns, "t": t})
        path = tmp_path / f"rec{factor}.csv"
        write_table(path, ["u", "y", "t"], np.column_stack([columns["u"], columns["y"], t]))
        results = []
        for read in (
            lambda f=frame: clpc.IOData.from_frame(f, "u", "y", time_column="t"),
            lambda p=path: clpc.load_iodata(p, "u", "y", time_column="t"),
        ):
            try:
                results.append(read().dt)
            except clpc.DataError as exc:
                assert "not uniformly sampled" in str(exc)
                results.append(None)
        assert (results[0] is not None) == accepted and results[0] == results[1]


def test_a_missing_sample_is_named_and_resampling_fills_it(columns):
    """One time-base rule (as ``clpc stream``): the gap is reported, the samples kept."""
    index = pd.date_range("2024-01-01", periods=N + 1, freq="10ms").delete(50)
    frame = pd.DataFrame(columns, index=index)
    with pytest.warns(UserWarning, match=r"DatetimeIndex\): 1 sample\(s\) missing before row 50"):
        kept = clpc.IOData.from_frame(frame, "u", "y")
    assert kept.dt == 0.01 and kept.n_samples == N  # the mean step between the gaps
    np.testing.assert_array_equal(kept.u[:, 0], columns["u"])
    ms = np.arange(N) * 10.0
    ms[50:] += 5.0  # a step of 1.5 sample times is not dropped samples: refused
    odd = pd.DataFrame(columns, index=pd.Timestamp("2024-01-01") + pd.to_timedelta(ms, "ms"))
    with pytest.raises(clpc.DataError, match=r"DatetimeIndex\) is not uniformly.*row 49 to row 50"):
        clpc.IOData.from_frame(odd, "u", "y")
    filled = clpc.IOData.from_frame(frame, "u", "y", dt=0.01, resample=True)
    assert filled.dt == 0.01 and filled.n_samples == N + 1
    # the filled sample lies on the line between its neighbours
    assert filled.u[50, 0] == pytest.approx(0.5 * (columns["u"][49] + columns["u"][50]))


def test_dt_must_agree_with_the_sample_times(columns):
    index = pd.date_range("2024-01-01", periods=N, freq="10ms")
    frame = pd.DataFrame(columns, index=index)
    assert clpc.IOData.from_frame(frame, "u", "y", dt=0.01).dt == 0.01
    with pytest.raises(clpc.DataError, match=r"dt gives a sample time of 0\.02 s"):
        clpc.IOData.from_frame(frame, "u", "y", dt=0.02)


def test_experiments_round_trip_and_share_one_sample_time(columns):
    data = clpc.IOData(columns["u"], columns["y"], dt=0.05)
    both = clpc.IOData.concat([data[:80], data[80:]])
    back = clpc.IOData.from_frame(both.to_frame(), "u", "y", experiment="experiment")
    assert back.dt == 0.05 and back.experiments == (80, N - 80)
    frame = both.to_frame()
    frame.loc[80:, "time"] *= 2  # the second experiment at another rate
    with pytest.raises(clpc.DataError, match=r"experiment 1 gives a sample time of 0\.1 s"):
        clpc.IOData.from_frame(frame, "u", "y", experiment="experiment")
