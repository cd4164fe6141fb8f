"""The command line: in-process (click's CliRunner) and real subprocesses."""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import math
import os
import select
import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner
from scipy import signal

import clpc
import clpc.datasets as ds
import clpc.workflows as wf
from clpc.cli import cli
from clpc.io import read_table, write_table
from clpc.io.model_files import load_model
from clpc.report import model_response, update_records

DRYER = str(ds.path("dryer"))


def run(*args: str, input: str | None = None):
    return CliRunner().invoke(cli, [str(a) for a in args], input=input)


def ok(*args: str, input: str | None = None):
    result = run(*args, input=input)
    assert result.exit_code == 0, result.output
    return result


def fails(code: int, *args: str, input: str | None = None):
    result = run(*args, input=input)
    assert result.exit_code == code, result.output
    assert "Traceback" not in result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)
    return result


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    """A noisy order-2 SISO record with a time column: (path, u, y, dt)."""
    rng = np.random.default_rng(7)
    n, dt = 900, 0.01
    u = rng.standard_normal(n)
    y = signal.lfilter([0.5, 1.0, 0.3], [1.0, -1.5, 0.7], u) + 0.01 * rng.standard_normal(n)
    path = tmp_path_factory.mktemp("rec") / "rec.csv"
    write_table(path, ["t", "u", "y"], np.column_stack([np.arange(n) * dt, u, y]))
    return str(path), u, y, dt


# ================================================================= help and version
def test_help_and_version():
    assert "identify" in ok("--help").output
    assert clpc.__version__ in ok("--version").output
    for cmd in ("identify", "track", "stream", "simulate", "compare", "demo", "datasets"):
        assert "Example" in ok(cmd, "--help").output, cmd


def test_datasets_lists_paths():
    out = ok("datasets").output
    for name in ("robot_arm", "dryer", "ballbeam", "cd_player_arm", "cascaded_tanks"):
        assert name in out
    rows = json.loads(ok("datasets", "--json").stdout)["datasets"]
    assert all(os.path.exists(r["path"]) for r in rows)
    tanks = next(r for r in rows if r["name"] == "cascaded_tanks")
    assert tanks["validation_inputs"] == ["uVal"]


# ================================================================= identify
def test_identify_text_on_shipped_record():
    args = ("--estimator", "lpc", "--order", "2", "--nk", "0")
    out = ok("identify", DRYER, "--input", "u", "--output", "y", "--dt", "0.08", *args).output
    for word in (
        "den(z) = 1 -",
        "poles:",
        "stable",
        "D = lambda_max",
        "verdict:",
        "simulation",
        "1-step prediction",
        "10-step prediction",
    ):
        assert word in out, word


def test_identify_json_matches_library():
    args = ("--estimator", "lpc", "--order", "3", "--nk", "0", "--json", "--dt", "0.08")
    res = ok("identify", DRYER, "-u", "u", "-y", "y", *args)
    s = json.loads(res.stdout)
    data = ds.load("dryer")
    model = clpc.LPC(order=3).fit(data)
    eq = s["equations"][0]
    np.testing.assert_allclose(eq["den"], model.den, rtol=1e-12)
    np.testing.assert_allclose(eq["num"]["u"], model.num, rtol=1e-12)
    assert eq["D"] == pytest.approx(model.info["D"])
    assert eq["determined"] == model.info["determined"]
    assert s["fit"]["prediction_10"][0] == pytest.approx(
        clpc.kstep_fit(model, data.u[:, 0], data.y[:, 0], k=10)
    )
    assert s["dt"] == 0.08 and s["structure"] == {"na": 3, "nb": 3, "nk": 0}


def test_identify_auto_order(record):
    path, *_ = record
    s = json.loads(
        ok(
            "identify",
            path,
            "-u",
            "u",
            "-y",
            "y",
            "--estimator",
            "lpc",
            "--nk",
            "0",
            "--order",
            "auto",
            "--max-order",
            "4",
            "--time",
            "t",
            "--json",
        ).stdout
    )
    sel = clpc.select_order(
        clpc.io.load_iodata(path, "u", "y"), orders=range(1, 5), criterion="validation"
    )
    assert s["order_selection"]["best"] == sel.best == s["structure"]["na"]
    assert s["order_selection"]["orders"] == [1, 2, 3, 4]
    assert s["order_selection"]["criterion"] == "validation"
    assert s["dt"] == pytest.approx(0.01)
    lpc = ("--estimator", "lpc", "--nk", "0")
    out = ok("identify", path, "-u", "u", "-y", "y", "-n", "auto", *lpc).output
    assert "order selection (held-out score: mean of free-run and" in out
    bic = ("--criterion", "bic")
    out = ok("identify", path, "-u", "u", "-y", "y", "-n", "auto", *bic, *lpc).output
    assert "order selection (BIC, lower is better)" in out


