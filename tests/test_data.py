"""IOData: validation at the boundary, conversions, slicing; the shipped real records."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import clpc
from clpc import DataError, IOData, as_iodata, datasets

# ----------------------------------------------------------------------------- conversions


def test_shapes_names_and_time():
    u = np.arange(6.0)
    y = np.column_stack([u, 2 * u])
    d = IOData(u, y, dt=0.5)
    assert d.u.shape == (6, 1) and d.y.shape == (6, 2)
    assert (d.n_samples, d.n_inputs, d.n_outputs, len(d)) == (6, 1, 2, 6)
    assert d.input_names == ("u",) and d.output_names == ("y0", "y1")
    np.testing.assert_array_equal(d.time, 0.5 * np.arange(6))
    assert d.u.dtype == np.float64 and d.u.flags.c_contiguous
    assert "n_samples=6" in repr(d)


def test_arrays_are_read_only():
    d = IOData(np.arange(5.0), np.arange(5.0))
    with pytest.raises(ValueError, match="read-only"):
        d.u[0] = 1.0


def test_input_arrays_are_copied_not_aliased():
    # 1-D: a later write by the caller must not reach the validated record
    u = np.arange(5.0)
    d = IOData(u, u.copy())
    u[0] = np.nan
    assert d.u[0, 0] == 0.0
    # 2-D: the caller's own array must stay writable
    y = np.zeros((5, 1))
    IOData(np.arange(5.0), y)
    y[0, 0] = 1.0


def test_pandas_lists_and_arrays_agree():
    rng = np.random.default_rng(1)
    u = rng.standard_normal(50)
    y = rng.standard_normal((50, 2))
    ref = IOData(u, y)
    frame = pd.DataFrame(y, columns=["left", "right"])
    series = pd.Series(u, name="torque")
    for uu, yy in [(series, frame), (u.tolist(), y.tolist()), (pd.DataFrame({"a": u}), y)]:
        d = IOData(uu, yy)
        np.testing.assert_array_equal(d.u, ref.u)
        np.testing.assert_array_equal(d.y, ref.y)
    named = IOData(series, frame)
    assert named.input_names == ("torque",) and named.output_names == ("left", "right")
    # explicit names win over the DataFrame's columns
    assert IOData(series, frame, output_names=["a", "b"]).output_names == ("a", "b")
    # a single string names a single channel
    assert IOData(u, y[:, 0], output_names="pos").output_names == ("pos",)


def test_integer_and_bool_data_become_float():
    d = IOData(np.arange(4), np.array([True, False, True, True]))
    assert d.u.dtype == np.float64 and d.y.dtype == np.float64
    np.testing.assert_array_equal(d.y[:, 0], [1.0, 0.0, 1.0, 1.0])


def test_slicing_keeps_names_and_dt():
    d = IOData(np.arange(10.0), np.arange(10.0) ** 2, dt=0.1, input_names=["a"])
    part = d[2:5]
    assert isinstance(part, IOData)
    assert part.n_samples == 3 and part.dt == 0.1 and part.input_names == ("a",)
    np.testing.assert_array_equal(part.y[:, 0], [4.0, 9.0, 16.0])
    with pytest.raises(TypeError, match="slicing only; got int"):
        d[3]


def test_as_iodata_passthrough_and_dt_override():
    d = IOData(np.arange(5.0), np.arange(5.0), dt=0.1)
    assert as_iodata(d) is d
    assert as_iodata(d, dt=0.1) is d
    d2 = as_iodata(d, dt=0.2)
    assert d2.dt == 0.2 and d.dt == 0.1
    assert as_iodata(np.arange(5.0), np.arange(5.0)).dt == 1.0
    assert as_iodata(np.arange(5.0), np.arange(5.0), 0.3, input_names=["q"]).input_names == ("q",)


def test_require_samples():
    d = IOData(np.arange(5.0), np.arange(5.0))
    d.require_samples(5, "x")
    with pytest.raises(DataError, match=r"A thing needs at least 6 samples; the record has 5"):
        d.require_samples(6, "A thing")


# ----------------------------------------------------------------------------- validation


def test_unequal_lengths():
    with pytest.raises(DataError, match=r"same number of samples; got len\(u\)=10, len\(y\)=9"):
        IOData(np.zeros(10), np.zeros(9))


def test_nan_names_channel_and_first_index():
    y = np.ones((20, 2))
    y[7, 1] = np.nan
    y[12, 1] = np.nan
    y[15, 0] = np.inf
    with pytest.raises(
        DataError,
        match=r"y channel 'y1' has 2 non-finite value\(s\); the first is NaN at "
        r"sample index 7",
    ):
        IOData(np.arange(20.0), y)


def test_nan_uses_given_channel_names():
    u = np.arange(10.0)
    u[3] = np.nan
    with pytest.raises(DataError, match=r"u channel 'torque' .* NaN at sample index 3"):
        IOData(u, np.arange(10.0), input_names=["torque"])


def test_inf():
    u = np.arange(10.0)
    u[4] = -np.inf
    with pytest.raises(DataError, match=r"u channel 'u' has 1 non-finite .* inf at sample index 4"):
        IOData(u, np.arange(10.0))


def test_non_numeric_strings():
    with pytest.raises(DataError, match=r"u must hold numbers; value 0 is the text 'a'"):
        IOData(["a", "b", "c"], [1.0, 2.0, 3.0])
    frame = pd.DataFrame({"y": ["1.0", "oops", "3"]})
    with pytest.raises(DataError, match=r"y must hold numbers; value 1 is the text 'oops'"):
        IOData([1.0, 2.0, 3.0], frame)


def test_numeric_strings_are_converted():
    # documented behaviour of numpy's astype: text that parses as numbers is accepted
    d = IOData(["1", "2.5", "3"], [1, 2, 3])
    np.testing.assert_array_equal(d.u[:, 0], [1.0, 2.5, 3.0])


def test_ragged():
    with pytest.raises(DataError, match="u must be a numeric array-like; could not convert"):
        IOData([[1.0, 2.0], [3.0]], [1.0, 2.0])


def test_complex():
    with pytest.raises(DataError, match="u must hold real numbers; got complex"):
        IOData(np.arange(3.0) + 1j, np.arange(3.0))


@pytest.mark.parametrize("empty", [[], np.zeros((0, 2)), np.zeros((5, 0))])
def test_empty(empty):
    with pytest.raises(DataError, match=r"u is empty \(shape"):
        IOData(empty, empty)


def test_three_d():
    with pytest.raises(DataError, match=r"u must be 1-D .* got 3-D with shape \(2, 2, 2\)"):
        IOData(np.zeros((2, 2, 2)), np.zeros(2))


def test_scalar():
    with pytest.raises(DataError, match="y must be 1-D or 2-D; got a scalar"):
        IOData([1.0], 3.0)


@pytest.mark.parametrize("dt", [0, -0.1, float("nan"), float("inf")])
def test_bad_dt(dt):
    with pytest.raises(DataError, match=r"dt .* must be a positive finite number of seconds"):
        IOData(np.arange(3.0), np.arange(3.0), dt=dt)


def test_non_numeric_dt():
    with pytest.raises(DataError, match=r"dt \(sample time\) must be a number of seconds; got 'x'"):
        IOData(np.arange(3.0), np.arange(3.0), dt="x")
    with pytest.raises(DataError, match=r"must be a number of seconds; got \[1, 2\]"):
        as_iodata(IOData(np.arange(3.0), np.arange(3.0)), dt=[1, 2])  # type: ignore[arg-type]


def test_wrong_names_count():
    with pytest.raises(DataError, match=r"input_names must name 1 channel\(s\); got 2"):
        IOData(np.arange(3.0), np.arange(3.0), input_names=["a", "b"])
    with pytest.raises(DataError, match=r"output_names must name 2 channel\(s\); got 1"):
        IOData(np.arange(3.0), np.zeros((3, 2)), output_names=["a"])


def test_dataframe_with_wrong_column_count_falls_back_to_defaults():
    frame = pd.DataFrame(np.zeros((3, 2)), columns=["p", "q"])
    assert IOData(np.arange(3.0), frame).output_names == ("p", "q")


def test_as_iodata_errors():
    d = IOData(np.arange(3.0), np.arange(3.0))
    with pytest.raises(DataError, match=r"pass either an IOData or \(u, y\), not both"):
        as_iodata(d, np.arange(3.0))
    with pytest.raises(DataError, match="y is missing"):
        as_iodata(np.arange(3.0))


def test_data_error_is_value_error():
    assert issubclass(DataError, ValueError)


# ----------------------------------------------------------------------------- datasets

SHAPES = {
    "robot_arm": (1024, 1, 1),
    "ballbeam": (1000, 1, 1),
    "dryer": (1000, 1, 1),
    "cd_player_arm": (2048, 2, 2),
    "exchanger": (4000, 1, 1),
    "winding": (2500, 5, 2),
    "industrial_dryer": (867, 3, 3),
}


@pytest.mark.parametrize("name", datasets.names())
def test_every_record_loads(name):
    loaded = datasets.load(name)
    parts = loaded if isinstance(loaded, tuple) else (loaded,)
    spec = datasets.DATASETS[name]
    for part in parts:
        assert isinstance(part, IOData)
        assert part.n_samples > 100
        assert np.all(np.isfinite(part.u)) and np.all(np.isfinite(part.y))
        assert part.dt == (spec.dt or 1.0)
        assert np.ptp(part.u, axis=0).min() > 0 and np.ptp(part.y, axis=0).min() > 0
    if name in SHAPES:
        d = parts[0]
        assert (d.n_samples, d.n_inputs, d.n_outputs) == SHAPES[name]
        assert d.input_names == spec.inputs and d.output_names == spec.outputs
    assert datasets.path(name).is_file()


def test_cascaded_tanks_returns_estimation_and_validation():
    est, val = datasets.load("cascaded_tanks")
    assert (est.n_samples, val.n_samples) == (1024, 1024)
    assert est.dt == val.dt == 4.0
    assert est.output_names == ("yEst",) and val.output_names == ("yVal",)
    assert not np.array_equal(est.y, val.y)
    # the documented saturation of the level at 10
    assert max(est.y.max(), val.y.max()) <= 10.0 + 1e-9


def test_names_and_unknown_dataset():
    assert set(SHAPES) | {"cascaded_tanks"} == set(datasets.names())
    with pytest.raises(KeyError, match="unknown dataset 'nope'; available: robot_arm"):
        datasets.load("nope")


def test_top_level_exports():
    for name in clpc.__all__:
        assert hasattr(clpc, name)


# ----------------------------------------------------------------------------- example


def test_real_data_example_smoke(capsys, monkeypatch):
    import importlib.util
    import sys
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "real_data_lpc.py"
    spec = importlib.util.spec_from_file_location("real_data_lpc", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "real_data_lpc", module)
    spec.loader.exec_module(module)

    assert module.main(["--records", "dryer", "--orders", "2", "3"]) == 0
    out = capsys.readouterr().out
    lines = [line for line in out.splitlines() if line.startswith("| dryer |")]
    assert len(lines) == 2
    assert "LPC paper sim %" in out and "LS ARX k10 %" in out
    # order 3 on the dryer: every estimator simulates a stable model with a fit above 75 %
    cells = [c.strip() for c in lines[1].strip("|").split("|")]
    assert cells[:2] == ["dryer", "3"]
    assert all(float(c) > 75.0 for c in cells[2:])
