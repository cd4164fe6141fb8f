"""The fleet's arithmetic and sources, without a cluster: band, distance, median, outliers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from clpc.analysis.excited_band import InputSpectrum, excited_band
from clpc.analysis.fleet import (
    FleetModel,
    band_grid,
    fleet_band,
    gain_drift,
    median_model,
    outlier_scores,
    response_distance,
)
from clpc.data import IOData
from clpc.workflows import SettingsError
from clpc.workflows.fleet_settings import FleetSettings
from clpc.workflows.fleet_sources import expand_sources, record_name


def _model(gain: float = 1.0, a1: float = -1.5) -> FleetModel:
    return FleetModel(np.array([[1.0, a1, 0.7]]), gain * np.array([[[0.0, 0.1, 0.05]]]), dt=0.001)


def test_the_spectrum_is_welchs_and_does_not_depend_on_how_the_record_is_chunked():
    rng = np.random.default_rng(0)
    u = rng.standard_normal((10_000, 2))
    whole = InputSpectrum(0.01, segment=256)
    whole.feed(u)
    pieces = InputSpectrum(0.01, segment=256)
    for part in np.array_split(u, [7, 300, 301, 5000]):
        pieces.feed(part)
    f1, p1 = whole.spectrum()
    f2, p2 = pieces.spectrum()
    assert np.array_equal(f1, f2) and np.allclose(p1, p2, rtol=1e-12)
    # scipy's Welch (symmetric Hann, no overlap, mean removed), one-sided density: ours
    # is the same up to the factor fs / 2 between the two bins' ends
    f_ref, p_ref = signal.welch(
        u[: 39 * 256, 0], fs=100.0, window=np.hanning(256), noverlap=0, detrend="constant"
    )
    assert np.allclose(f_ref, f1)
    assert np.allclose(p1[1:-1, 0], p_ref[1:-1] * 100.0 / 2, rtol=1e-10)


def test_the_band_holds_the_frequencies_an_input_excites():
    dt, n = 0.001, 2**16
    t = np.arange(n) * dt
    u = np.sin(2 * np.pi * 20.0 * t) + 0.5 * np.sin(2 * np.pi * 150.0 * t)
    spec = InputSpectrum(dt, segment=1024)
    spec.feed(u[:, None])
    band = excited_band(*spec.spectrum())
    assert band is not None
    resolution = 1 / (1024 * dt)
    # the Hann window spreads each line over +-2 bins; both lines are within 20 dB
    assert abs(band[0] - 20.0) <= 2 * resolution and abs(band[1] - 150.0) <= 2 * resolution
    constant = InputSpectrum(dt, segment=64)
    constant.feed(np.ones((500, 1)))
    assert excited_band(*constant.spectrum()) is None
    with pytest.raises(ValueError, match="at least 4 samples"):
        InputSpectrum(dt).spectrum()


def test_a_model_with_a_fifth_less_gain_is_at_distance_0_2_from_the_median():
    freqs = band_grid((1.0, 400.0))
    models = [_model(), _model(), _model(0.8), _model(), _model()]
    ref = median_model(models)
    assert np.array_equal(ref.den, models[0].den) and np.array_equal(ref.num, models[0].num)
    assert response_distance(models[2], ref, freqs) == pytest.approx(0.2, rel=1e-12)
    assert response_distance(models[0], ref, freqs) == 0.0
    # the median is coefficient-wise (np.median of the stacked coefficients)
    spread = [_model(a1=a) for a in (-1.50, -1.52, -1.49, -1.40)]
    assert median_model(spread).den[0, 1] == pytest.approx(np.median([-1.5, -1.52, -1.49, -1.4]))
    # a model of another sample time does not enter the median
    other = FleetModel(models[0].den, 3 * models[0].num, dt=0.01)
    assert np.array_equal(median_model([*models, other]).num, ref.num)


def test_the_distance_is_the_relative_rms_of_the_response_difference():
    freqs = np.array([1.0, 10.0, 100.0])
    a, b = _model(), _model(a1=-1.45)
    ha, hb = a.response(freqs)[:, 0, 0], b.response(freqs)[:, 0, 0]
    expected = np.sqrt(np.sum(np.abs(hb - ha) ** 2) / np.sum(np.abs(ha) ** 2))
    assert response_distance(b, a, freqs) == pytest.approx(expected, rel=1e-12)
    assert a.dc_gain()[0, 0] == pytest.approx(0.15 / 0.2)


def test_outliers_by_robust_z_score():
    d = [0.010, 0.012, 0.011, 0.009, 0.2, 0.010]
    z, flag = outlier_scores(d)
    med = np.median(d)
    scale = max(1.4826 * np.median(np.abs(np.array(d) - med)), 0.01)
    assert np.allclose(z, (np.array(d) - med) / scale)
    assert flag.tolist() == [False, False, False, False, True, False]
    assert not outlier_scores([0.0, 5.0])[1].any()  # two records: no spread to judge by
    assert not outlier_scores([0.01, 0.011, 0.012, 0.02])[1].any()  # below the 1 % floor


def test_gain_drift_compares_the_last_quarter_with_the_first():
    g = np.linspace(1.0, 2.0, 101)
    q = 101 // 4
    expected = (np.median(g[-q:]) - np.median(g[:q])) / np.median(g)
    assert gain_drift(g) == pytest.approx(expected)
    assert gain_drift(np.array([1.0, np.nan] * 3)) is None  # too few finite values


def test_the_fleet_band_is_the_median_of_the_edges():
    assert fleet_band([(1.0, 100.0), (2.0, 300.0), (1.5, 200.0)]) == (1.5, 200.0)
    with pytest.raises(ValueError, match="no band"):
        fleet_band([(5.0, 1.0)])


def _touch(path, text="t,u,y\n0,1,2\n"):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def test_sources_files_globs_folders_partitions_and_iodata(tmp_path):
    a = _touch(tmp_path / "one" / "m1.csv")
    b = _touch(tmp_path / "two" / "m1.csv.gz")
    _touch(tmp_path / "one" / "notes.md")
    assert record_name(b) == "m1"
    found = expand_sources([str(tmp_path / "one"), str(tmp_path / "two" / "*.gz")])
    assert [(s.name, s.file) for s in found] == [("one-m1", str(a)), ("two-m1", str(b))]
    ds = tmp_path / "ds"
    for axis in ("A2", "A1"):
        _touch(ds / f"axis={axis}" / "part.parquet")
    parts = expand_sources(ds)
    assert [s.name for s in parts] == ["axis=A1", "axis=A2"]
    assert parts[0].file == str(ds / "axis=A1" / "part.parquet")
    data = IOData(np.zeros(10), np.zeros(10))
    mixed = expand_sources([data, a])
    assert mixed[0].name == "record-0" and mixed[0].data is data and mixed[1].name == "m1"
    named = expand_sources({"x/y": a, "z": data})
    assert [s.name for s in named] == ["x_y", "z"]


def test_sources_that_name_nothing_are_refused_with_the_reason(tmp_path):
    with pytest.raises(SettingsError, match="no such file or folder"):
        expand_sources(str(tmp_path / "missing.csv"))
    with pytest.raises(SettingsError, match="no file matches"):
        expand_sources(str(tmp_path / "*.csv"))
    (tmp_path / "empty").mkdir()
    with pytest.raises(SettingsError, match="holds no data file"):
        expand_sources(tmp_path / "empty")
    _touch(tmp_path / "ds" / "axis=A1" / "a.parquet")
    _touch(tmp_path / "ds" / "axis=A1" / "b.parquet")
    with pytest.raises(SettingsError, match="holds 2 data files"):
        expand_sources(tmp_path / "ds")


def test_fleet_settings_take_track_s_names_and_refuse_unknown_ones():
    s = FleetSettings.from_keywords(inputs="u", outputs=["y"], dt=0.01, order=3, fmt="parquet")
    assert s.record.inputs == ("u",) and s.record.outputs == ("y",) and s.record.dt == 0.01
    assert s.appraiser.order == 3 and s.fmt == "parquet"
    ts = s.track_settings("a.csv", "out/a")
    assert ts.record.file == "a.csv" and ts.out_dir == "out/a" and ts.appraiser.order == 3
    with pytest.raises(TypeError, match=r"unknown setting.*'windowsize'"):
        FleetSettings.from_keywords(inputs="u", outputs="y", windowsize=10)
    with pytest.raises(SettingsError, match="cannot resample"):
        FleetSettings.from_keywords(inputs="u", outputs="y", time_col="t", resample=True)
    with pytest.raises(SettingsError, match="--decimate-to"):
        FleetSettings.from_keywords(inputs="u", outputs="y", decimate_to=0.01)


def test_a_record_on_its_own_decimated_equals_track_file(tmp_path):
    from clpc.workflows import track_file
    from clpc.workflows.fleet_record import track_record
    from clpc.workflows.fleet_settings import RecordSource
    from fleet_sim import axis_record

    path = tmp_path / "a.parquet"
    axis_record(5, 6000).drop(columns="t").to_parquet(path)
    settings = FleetSettings.from_keywords(
        inputs="u", outputs="y", dt=0.001, decimate_to=0.002, window_size=101
    )
    row = track_record(RecordSource("a", file=str(path)), settings, str(tmp_path / "out"))
    assert row["error"] is None, row["error"]
    direct = track_file(settings.track_settings(str(path), str(tmp_path / "direct")))
    assert row["dt"] == 0.002 == direct.model.dt and row["samples"] == 6000
    assert np.array_equal(np.asarray(row["den"]), direct.model.denominators)
    lo, hi = row["band_hz"]
    assert 0 < lo < hi <= 0.5 / 0.002  # capped at the decimated model's Nyquist frequency
    trace = (tmp_path / "out" / "a" / "trace.csv").read_bytes()
    assert trace == (tmp_path / "direct" / "trace.csv").read_bytes()
    # without an output folder: the same row, nothing kept
    alone = track_record(RecordSource("a", file=str(path)), settings, None)
    assert alone["folder"] is None and alone["den"] == row["den"]


def test_track_many_refuses_bad_sources_before_starting_a_cluster(tmp_path):
    from click.testing import CliRunner

    from clpc.cli import cli

    res = CliRunner().invoke(
        cli,
        ["track-many", str(tmp_path / "nope.csv"), "-u", "u", "-y", "y", "--out", str(tmp_path)],
    )
    assert res.exit_code == 2 and "no such file or folder" in res.output, res.output
    res = CliRunner().invoke(
        cli,
        [
            "track-many",
            str(tmp_path),
            "-u",
            "u",
            "-y",
            "y",
            "--out",
            str(tmp_path),
            "--time",
            "t",
            "--resample",
        ],
    )
    assert res.exit_code == 2 and "cannot resample" in res.output, res.output


def test_records_without_a_common_band_are_listed_not_ranked():
    from clpc.workflows.fleet_table import rank_rows

    model = _model()
    row = {"den": model.den.tolist(), "num": model.num.tolist(), "dt": model.dt, "error": None}
    bands = ([520.0, 600.0], [540.0, 700.0])  # median 530-650 Hz, above the Nyquist 500 Hz
    rows = [dict(row, name=n, band_hz=b) for n, b in zip("ab", bands, strict=True)]
    ranked, band, ref, method = rank_rows(rows)
    assert band is None and ref is not None and all(r["rank"] is None for r in ranked)
    assert method.startswith("The records are not ranked: the band 530 Hz is above")
    ranked, band, _, method = rank_rows([dict(r, band_hz=None) for r in rows])
    assert band is None and "no band to compare over" in method
    assert rank_rows([{"name": "x", "error": "DataError: bad"}])[3].startswith("No record has")