def test_identify_mimo_and_column_indices():
    s = json.loads(
        ok(
            "identify",
            str(ds.path("cd_player_arm")),
            "-u",
            "u1",
            "-u",
            "u2",
            "-y",
            "y1",
            "-y",
            "y2",
            "--json",
        ).stdout
    )
    assert [e["output"] for e in s["equations"]] == ["y1", "y2"]
    assert set(s["equations"][0]["num"]) == {"u1", "u2"}
    by_index = json.loads(ok("identify", DRYER, "-u", "0", "-y", "1", "--json").stdout)
    assert by_index["inputs"] == ["u"] and by_index["outputs"] == ["y"]


def test_save_simulate_compare_round_trip(record, tmp_path):
    path, u, y, dt = record
    model_file = tmp_path / "m.json"
    lpc = ("--estimator", "lpc", "--order", "2", "--nk", "0")
    out = ok("identify", path, "-u", "u", "-y", "y", "--dt", dt, "--save", model_file, *lpc).output
    assert f"model saved to {model_file}" in out
    model = clpc.LPC(order=2).fit(u, y, dt)
    loaded = load_model(model_file)
    np.testing.assert_array_equal(loaded.theta, model.theta)
    # simulate: to a file, and to stdout
    sim_file = tmp_path / "sim.csv"
    ok("simulate", model_file, path, "--input", "u", "--out", sim_file)
    table = read_table(sim_file)
    assert table.names == ["u", "y_sim"]
    np.testing.assert_allclose(table["y_sim"], model.simulate(u), rtol=1e-12, atol=1e-12)
    lines = ok("simulate", model_file, path).stdout.splitlines()  # default: the model's names
    assert lines[0] == "u,y_sim" and len(lines) == len(u) + 1
    assert float(lines[-1].split(",")[1]) == pytest.approx(table["y_sim"][-1])
    # compare: free run and k-step, text, JSON and plot
    res = json.loads(ok("compare", model_file, path, "--json").stdout)
    _, _, fit = model_response(model, u, y)
    assert res["fit"]["y"] == pytest.approx(fit[0]) and res["compared"] == "simulation"
    res = json.loads(
        ok("compare", model_file, path, "-u", "u", "-y", "y", "--k", "5", "--json").output
    )
    assert res["fit"]["y"] == pytest.approx(clpc.kstep_fit(model, u, y, k=5))
    if importlib.util.find_spec("matplotlib") is None:
        return
    png = tmp_path / "cmp.png"
    out = ok("compare", model_file, path, "--k", "1", "--plot", png, "--time", "t").output
    assert "fit of 1-step prediction, y:" in out and png.read_bytes()[:4] == b"\x89PNG"


def test_cascaded_tanks_estimation_then_validation(tmp_path):
    tanks = str(ds.path("cascaded_tanks"))
    model_file = tmp_path / "tanks.json"
    ok("identify", tanks, "-u", "uEst", "-y", "yEst", "--dt", "4", "--save", model_file)
    out = ok("compare", model_file, tanks, "-u", "uVal", "-y", "yVal").output
    assert "fit of simulation, yVal:" in out


