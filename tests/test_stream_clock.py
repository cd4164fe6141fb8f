"""``clpc stream --time``: the readers' time-base rule, one sample at a time (issue 28).

A 1 kHz log with 1e-5 relative jitter, Unix-epoch stamps and a dropped sample must give
every good sample to the appraiser, and the same updates as ``clpc track`` on the file.
"""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from click.testing import CliRunner

import clpc
from clpc.cli import cli
from clpc.data.timegrid import TimeGrid

N = 2400
WINDOW = ("--window-size", "101", "--cluster-size", "10")


def run(*args, input=None):
    return CliRunner().invoke(cli, [str(a) for a in args], input=input)


def _log(drop=(), jitter=1e-5, t0=1.7e9, scale=1.0, name="t", seed=3):
    """A 1 kHz drive-like log: csv text (time, volt, pos) and the samples kept."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(N)
    y = clpc.simulate_arx(np.array([1.0, -1.5, 0.7]), np.array([0.2, 0.5, 0.1]), u)
    y = y + 0.01 * rng.standard_normal(N)
    t = (t0 + (np.arange(N) + jitter * rng.standard_normal(N)) * 1e-3) * scale
    keep = np.ones(N, bool)
    keep[list(drop)] = False
    rows = zip(t[keep].tolist(), u[keep].tolist(), y[keep].tolist(), strict=True)
    text = f"{name},volt,pos\n" + "".join(f"{a:.7f},{b!r},{c!r}\n" for a, b, c in rows)
    return text, u[keep], y[keep]


def _stream(text, *extra):
    res = run("stream", "-u", "volt", "-y", "pos", *WINDOW, *extra, input=text)
    return res, [json.loads(line) for line in res.stdout.splitlines()]


def _track(tmp_path, text, *sampling):
    path = tmp_path / "log.csv"
    path.write_text(text)
    res = run("track", path, "-u", "volt", "-y", "pos", *sampling, *WINDOW, "--out", tmp_path / "o")
    assert res.exit_code == 0, res.output
    with open(tmp_path / "o" / "trace.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def _same_as_track(updates, rows, dt_rtol):
    assert len(updates) == len(rows) > 100
    assert [u["index"] for u in updates] == [int(r["index"]) for r in rows]
    theta = np.array([[float(r[k]) for k in ("a0", "a1", "a2", "b0", "b1", "b2")] for r in rows])
    np.testing.assert_array_equal(np.array([u["theta"] for u in updates]), theta)
    assert [u["accepted"] for u in updates] == [r["accepted"] == "1" for r in rows]
    times = np.array([float(r["time"]) for r in rows])
    np.testing.assert_allclose([u["time"] for u in updates], times, rtol=dt_rtol)


def test_jittery_epoch_log_uses_every_sample_and_matches_track(tmp_path):
    """Formerly: 'off the uniform grid' for every line after the second, 0 updates, exit 0."""
    text, _, _ = _log()
    res, updates = _stream(text, "--time", "t")
    assert res.exit_code == 0, res.output
    assert "skipped" not in res.stderr and "missing" not in res.stderr
    # the stream's dt is the mean of its first steps, track's the mean of every step: the
    # stamps hold 1e-7 s of a 1e-3 s step, so the sample times agree to about 1e-4
    _same_as_track(updates, _track(tmp_path, text, "--time", "t"), dt_rtol=2e-4)


def test_dropped_sample_is_reported_once_and_later_samples_are_used(tmp_path):
    text, _, _ = _log(drop=[1500])
    res, updates = _stream(text, "--time", "t")
    assert res.exit_code == 0, res.output
    gaps = [line for line in res.stderr.splitlines() if "missing" in line]
    assert len(gaps) == 1 and gaps[0].startswith("clpc stream: line 1502: 1 sample(s) missing")
    assert "skipped" not in res.stderr
    # every kept sample goes to the appraiser, one after the other, as track --dt reads them
    _same_as_track(updates, _track(tmp_path, text, "--dt", "0.001"), dt_rtol=2e-4)


def test_track_reads_the_time_column_across_a_dropped_sample_as_the_stream(tmp_path):
    """One time-base rule: formerly track refused the file ('not uniformly sampled')."""
    text, _, _ = _log(drop=[1500])
    _, updates = _stream(text, "--time", "t")
    path = tmp_path / "log.csv"
    path.write_text(text)
    res = run(
        "track", path, "-u", "volt", "-y", "pos", "--time", "t", *WINDOW, "--out", tmp_path / "o"
    )
    assert res.exit_code == 0, res.output
    notes = [line for line in res.stderr.splitlines() if "missing" in line]
    assert len(notes) == 1 and notes[0].startswith(
        "warning: time column 't': 1 sample(s) missing before data row 1501"
    ), res.stderr
    with open(tmp_path / "o" / "trace.csv", newline="") as fh:
        _same_as_track(updates, list(csv.DictReader(fh)), dt_rtol=2e-4)


@pytest.mark.parametrize("chunk_rows", [None, 700])
def test_gaps_in_the_first_or_a_later_chunk_reanchor_the_grid(tmp_path, monkeypatch, chunk_rows):
    """Two gaps (1 and 3 samples) on an exact grid: the later samples stay on it."""
    text, u, y = _log(drop=[300, 1800, 1801, 1802], jitter=0.0, t0=0.0)
    if chunk_rows is not None:
        import clpc.workflows.track as track_module

        real = track_module.iter_table_chunks
        monkeypatch.setattr(
            track_module, "iter_table_chunks", lambda path, rows, **k: real(path, chunk_rows, **k)
        )
    path = tmp_path / "log.csv"
    path.write_text(text)
    res = run(
        "track", path, "-u", "volt", "-y", "pos", "--time", "t", *WINDOW, "--out", tmp_path / "o"
    )
    assert res.exit_code == 0, res.output
    assert "1 sample(s) missing before data row 301" in res.stderr  # kept sample 300
    assert "3 sample(s) missing" in res.stderr or "4 samples missing in all" in res.stderr
    with open(tmp_path / "o" / "trace.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    ref = clpc.CLPC(order=2, window_size=101, cluster_size=10).run(u, y)  # the kept samples
    theta = np.array([[float(r[k]) for k in ("a0", "a1", "a2", "b0", "b1", "b2")] for r in rows])
    np.testing.assert_array_equal(theta, ref.theta)


def test_bad_stamp_is_refused_and_the_grid_is_not_lost():
    text, _, _ = _log(jitter=0.0, t0=0.0)
    lines = text.splitlines(keepends=True)
    lines[700] = "99999," + lines[700].split(",", 1)[1]  # a stamp far ahead
    lines[900] = "0.5," + lines[900].split(",", 1)[1]  # a stamp going back
    res, updates = _stream("".join(lines), "--time", "t")
    assert res.exit_code == 0, res.output
    skipped = [line for line in res.stderr.splitlines() if line.endswith("(skipped)")]
    assert [s.split(":")[1].strip() for s in skipped] == ["line 701", "line 901"]
    assert "2 malformed line(s) skipped" in res.stderr
    ref = clpc.CLPC(order=2, window_size=101, cluster_size=10).run(*_kept(text, [699, 899]))
    assert len(updates) == len(ref)
    np.testing.assert_array_equal(np.array([u["theta"] for u in updates]), ref.theta)


def _kept(text, drop):
    rows = np.array([[float(v) for v in line.split(",")] for line in text.splitlines()[1:]])
    rows = np.delete(rows, drop, axis=0)
    return rows[:, 1], rows[:, 2]


@pytest.mark.parametrize(
    ("name", "scale", "extra"),
    [("t_ms", 1e3, ()), ("stamp", 1e3, ("--time-unit", "ms")), ("time_us", 1e6, ())],
)
def test_time_unit_from_the_column_name_or_the_option(name, scale, extra):
    """Formerly a t_ms column was read as seconds (dt = 1 s)."""
    text, _, _ = _log(jitter=0.0, t0=0.0, scale=scale, name=name)
    res, updates = _stream(text, "--time", name, *extra)
    assert res.exit_code == 0, res.output
    assert updates[0]["time"] == pytest.approx(updates[0]["index"] * 1e-3, rel=1e-9)


def test_time_rtol_is_the_readers_tolerance():
    text, _, _ = _log(jitter=2e-3)  # steps deviate by up to ~1 %: refused at 1e-3
    res, updates = _stream(text, "--time", "t", "--time-rtol", "1e-3")
    assert "sample refused" in res.stderr
    res, loose = _stream(text, "--time", "t", "--time-rtol", "0.05")
    assert res.exit_code == 0 and "refused" not in res.stderr and len(loose) > len(updates)


def test_no_update_because_of_the_clock_exits_nonzero():
    """Formerly exit 0 with every line 'off the grid' and no update."""
    text, _, _ = _log(jitter=0.0, t0=0.0)
    lines = text.splitlines(keepends=True)
    stuck = [lines[0]] + ["5," + line.split(",", 1)[1] for line in lines[1:]]
    res, updates = _stream("".join(stuck), "--time", "t")
    assert res.exit_code == 1 and updates == []
    last = res.output.strip().splitlines()[-1]
    assert last.startswith("Error:") and "time column 't'" in last and "Traceback" not in res.output
    res, _ = _stream("".join(lines[:2]), "--time", "t")
    assert res.exit_code == 1 and "2 are needed" in res.output


def test_time_unit_without_time_is_a_usage_error():
    res = run("stream", "--dt", "0.1", "--time-unit", "ms", input="1,2\n")
    assert res.exit_code == 2 and "--time" in res.output


def test_time_grid_follows_a_clock_that_jumped():
    grid = TimeGrid("t")
    notes = [n for k in range(100) for n in grid.feed(k * 0.01, f"line {k}")]
    assert notes == [] and grid.dt == 0.01
    with pytest.raises(ValueError, match="not a whole number"):
        grid.feed(100.004, "line 100")  # off the grid: refused
    notes = grid.feed(100.014, "line 101")  # one step after it: the clock jumped
    assert len(notes) == 1 and "jumped" in notes[0] and grid.refused == 1
    assert grid.feed(100.024, "line 102") == []


def test_time_grid_warm_up_gap_is_reported_and_does_not_bias_dt():
    grid = TimeGrid("t_ms", warmup=8)
    stamps = [0, 2, 4, 8, 10, 12, 14, 16, 18]  # ms; one sample missing at 6
    notes = [n for k, s in enumerate(stamps) for n in grid.feed(s, f"line {k + 2}")]
    assert grid.dt == 0.002
    assert len(notes) == 1 and notes[0].startswith("line 5: 1 sample(s) missing")


def test_readers_take_a_dropped_sample_with_one_warning_line(tmp_path):
    text, u, _ = _log(drop=[1000, 1001], jitter=0.0, t0=0.0)
    path = tmp_path / "log.csv"
    path.write_text(text)
    with pytest.warns(UserWarning, match=r"'t' of .*: 2 sample\(s\) missing before line 1002"):
        data = clpc.load_iodata(path, "volt", "pos", time_column="t")
    assert data.dt == 1e-3 and data.n_samples == N - 2
    np.testing.assert_array_equal(data.u[:, 0], u)
    res = run(
        "identify",
        path,
        "-u",
        "volt",
        "-y",
        "pos",
        "--time",
        "t",
        "--order",
        "2",
        "--estimator",
        "arx",
    )
    assert res.exit_code == 0, res.output
    warned = [line for line in res.stderr.splitlines() if line.startswith("warning:")]
    assert len(warned) == 1 and "2 sample(s) missing before line 1002" in warned[0]
    assert "UserWarning" not in res.stderr and "warnings.warn" not in res.stderr


def test_the_stream_and_the_readers_classify_a_step_alike():
    """One rule written twice (array and scalar forms): they must agree, at any tolerance."""
    from clpc.data.time_gaps import classify_steps, whole_steps

    rng = np.random.default_rng(5)
    steps = np.concatenate([rng.uniform(0.0, 4.0, 20_000), np.arange(1, 1003) * 1.003, [np.inf]])
    for rtol in (1e-3, 1e-2, 0.3, 0.6):
        single, missing = classify_steps(steps, 1.0, rtol)
        want = np.where(single, 1, np.where(missing > 0, missing + 1, 0))
        got = np.array([whole_steps(float(s), 1.0, rtol) for s in steps])
        np.testing.assert_array_equal(got, want)
