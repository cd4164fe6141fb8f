"""One vocabulary: ``order``, ``window_size``, ``cluster_size`` everywhere, ``dt`` for the data's
sample time and ``decimate_to`` for the appraiser's, ``compare`` checks the model's dt,
``simulate`` keeps the time column, progress reaches a callback and the log."""

from __future__ import annotations

import logging
import warnings

import numpy as np
import pytest
from click.testing import CliRunner
from scipy import signal

import clpc
from clpc.cli import cli
from clpc.io import read_table, write_table


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(3)
    u = rng.standard_normal(3000)
    y = signal.lfilter([0.0, 0.5, 0.2], [1.0, -1.5, 0.7], u) + 0.01 * rng.standard_normal(3000)
    return u, y


def _run(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


def test_lpc_has_one_name_for_its_order():
    with pytest.raises(TypeError, match="parameters_size"):
        clpc.LPC(parameters_size=4)


def test_clpc_has_one_name_per_setting():
    assert "order=2" in repr(clpc.CLPC())
    for former in ("parameters_size", "data_cluster_dimension", "sample_time", "gate"):
        with pytest.raises(TypeError, match=former):
            clpc.CLPC(**{former: 3})
    with pytest.raises(TypeError, match="data_sample_time"):
        clpc.CLPC(data_sample_time=0.01)
    with pytest.raises(TypeError):
        clpc.CLPC(3, 101, 10)  # type: ignore[misc]  # settings are named, never positional
    assert not hasattr(clpc.CLPC(), "parameters_size")


def test_the_papers_names_are_not_settings(record):
    u, y = record
    with pytest.raises(TypeError, match="parameters_size"):
        clpc.workflows.AppraiserSettings(parameters_size=3)  # type: ignore[call-arg]
    with pytest.raises(TypeError, match="sample_time"):
        clpc.workflows.AppraiserSettings(sample_time=0.1)  # type: ignore[call-arg]
    settings = clpc.workflows.AppraiserSettings(order=3, window_size=101, cluster_size=10)
    a = settings.build(None).run(u, y)
    b = clpc.CLPC(order=3, window_size=101, cluster_size=10).run(u, y)
    np.testing.assert_array_equal(a.theta, b.theta)


def test_dt_and_decimate_to_are_unambiguous(record):
    u, y = record
    new = clpc.CLPC(order=2, window_size=101, cluster_size=5, dt=0.01, decimate_to=0.02)
    got = new.run(u, y)
    same = clpc.CLPC(order=2, window_size=101, cluster_size=5, decimate_to=0.02).run(u, y, 0.01)
    np.testing.assert_array_equal(got.theta, same.theta)
    assert got.sample_time == 0.02 and len(got) == len(same) > 0
    # the data's own sample time: no decimation, the trace's time axis in seconds
    plain = clpc.CLPC(order=2, window_size=101, cluster_size=5, dt=0.01).run(u, y)
    assert plain.sample_time == 0.01 and len(plain) > len(got)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the same rate: nothing ambiguous, no warning
        clpc.CLPC(order=2, window_size=101, cluster_size=5, decimate_to=0.01).run(u, y, 0.01)


def test_decimate_to_needs_the_data_rate_and_dt_must_agree(record):
    u, y = record
    with pytest.raises(clpc.DataError, match="needs the data's sample time"):
        clpc.CLPC(decimate_to=0.02).run(u, y)
    with pytest.raises(clpc.DataError, match="must agree"):
        clpc.CLPC(dt=0.01).run(clpc.IOData(u, y, dt=0.02))


def test_state_round_trip_keeps_the_new_names(record):
    u, y = record
    a = clpc.CLPC(order=2, window_size=101, cluster_size=5, dt=0.01, decimate_to=0.02)
    a.push(u[:1000], y[:1000])
    b = clpc.CLPC.from_state_dict(a.state_dict())
    assert (b.dt, b.decimate_to, b.order) == (0.01, 0.02, 2)
    np.testing.assert_array_equal(
        a.push(u[1000:], y[1000:]).theta, b.push(u[1000:], y[1000:]).theta
    )


def test_progress_callback_and_logging(record, caplog):
    u, y = record
    calls = []
    appraiser = clpc.CLPC(order=2, window_size=101, cluster_size=10, chunk_samples=1024)
    with caplog.at_level(logging.DEBUG, logger="clpc.appraiser"):
        trace = appraiser.run(u, y, progress=lambda *a: calls.append(a))
    assert [c[0] for c in calls] == [1024, 2048, 3000]
    assert all(c[1] == 3000 for c in calls) and calls[-1][2] == len(trace)
    assert sum("3000 of 3000 samples" in r.getMessage() for r in caplog.records) == 1


def test_cli_has_one_name_per_setting(tmp_path, record):
    u, y = record
    path = tmp_path / "r.csv"
    write_table(path, ["u", "y"], np.column_stack([u, y]))
    common = ["track", path, "-u", "u", "-y", "y", "--out", tmp_path / "a"]
    for former in (
        ("--parameters-size", "3"),
        ("-p", "3"),
        ("--sample-time", "1"),
        ("--window", "101"),
        ("--cluster", "5"),
        ("--gate",),
    ):
        res = _run(*common, *former)
        assert res.exit_code == 2 and "No such option" in res.output, (former, res.output)
    help_text = _run("track", "--help").output
    for name in ("--order", "--window-size", "--cluster-size", "--dt", "--decimate-to", "--guard"):
        assert name in help_text


def test_every_command_names_a_setting_alike_and_hides_no_option():
    import importlib

    from clpc.cli.app import COMMANDS

    seen: dict[str, tuple[str, tuple[str, ...]]] = {}
    for command, (module, attr) in COMMANDS.items():
        for param in getattr(importlib.import_module(module), attr).params:
            assert not getattr(param, "hidden", False), (command, param.name)
            if not param.opts[0].startswith("--"):
                continue  # arguments
            names = tuple(sorted(o for o in param.opts if o.startswith("--")))
            first = seen.setdefault(str(param.name), (command, names))
            assert first[1] == names, (param.name, first, command, names)


def test_compare_refuses_another_rate_and_simulate_keeps_time(tmp_path, record):
    u, y = record
    path = tmp_path / "r.csv"
    t = np.arange(u.size) * 0.01
    write_table(path, ["t", "u", "y"], np.column_stack([t, u, y]))
    model_file = tmp_path / "m.json"
    assert _run("identify", path, "-u", "u", "-y", "y", "--dt", "0.01", "--save", model_file)
    ok = _run("compare", model_file, path, "-u", "u", "-y", "y", "--time", "t")
    assert ok.exit_code == 0, ok.output
    bad = _run("compare", model_file, path, "-u", "u", "-y", "y", "--dt", "0.02")
    assert bad.exit_code == 1 and "identified at dt = 0.01 s" in bad.output
    sim = _run("simulate", model_file, path, "-u", "u", "--time", "t", "--out", tmp_path / "s.csv")
    assert sim.exit_code == 0, sim.output
    table = read_table(tmp_path / "s.csv")
    assert table.names[:2] == ["t", "u"]
    np.testing.assert_array_equal(table["t"], t)
    model = clpc.load_model(model_file)
    np.testing.assert_allclose(table["y_sim"], np.ravel(model.simulate(u)), rtol=1e-12)


def test_track_progress_into_a_pipe_is_plain_lines(tmp_path, record):
    u, y = record
    path = tmp_path / "r.csv"
    write_table(path, ["u", "y"], np.column_stack([u, y]))
    res = CliRunner().invoke(
        cli,
        [
            str(a)
            for a in (
                "track",
                path,
                "-u",
                "u",
                "-y",
                "y",
                "--window-size",
                "101",
                "--chunk-rows",
                "1000",
                "--progress",
                "--out",
                tmp_path / "o",
            )
        ],
    )
    assert res.exit_code == 0, res.output
    lines = [ln for ln in res.stderr.splitlines() if ln.startswith("tracking:")]
    assert lines == [
        "tracking: 1000 of 3000 rows (33%)",
        "tracking: 2000 of 3000 rows (67%)",
        "tracking: 3000 of 3000 rows (100%)",
    ]


def test_integrating_is_not_unstable():
    rng = np.random.default_rng(0)
    u = rng.standard_normal(3000)
    # voltage -> position: a pole at z = 1 and one at 0.7
    y = clpc.simulate_arx([1, -1.7, 0.7], [0, 0.1, 0.05], u) + 1e-3 * rng.standard_normal(3000)
    model = clpc.LPC(order=2, nk=1).fit(u, y, dt=0.01)
    assert np.min(np.abs(model.poles() - 1.0)) < 1e-3
    assert model.stability == "integrating" and not model.is_stable
    assert "integrating (pole at z = 1)" in repr(model)
    verdict = clpc.fit_verdict(model)
    assert verdict.stability == "integrating" and "NOT stable" not in str(verdict)
    assert "the model is integrating (pole at z = 1)" in str(verdict)
    from clpc.core.polynomials import pole_class

    assert pole_class(np.array([1.02, 0.5])) == "unstable"
    assert pole_class(np.array([-1.0, 0.5])) == "marginal"
    assert pole_class(np.array([0.99 + 0.0j, 0.5])) == "stable"
    assert pole_class(np.array([0.998, 0.5])) == "integrating"


def test_identify_na_nb(tmp_path, record):
    u, y = record
    path = tmp_path / "r.csv"
    write_table(path, ["u", "y"], np.column_stack([u, y]))
    res = _run(
        "identify", path, "-u", "u", "-y", "y", "--na", "2", "--nb", "1", "--nk", "1", "--json"
    )
    assert res.exit_code == 0, res.output
    ref = clpc.LPC(na=2, nb=1, nk=1).fit(u, y)
    assert '"na": 2, "nb": 1, "nk": 1' in res.output
    assert "MATLAB" in _run("identify", "--help").output
    assert ref.num.size == 3  # nk = 1 leading zero, then nb + 1 = 2 coefficients
    lpc = ("--estimator", "lpc", "--nk", "0")
    bad = _run("identify", path, "-u", "u", "-y", "y", "--order", "auto", "--na", "2", *lpc)
    assert bad.exit_code == 2 and "order auto" in bad.output


def test_compare_exits_1_when_the_response_diverges(tmp_path):
    rng = np.random.default_rng(5)
    u = rng.standard_normal(200)
    y = clpc.simulate_arx([1, -1.05], [0, 0.5], u)  # an unstable plant, short record
    model = clpc.ARX(order=1, nk=1).fit(u, y, dt=1.0)
    assert model.stability == "unstable"
    model_file = tmp_path / "m.json"
    clpc.save_model(model, model_file)
    long_u = rng.standard_normal(20000)
    path = tmp_path / "long.csv"
    write_table(path, ["u", "y"], np.column_stack([long_u, long_u]))
    res = _run("compare", model_file, path, "-u", "u", "-y", "y")
    assert res.exit_code == 1
    assert "n/a (diverges)" in res.stdout and "diverges on this record" in res.stderr