# ================================================================= track
def test_track_writes_trace_figures_report(record, tmp_path):
    pytest.importorskip("matplotlib")
    path, u, y, dt = record
    out_dir = tmp_path / "out"
    res = ok(
        "track",
        path,
        "-u",
        "u",
        "-y",
        "y",
        "--time",
        "t",
        "--window-size",
        "101",
        "--cluster-size",
        "10",
        "--chunk-rows",
        "97",
        "--nk",
        "1",  # b0 of the record is nonzero: the windows are mis-specified and untrusted,
        "--no-guard",  # so the paper's appraiser (no guard) is what produces a model here
        "--out",
        out_dir,
        "--save",
        tmp_path / "ss.json",
    )
    for name in ("trace.csv", "trace.png", "pz.png", "bode.png", "report.html"):
        assert (out_dir / name).stat().st_size > 0, name
    assert "updates:" in res.output and "wrote" in res.output
    ref = clpc.CLPC(order=2, window_size=101, cluster_size=10, dt=dt, nk=1, guard=False).run(
        u, y, dt
    )
    table = read_table(out_dir / "trace.csv")
    np.testing.assert_array_equal(table["index"], ref.index)
    np.testing.assert_allclose(table["time"], ref.time, rtol=1e-12)
    np.testing.assert_allclose(table["D"], ref.D, rtol=1e-9)
    for i, lab in enumerate(ref.labels()):
        np.testing.assert_allclose(table[lab], ref.theta[:, i], rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(table["accepted"], ref.accepted)
    assert load_model(tmp_path / "ss.json").n_inputs == 1
    html = (out_dir / "report.html").read_text()
    assert "data:image/png;base64" in html and "Last 20 updates" in html


def test_track_parquet_progress_and_mimo(tmp_path):
    pytest.importorskip("matplotlib")
    pytest.importorskip("pyarrow")
    res = ok(
        "track",
        str(ds.path("cd_player_arm")),
        "-u",
        "u1",
        "-u",
        "u2",
        "-y",
        "y1",
        "-y",
        "y2",
        "--window-size",
        "101",
        "--out",
        tmp_path,
        "--format",
        "parquet",
        "--progress",
    )
    assert "tracking" in res.stderr
    table = read_table(tmp_path / "trace.parquet")
    assert "y1:D" in table.names and "y2:b2_u2" in table.names


def test_track_errors(record, tmp_path):
    path, *_ = record
    r = fails(1, "track", path, "-u", "u", "-y", "y", "--window-size", "5000", "--out", tmp_path)
    assert "too short for the window" in r.output and "needs at least 5002" in r.output
    bad_time = tmp_path / "bad_time.csv"
    write_table(bad_time, ["t", "u", "y"], [[0, 1, 2], [0.1, 2, 3], [0.25, 3, 4], [0.35, 1, 1]])
    r = fails(1, "track", bad_time, "-u", "u", "-y", "y", "--time", "t", "--out", tmp_path)
    assert "not uniformly" in r.output
    fails(2, "track", path, "-u", "u", "-y", "y", "--out", tmp_path, "--dt", "1", "--time", "t")
    fails(2, "track", path, "-u", "u", "-y", "y", "--out", tmp_path, "--window-size", "1")
    fails(2, "track", path, "-u", "u", "-y", "y")  # --out missing


# ================================================================= stream
def _stream_lines(u, y, bad: dict[int, str]) -> tuple[str, list[int]]:
    """CSV lines of (u, y) with malformed lines inserted before sample k (bad[k])."""
    lines, bad_line_numbers = ["u,y"], []
    for k, (a, b) in enumerate(zip(u, y, strict=True)):
        if k in bad:
            lines.append(bad[k])
            if bad[k].strip() and not bad[k].startswith("#"):
                bad_line_numbers.append(len(lines))
        lines.append(f"{float(a)!r},{float(b)!r}")
    return "\n".join(lines) + "\n", bad_line_numbers


def _assert_same_updates(got: list[dict], want: list[dict]) -> None:
    assert len(got) == len(want)
    for g, w in zip(got, want, strict=True):
        assert g.keys() == w.keys()
        for key, wv in w.items():
            gv = g[key]
            if isinstance(wv, bool) or isinstance(wv, int) or wv is None:
                assert gv == wv, key
            else:
                np.testing.assert_allclose(gv, wv, rtol=1e-9, atol=1e-12, err_msg=key)


BAD = {5: "abc,1", 40: "1,2,3", 41: "", 77: "nan,2", 90: "# a comment", 130: "1;2", 200: '{"u": 1}'}


def test_stream_in_process_skips_malformed_lines(record):
    _, u, y, _ = record
    u, y = u[:300], y[:300]
    text, bad_lines = _stream_lines(u, y, BAD)
    res = ok("stream", "--window-size", "51", "--cluster-size", "7", input=text)
    got = [json.loads(line) for line in res.stdout.splitlines()]
    _assert_same_updates(
        got, update_records(clpc.CLPC(order=2, window_size=51, cluster_size=7).run(u, y))
    )
    for no in bad_lines:
        assert f"line {no}:" in res.stderr
    assert f"{len(bad_lines)} malformed line(s) skipped" in res.stderr


def test_stream_stop_on_error(record):
    _, u, y, _ = record
    text, bad_lines = _stream_lines(u[:100], y[:100], {60: "1,x"})
    res = fails(
        1, "stream", "--window-size", "20", "--cluster-size", "5", "--on-error", "stop", input=text
    )
    assert f"line {bad_lines[0]}: field 2 'x' is not a number" in res.stderr
    # the updates before the bad line were written
    assert len(res.stdout.splitlines()) == len(
        clpc.CLPC(order=2, window_size=20, cluster_size=5).run(u[:60], y[:60])
    )


def test_stream_jsonl_mimo_and_sample_time(rng):
    u = rng.standard_normal((200, 2))
    y = np.column_stack(
        [signal.lfilter([0, 1.0], [1, -0.5], u[:, 0]), signal.lfilter([0, 0.5], [1, -0.3], u[:, 1])]
    )
    text = "\n".join(
        json.dumps({"u": a.tolist(), "y": b.tolist()}) for a, b in zip(u, y, strict=True)
    )
    text += '\n{"u": [1, 2], "y": 3}\nnot json\n'
    res = ok(
        "stream",
        "--format",
        "jsonl",
        "--inputs",
        "2",
        "--outputs",
        "2",
        "--window-size",
        "40",
        "--cluster-size",
        "10",
        "--dt",
        "0.5",
        "--nk",
        "1",
        input=text,
    )
    got = [json.loads(line) for line in res.stdout.splitlines()]
    want = update_records(
        clpc.CLPC(order=2, window_size=40, cluster_size=10, dt=0.5, nk=1).run(u, y, 0.5)
    )
    _assert_same_updates(got, want)
    assert got[0]["time"] == pytest.approx(0.5 * got[0]["index"])
    assert "line 201: 'y' must be a list of 2 numbers" in res.stderr
    assert "line 202: not valid JSON" in res.stderr


def test_stream_through_a_real_pipe(record):
    """Lines written to a pipe come back as updates at once; nothing valid is lost."""
    _, u, y, _ = record
    text, bad_lines = _stream_lines(u, y, BAD)
    lines = text.splitlines(keepends=True)
    cmd = [sys.executable, "-m", "clpc", "stream", "--window-size", "51", "--cluster-size", "7"]
    proc = subprocess.Popen(
        cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, bufsize=0
    )
    try:
        first = 30  # header + 1 bad line + 28 samples: 26 lag vectors, 3 updates (C = 7)
        proc.stdin.write("".join(lines[:first]).encode())
        early = b""
        while early.count(b"\n") < 3:  # unbuffered reads: nothing is held back
            ready, _, _ = select.select([proc.stdout], [], [], 30)
            assert ready, "no update came back while standard input was still open"
            chunk = os.read(proc.stdout.fileno(), 1 << 16)
            assert chunk, "stream ended early"
            early += chunk
        out_b, err_b = proc.communicate("".join(lines[first:]).encode(), timeout=60)
    finally:
        proc.kill()
    out, err = (early + out_b).decode(), err_b.decode()
    assert len(early.splitlines()) == 3  # the updates of the first lines, before EOF
    assert proc.returncode == 0, err
    got = [json.loads(line) for line in out.splitlines()]
    _assert_same_updates(
        got, update_records(clpc.CLPC(order=2, window_size=51, cluster_size=7).run(u, y))
    )
    for no in bad_lines:
        assert f"line {no}:" in err
    assert "Traceback" not in err


def test_identify_in_a_subprocess():
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "clpc",
            "identify",
            DRYER,
            "--input",
            "u",
            "--output",
            "y",
            "--dt",
            "0.08",
        ],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert "poles:" in proc.stdout and "fit:" in proc.stdout
    proc = subprocess.run(
        [sys.executable, "-m", "clpc", "identify", "missing.csv", "-u", "u", "-y", "y"],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert proc.returncode == 1
    assert proc.stderr.startswith("Error: data file 'missing.csv' does not exist")
    assert "Traceback" not in proc.stderr


# ================================================================= error paths
def test_data_errors_exit_1_with_one_line(tmp_path, record):
    path, *_ = record
    r = fails(1, "identify", tmp_path / "nope.csv", "-u", "u", "-y", "y")
    assert "does not exist" in r.output
    r = fails(1, "identify", path, "-u", "u", "-y", "speed")
    assert "unknown column 'speed'" in r.output and "['t', 'u', 'y']" in r.output
    text = tmp_path / "text.csv"
    text.write_text("u,y\n1,2\n2,abc\n3,4\n")
    r = fails(1, "identify", text, "-u", "u", "-y", "y")
    assert "line 3, column 'y': 'abc' is not a number" in r.output
    nan = tmp_path / "nan.csv"
    nan.write_text("u,y\n1,2\n2,nan\n3,4\n")
    assert "not a finite number" in fails(1, "identify", nan, "-u", "u", "-y", "y").output
    short = tmp_path / "short.csv"
    short.write_text("u,y\n1,2\n2,3\n3,5\n4,1\n")
    assert "needs at least" in fails(1, "identify", short, "-u", "u", "-y", "y").output
    flat = tmp_path / "flat.csv"
    write_table(flat, ["u", "y"], np.column_stack([np.ones(50), np.arange(50.0)]))
    assert "nothing to identify" in fails(1, "identify", flat, "-u", "u", "-y", "y").output
    bad_model = tmp_path / "bad.json"
    bad_model.write_text("{not json")
    assert "not valid JSON" in fails(1, "simulate", bad_model, path).output
    assert "does not exist" in fails(1, "compare", tmp_path / "no.json", path).output
    for r in (fails(1, "identify", path, "-u", "u", "-y", "speed"),):
        assert len(r.output.strip().splitlines()) == 1


def test_usage_errors_exit_2(record, tmp_path):
    path, *_ = record
    assert (
        "must be an int >= 1 or 'auto'"
        in fails(2, "identify", path, "-u", "u", "-y", "y", "--order", "0").output
    )
    fails(2, "identify", path, "-u", "u", "-y", "y", "--order", "two")
    fails(2, "identify", path, "-u", "u", "-y", "y", "--dt", "-1")
    fails(2, "identify", path, "-u", "u", "-y", "y", "--method", "magic")
    fails(2, "identify", path, "-u", "u")  # --output missing
    r = fails(2, "identify", path, "-u", "u", "-y", "y", "--dt", "0.01", "--time", "t")
    assert "either --dt or --time" in r.output
    fails(2, "stream", "--cluster-size", "0")
    fails(2, "stream", "--format", "xml")
    fails(2, "nonsense")
    model_file = tmp_path / "m.json"
    ok("identify", path, "-u", "u", "-y", "y", "--save", model_file)
    r = fails(2, "compare", model_file, path, "-u", "u", "-u", "t", "-y", "y")
    assert "the model has 1 input(s) ['u']" in r.output
    fails(2, "compare", model_file, path, "--k", "0")


# ================================================================= demo
def test_demo_reports_missing_experiment(monkeypatch, tmp_path):
    for name in ("clpc_paper", "clpc_paper.demo"):
        monkeypatch.setitem(sys.modules, name, None)  # import now fails
    r = fails(1, "demo", "--out", tmp_path)
    assert "needs clpc_paper" in r.output


def test_demo_quick(tmp_path):
    if importlib.util.find_spec("clpc_paper.experiment") is None:
        pytest.skip("clpc_paper.experiment (the motor experiment) is not in this tree yet")
    res = ok("demo", "--out", tmp_path, "--quick", "--duration", "3")
    assert "motor experiment finished" in res.output
    assert (tmp_path / "summary.json").exists()
    assert "report.html" in res.output and (tmp_path / "report.html").exists()
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert math.isfinite(summary["runtime_s"])


def test_claim_text():
    from clpc.cli.info import _claim_text

    claim = {
        "id": "D",
        "paper": "D rises",
        "ramp": {"verdict": "partly"},
        "rich": {"verdict": "reproduced"},
    }
    assert _claim_text(claim) == "D rises [ramp: partly; rich: reproduced]"
    assert _claim_text("plain") == "plain"


# ================================================================= workflows (no click)
def test_workflows_without_the_command_line(record, tmp_path):
    path, u, _, dt = record
    rec = wf.RecordSpec(path, ("u",), ("y",), time_col="t")
    model_file = str(tmp_path / "m.json")
    settings = wf.IdentifySettings(
        rec, estimator="lpc", nk=0, order="auto", max_order=3, save=model_file
    )
    res = wf.identify_file(settings)
    assert res.selection is not None and res.summary["saved"] == model_file
    assert len(res.scores()) == 3 and res.summary["dt"] == pytest.approx(dt)
    cmp = wf.compare_file(wf.CompareSettings(model_file, wf.RecordSpec(path, time_col="t"), k=1))
    assert cmp.compared == "1-step prediction" and cmp.fit["y"] > 90
    assert "plot" not in cmp.to_dict()
    sim = wf.simulate_file(model_file, path)
    assert sim.names == ["u", "y_sim"] and sim.values.shape == (len(u), 2)
    with pytest.raises(wf.ChannelCountError, match="the model has 1 input"):
        wf.simulate_file(model_file, path, ("u", "y"))
    with pytest.raises(wf.SamplingConflictError):
        wf.RecordSpec(path, ("u",), ("y",), dt=dt, time_col="t").load()
    with pytest.raises(ValueError, match="window_size must be an int"):
        wf.AppraiserSettings(window_size=1)
    with pytest.raises(ValueError, match="order must be an int"):
        wf.IdentifySettings(rec, order=0)


def test_stream_samples_matches_a_batch_run(record):
    _, u, y, _ = record
    text, bad_lines = _stream_lines(u[:200], y[:200], {10: "1,x"})
    lines = text.splitlines()
    settings = wf.StreamSettings(wf.AppraiserSettings(window_size=40, cluster_size=9))
    batches = list(wf.stream_samples([lines[:50], lines[50:]], settings))
    records = [r for b in batches for r in b.records]
    _assert_same_updates(
        records,
        update_records(clpc.CLPC(order=2, window_size=40, cluster_size=9).run(u[:200], y[:200])),
    )
    assert [m.split(":")[0] for b in batches for m in b.skipped] == [f"line {bad_lines[0]}"]
    stop = dataclasses.replace(settings, on_error="stop")
    with pytest.raises(clpc.DataError, match="field 2 'x' is not a number"):
        list(wf.stream_samples([lines], stop))


def test_closed_pipe_ends_quietly(record, tmp_path):
    """`clpc simulate ... | head -1`: no traceback when the reader goes away."""
    path, u, _, _ = record
    model_file = tmp_path / "m.json"
    ok("identify", path, "-u", "u", "-y", "y", "--save", model_file)
    big = tmp_path / "big.csv"
    write_table(big, ["u"], np.tile(u, 30))  # ~1 MB of simulated output, more than a pipe holds
    proc = subprocess.Popen(
        [sys.executable, "-m", "clpc", "simulate", model_file, big],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert proc.stdout.readline() == b"u,y_sim\n"
    proc.stdout.close()
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 1
    assert "Traceback" not in err and "Error" not in err


def test_stream_jsonl_survives_huge_numbers_and_deep_nesting(record):
    _, u, y, _ = record
    u, y = u[:200], y[:200]
    lines = [json.dumps({"u": float(a), "y": float(b)}) for a, b in zip(u, y, strict=True)]
    lines.insert(50, '{"u": 1' + "0" * 400 + ', "y": 1}')  # an int no float can hold
    lines.insert(120, "[" * 100_000)  # deeper than the JSON parser recurses
    res = ok(
        "stream",
        "--format",
        "jsonl",
        "--window-size",
        "51",
        "--cluster-size",
        "7",
        input="\n".join(lines),
    )
    got = [json.loads(line) for line in res.stdout.splitlines()]
    _assert_same_updates(
        got, update_records(clpc.CLPC(order=2, window_size=51, cluster_size=7).run(u, y))
    )
    assert "line 51: 'u' holds a number too large for a float" in res.stderr
    assert "line 121: not a sample: JSON nested too deeply" in res.stderr
