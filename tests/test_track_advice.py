"""Issue 28, items 1 and 6: ``track --na/--nb``, advice when the data cannot decide, dt hint.

A sine input is persistently exciting of order 2 only: with nb = 2 every window is rejected
("not persistently exciting of order 3"), and ``clpc track`` must then say what would help.
Without ``--time``/``--dt`` beside a column named like sample times, ``identify`` and
``track`` warn on stderr that dt = 1 s is used.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from click.testing import CliRunner

from clpc.cli import cli
from clpc.data.time_units import time_like
from clpc.workflows import AppraiserSettings
from clpc.workflows.track_advice import excitation_advice


def _run(*args: object):
    return CliRunner().invoke(cli, [str(a) for a in args])


def _record(path, u: np.ndarray, time_name: str = "t_s", seed: int = 1):
    """A second-order plant (poles 0.75 +- 0.37j, delay 1) driven by ``u``, written as CSV."""
    rng = np.random.default_rng(seed)
    y = np.zeros(u.size)
    for k in range(2, u.size):
        y[k] = 1.5 * y[k - 1] - 0.7 * y[k - 2] + 0.5 * u[k - 1]
    y += 1e-3 * rng.standard_normal(u.size)
    t = 0.01 * np.arange(u.size)
    np.savetxt(path, np.c_[t, u, y], delimiter=",", header=f"{time_name},u,y", comments="")
    return str(path)


@pytest.fixture
def sine_csv(tmp_path):
    return _record(tmp_path / "sine.csv", np.sin(2 * np.pi * 0.01 * np.arange(3000)))


@pytest.fixture
def noise_csv(tmp_path):
    return _record(tmp_path / "noise.csv", np.random.default_rng(0).standard_normal(3000))


# ============================================================================ --na/--nb
def test_track_takes_na_nb_nk(noise_csv, tmp_path):
    out = tmp_path / "run"
    res = _run("track", noise_csv, "-u", "u", "-y", "y", "--dt", 0.01, "--na", 2, "--nb", 0,
               "--nk", 1, "--out", out)  # fmt: skip
    assert res.exit_code == 0, res.output
    header = (out / "trace.csv").read_text().splitlines()[0].split(",")
    assert [c for c in header if c[0] in "ab" and c[1:].isdigit()] == ["a0", "a1", "a2", "b0"]
    assert "accepted" in res.output and not res.output.startswith("0 updates")
    first = res.output.split(":")[1]
    assert int(first.split()[0]) > 200  # most of the 249 windows are accepted


def test_appraiser_settings_na_nb_reach_the_appraiser():
    s = AppraiserSettings(order=2, na=3, nb=1, nk=2).build(None).structure
    assert (s.na, s.nb, s.nk) == (3, 1, 2)
    with pytest.raises(ValueError, match="nb"):
        AppraiserSettings(nb=-1)


def test_identify_and_track_share_the_na_nb_options():
    for command in ("identify", "track"):
        res = _run(command, "--help")
        assert "--na INTEGER RANGE" in res.output and "--nb INTEGER RANGE" in res.output
    res = _run("track", "x.csv", "-u", "u", "-y", "y", "--nb", -1, "--out", "o")
    assert res.exit_code == 2 and "--nb" in res.output


# ============================================================================ advice
def test_track_advises_when_a_sine_input_excites_too_little(sine_csv, tmp_path):
    out = tmp_path / "run"
    res = _run("track", sine_csv, "-u", "u", "-y", "y", "--time", "t_s", "--out", out)
    assert res.exit_code == 0, res.output
    advice = [line for line in res.output.splitlines() if "cannot decide" in line]
    assert len(advice) == 1, res.output
    line = advice[0]
    assert "0 of 249 windows accepted, 249 rejected" in line
    assert "not persistently exciting of order 3" in line
    assert "order 2 of the 5 (na + nb + 1)" in line  # measured vs needed
    assert "threshold 1e-05" in line
    for hint in ("a richer input", "--nb 1", "--window-size than 201", "clpc identify"):
        assert hint in line
    assert f"clpc identify {sine_csv} -u u -y y" in line
    html = (out / "report.html").read_text()
    assert "0 of 249 windows accepted" in html and "a richer input" in html


def test_track_gives_no_advice_when_the_input_excites_enough(noise_csv, tmp_path):
    res = _run("track", noise_csv, "-u", "u", "-y", "y", "--time", "t_s", "--out", tmp_path / "o")
    assert res.exit_code == 0, res.output
    assert "cannot decide" not in res.output
    assert "cannot decide" not in (tmp_path / "o" / "report.html").read_text()


class _Trace:
    """The least of a scanned trace that :func:`excitation_advice` reads."""

    def __init__(self, accepted: np.ndarray, relations: np.ndarray) -> None:
        from clpc.model.structure import Structure

        self.counts = {"accepted": int(accepted.sum()), "lacking": int((relations > 0).sum())}
        self.structure = Structure(2, 2, 0)
        self.n = accepted.size

    def __len__(self) -> int:
        return self.n


@pytest.mark.parametrize(
    ("n_accepted", "n_lacking", "advised"),
    [(0, 100, True), (40, 60, True), (50, 50, False), (0, 40, False), (0, 60, True)],
)
def test_excitation_advice_only_when_few_accepted_for_want_of_excitation(
    n_accepted, n_lacking, advised
):
    accepted = np.arange(100) < n_accepted
    lacking = (np.arange(100) >= 100 - n_lacking).astype(int)
    command = {"file": "f.csv", "inputs": ("u",), "outputs": ("y",)}
    u = np.sin(0.3 * np.arange(500))[:, None]
    text = excitation_advice(_Trace(accepted, lacking), u, 201, command)
    assert (text is not None) == advised
    if advised:
        assert f"{n_accepted} of 100 windows accepted, {n_lacking} rejected" in text
        assert "the last 500 samples together of order 2" in text


def test_excitation_advice_without_samples_still_advises():
    command = {"file": "my file.csv", "inputs": ("u 1",), "outputs": ("y",)}
    trace = _Trace(np.zeros(10, bool), np.ones(10, int))
    text = excitation_advice(trace, np.empty((0, 1)), 201, command)
    assert text is not None and "measured" not in text
    assert "clpc identify 'my file.csv' -u 'u 1' -y y" in text  # quoted for a shell


# ============================================================================ dt hint
@pytest.mark.parametrize(
    ("name", "unit"),
    [("t", "s"), ("time", "s"), ("t_s", "s"), ("t_ms", "ms"), ("time_us", "us"),
     ("timestamp", "s"), ("Time [ms]", "ms"), ("t1", None), ("torque", None),
     ("temp", None), ("u", None), ("time_of_day", None)],
)  # fmt: skip
def test_time_like_names(name, unit):
    assert time_like(name) == unit


@pytest.mark.parametrize("command", ["identify", "track"])
def test_unnamed_time_column_warns_once_on_stderr(command, tmp_path):
    path = _record(tmp_path / "r.csv", np.random.default_rng(0).standard_normal(600), "t_ms")
    extra = ["--estimator", "arx", "--order", 2, "--nk", 1] if command == "identify" else []
    if command == "track":
        extra = ["--out", tmp_path / "o"]
    res = _run(command, path, "-u", "u", "-y", "y", *extra)
    assert res.exit_code == 0, res.output
    lines = [line for line in res.stderr.splitlines() if line.startswith("warning:")]
    assert lines == [
        "warning: column 't_ms' looks like sample times [ms] but neither --time nor --dt was "
        "given, so dt = 1 s is used; use --time t_ms (or --dt)."
    ]
    assert "looks like sample times" not in res.stdout


@pytest.mark.parametrize(
    "extra", [["--time", "t_ms"], ["--dt", 0.01]], ids=["time-given", "dt-given"]
)
def test_no_time_hint_when_the_time_base_is_given(extra, tmp_path):
    path = _record(tmp_path / "r.csv", np.random.default_rng(0).standard_normal(600), "t_ms")
    res = _run("identify", path, "-u", "u", "-y", "y", "--estimator", "arx", "--order", 2,
               "--nk", 1, *extra)  # fmt: skip
    assert res.exit_code == 0, res.output
    assert "looks like sample times" not in res.stderr


def test_no_time_hint_for_a_time_like_column_used_as_a_signal(tmp_path):
    path = _record(tmp_path / "r.csv", np.random.default_rng(0).standard_normal(600), "time")
    res = _run("identify", path, "-u", "time", "-y", "y", "--estimator", "arx", "--order", 1,
               "--nk", 1)  # fmt: skip
    assert "looks like sample times" not in res.stderr


def test_dataclass_replace_keeps_na_nb():
    s = dataclasses.replace(AppraiserSettings(na=1, nb=0), window_size=50)
    assert (s.na, s.nb) == (1, 0)


def test_no_time_hint_beside_a_missing_column_error(tmp_path):
    path = _record(tmp_path / "r.csv", np.random.default_rng(0).standard_normal(600), "t")
    res = _run("identify", path, "-u", "u", "-y", "speed")
    assert res.exit_code == 1
    assert len(res.output.strip().splitlines()) == 1 and "speed" in res.output


def test_report_draws_the_window_tests_that_rejected_the_sine(sine_csv, noise_csv, tmp_path):
    # issue 28 item 6: the report said its figure "shows why" no window was accepted; the
    # window tests (separation and a0 weight against the rule's thresholds) now show it
    pytest.importorskip("matplotlib")
    import clpc
    from clpc.plotting.window_tests import REASONS, first_failure, plot_window_tests

    out = tmp_path / "sine"
    res = _run("track", sine_csv, "-u", "u", "-y", "y", "--dt", 0.01, "--out", out)
    assert res.exit_code == 0, res.output
    assert (out / "tests.png").stat().st_size > 10_000
    html = (out / "report.html").read_text()
    assert "Why windows were rejected" in html and "window tests below show why" in html
    # the figure's points are the trace's own measures; a sine leaves more than one
    # near-null direction in every full window: "not determined" first
    data = clpc.load_iodata(sine_csv, "u", "y", time_column="t_s")
    trace = clpc.CLPC(order=2).run(data)
    full = trace.rows == trace.rows.max()
    assert np.all(trace.arrays["n_null"][full, 0] > 1)
    assert np.all(first_failure(trace, 0)[full] == REASONS.index("not determined"))
    fig = plot_window_tests(trace)
    sep_ax = fig.axes[1]
    drawn = np.concatenate([line.get_ydata() for line in sep_ax.lines[:2]])
    expected = np.clip(trace.arrays["separation"][:, 0], 1e-6, None)
    np.testing.assert_array_equal(np.sort(drawn), np.sort(expected))
    assert sep_ax.lines[2].get_ydata()[0] == clpc.RobustRule().separation
    # a well-excited record: most windows pass, no tests figure
    fine = tmp_path / "noise"
    done = _run("track", noise_csv, "-u", "u", "-y", "y", "--dt", 0.01, "--out", fine)
    assert done.exit_code == 0
    assert not (fine / "tests.png").exists()
