"""Hostile and careless input to ``clpc track`` and ``clpc stream`` (issue 15)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading

import numpy as np
import pytest
from click.testing import CliRunner
from scipy import signal

import clpc
from clpc.cli import cli
from clpc.io import write_table
from clpc.report import update_records


def run(*args, input=None):
    return CliRunner().invoke(cli, [str(a) for a in args], input=input)


def code(expected, *args, input=None):
    res = run(*args, input=input)
    assert res.exit_code == expected, res.output
    assert "Traceback" not in res.output
    assert res.exception is None or isinstance(res.exception, SystemExit)
    return res


@pytest.fixture(scope="module")
def sig():
    rng = np.random.default_rng(5)
    n = 600
    u = rng.standard_normal(n)
    y = signal.lfilter([0.0, 1.0, 0.3], [1.0, -1.5, 0.7], u) + 0.01 * rng.standard_normal(n)
    return u, y


def _csv(u, y):
    return "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(u, y, strict=True))


def _same(got, want):
    assert [g["index"] for g in got] == [w["index"] for w in want]
    for g, w in zip(got, want, strict=True):
        np.testing.assert_allclose(g["theta"], w["theta"], rtol=1e-9, atol=1e-12)
        assert g["accepted"] == w["accepted"]


# ------------------------------------------------------------------ track
def test_track_save_with_nothing_accepted_fails(tmp_path):
    n = 400
    path = tmp_path / "flat.csv"
    write_table(path, ["u", "y"], np.column_stack([np.ones(n), np.ones(n)]))
    res = code(
        1,
        "track",
        path,
        "-u",
        "u",
        "-y",
        "y",
        "--window-size",
        "51",
        "--out",
        tmp_path / "o",
        "--save",
        tmp_path / "m.json",
    )
    assert "no update was accepted" in res.output
    assert not (tmp_path / "m.json").exists()


def test_track_sample_time_without_data_sample_time_is_refused(tmp_path, sig):
    u, y = sig
    path = tmp_path / "r.csv"
    write_table(path, ["u", "y"], np.column_stack([u, y]))
    res = code(2, "track", path, "-u", "u", "-y", "y", "--decimate-to", "0.03", "--out", tmp_path)
    assert "--dt" in res.output and "--decimate-to" in res.output


def test_track_window_too_small_fails(tmp_path, sig):
    u, y = sig
    path = tmp_path / "r.csv"
    write_table(path, ["u", "y"], np.column_stack([u, y]))
    res = run("track", path, "-u", "u", "-y", "y", "--window-size", "3", "--out", tmp_path)
    assert res.exit_code != 0 and "cannot hold" in res.output


# ------------------------------------------------------------------ stream: exit status
def test_stream_without_a_valid_sample_exits_nonzero():
    res = code(1, "stream", input="x,1\n1,2,3\n{}\n")
    assert "no valid sample" in res.output
    code(1, "stream", input="")
    res = code(1, "stream", "--format", "jsonl", input='{"u": 1}\nnope\n')
    assert "no valid sample" in res.output


def test_stream_window_too_small_fails():
    res = run("stream", "--window-size", "3", input="1,2\n3,4\n")
    assert res.exit_code != 0 and "cannot hold" in res.output


def test_stream_sample_time_without_dt_is_refused(sig):
    u, y = sig
    res = code(2, "stream", "--decimate-to", "0.03", input=_csv(u, y))
    assert "--dt" in res.output


# ------------------------------------------------------------------ stream: malformed lines
BAD_CSV = [
    "1_5,2",  # underscores
    "\u0661\u0662,3",  # Arabic-Indic digits
    "\uff11,2",  # full-width digit
    "1" + "0" * 400 + ",1",  # overflows to inf
    "nan,1",
    "0x10,1",
    "1,2,3",
    "1;2",
    "true,1",
    "[" * 100000,
]
BAD_JSONL = [
    '{"u": 1' + "0" * 400 + ', "y": 1}',
    "[" * 100000,
    '{"u": "1", "y": 2}',
    '{"u": true, "y": 2}',
    '{"u": null, "y": 2}',
    '{"u": [1, 2], "y": 2}',
    '{"u": {"a": 1}, "y": 2}',
    '{"u": NaN, "y": 2}',
    '{"u": Infinity, "y": 2}',
    '{"u": 1e999, "y": 2}',
    '"u"',
    "[1, 2]",
    '{"u": 1_5, "y": 2}',
    '{"u": \u0661, "y": 2}',
]


@pytest.mark.parametrize(("fmt", "bad"), [("csv", BAD_CSV), ("jsonl", BAD_JSONL)])
def test_stream_skips_every_malformed_line_and_keeps_the_rest(sig, fmt, bad):
    u, y = sig
    good = (
        [f"{float(a)!r},{float(b)!r}" for a, b in zip(u, y, strict=True)]
        if fmt == "csv"
        else [json.dumps({"u": float(a), "y": float(b)}) for a, b in zip(u, y, strict=True)]
    )
    lines, bad_numbers = [], []
    step = len(good) // (len(bad) + 1)
    for k, line in enumerate(good):
        if k and k % step == 0 and k // step <= len(bad):
            lines.append(bad[k // step - 1])
            bad_numbers.append(len(lines))
        lines.append(line)
    res = code(
        0,
        "stream",
        "--format",
        fmt,
        "--window-size",
        "51",
        "--cluster-size",
        "7",
        input="\n".join(lines) + "\n",
    )
    got = [json.loads(x) for x in res.stdout.splitlines()]
    _same(got, update_records(clpc.CLPC(order=2, window_size=51, cluster_size=7).run(u, y)))
    for no in bad_numbers:
        assert f"line {no}:" in res.stderr, (no, res.stderr[-2000:])
    assert f"{len(bad)} malformed line(s) skipped" in res.stderr


# ------------------------------------------------------------------ stream: header detection
def test_stream_first_line_that_is_not_data_is_reported(sig):
    u, y = sig
    for first in ("hello", "a,b,c"):
        res = code(
            0,
            "stream",
            "--window-size",
            "51",
            "--cluster-size",
            "7",
            input=first + "\n" + _csv(u, y),
        )
        assert "line 1:" in res.stderr, res.stderr
        got = [json.loads(x) for x in res.stdout.splitlines()]
        _same(got, update_records(clpc.CLPC(order=2, window_size=51, cluster_size=7).run(u, y)))
    res = code(
        0, "stream", "--window-size", "51", "--cluster-size", "7", input="u,y\n" + _csv(u, y)
    )
    assert "header" in res.stderr and "u, y" in res.stderr


def test_stream_header_with_a_data_like_name_is_not_swallowed(sig):
    u, y = sig
    # "1e3" is a number: the first line is data, not a header
    res = code(
        0, "stream", "--window-size", "51", "--cluster-size", "7", input="1e3,2\n" + _csv(u, y)
    )
    got = [json.loads(x) for x in res.stdout.splitlines()]
    _same(
        got,
        update_records(
            clpc.CLPC(order=2, window_size=51, cluster_size=7).run(np.r_[1e3, u], np.r_[2, y])
        ),
    )
    assert "header" not in res.stderr


# ------------------------------------------------------------------ stream: column selection
def test_stream_selects_columns_by_name_and_index(sig):
    u, y = sig
    rows = "".join(
        f"{k},{float(b)!r},9,{float(a)!r}\n" for k, (a, b) in enumerate(zip(u, y, strict=True))
    )
    want = update_records(clpc.CLPC(order=2, window_size=51, cluster_size=7).run(u, y, 0.5))
    text = "t,pos,junk,volt\n" + "".join(
        f"{0.5 * k!r},{float(b)!r},9,{float(a)!r}\n"
        for k, (a, b) in enumerate(zip(u, y, strict=True))
    )
    res = code(
        0,
        "stream",
        "-u",
        "volt",
        "-y",
        "pos",
        "--time",
        "t",
        "--window-size",
        "51",
        "--cluster-size",
        "7",
        input=text,
    )
    _same([json.loads(x) for x in res.stdout.splitlines()], want)
    assert json.loads(res.stdout.splitlines()[0])["time"] == pytest.approx(
        0.5 * json.loads(res.stdout.splitlines()[0])["index"]
    )
    res = code(
        0, "stream", "-u", "3", "-y", "1", "--window-size", "51", "--cluster-size", "7", input=rows
    )
    _same(
        [json.loads(x) for x in res.stdout.splitlines()],
        update_records(clpc.CLPC(order=2, window_size=51, cluster_size=7).run(u, y)),
    )
    res = code(2, "stream", "-u", "nope", "-y", "pos", input=text)
    assert "nope" in res.output
    jl = "".join(
        json.dumps({"V": float(a), "x": float(b)}) + "\n" for a, b in zip(u, y, strict=True)
    )
    res = code(
        0,
        "stream",
        "--format",
        "jsonl",
        "-u",
        "V",
        "-y",
        "x",
        "--window-size",
        "51",
        "--cluster-size",
        "7",
        input=jl,
    )
    _same(
        [json.loads(x) for x in res.stdout.splitlines()],
        update_records(clpc.CLPC(order=2, window_size=51, cluster_size=7).run(u, y)),
    )


def test_stream_help_lists_only_accepted_options():
    import re

    from clpc.cli.stream import stream

    text = run("stream", "--help").output
    accepted = {o for p in stream.params for o in (*p.opts, *p.secondary_opts)}
    mentioned = {m for m in re.findall(r"(--[a-z][a-z-]+)", text) if not m.endswith("-")}
    assert mentioned - accepted - {"--help"} == set()
    assert "--time" in accepted


# ------------------------------------------------------------------ stream: a named pipe
@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs named pipes")
def test_stream_reads_a_named_pipe_without_loss(tmp_path, sig):
    u, y = sig
    fifo = tmp_path / "p"
    os.mkfifo(fifo)
    text = "u,y\n" + _csv(u, y)

    def feed():
        with open(fifo, "w") as fh:
            fh.write(text)

    t = threading.Thread(target=feed)
    t.start()
    with open(fifo) as src:
        proc = subprocess.run(
            [sys.executable, "-m", "clpc", "stream", "--window-size", "51", "--cluster-size", "7"],
            stdin=src,
            capture_output=True,
            text=True,
            timeout=120,
        )
    t.join()
    assert proc.returncode == 0, proc.stderr
    got = [json.loads(x) for x in proc.stdout.splitlines()]
    _same(got, update_records(clpc.CLPC(order=2, window_size=51, cluster_size=7).run(u, y)))


# ------------------------------------------------------------------ simulate / compare
@pytest.fixture
def unstable(tmp_path):
    from clpc.io import save_model
    from clpc.lpc.regressors import Structure
    from clpc.model import LinearModel

    model = LinearModel(np.array([[1.0, -2.5, 0.0, 1.0]]), Structure(1, 1), 1, "siso", [0.0])
    save_model(model, tmp_path / "unstable.json")
    u = np.random.default_rng(0).standard_normal(3000)
    write_table(tmp_path / "u.csv", ["u", "y"], np.column_stack([u, u]))
    return tmp_path


def test_simulate_of_an_unstable_model_writes_nothing(unstable):
    out = unstable / "sim.csv"
    res = code(
        1, "simulate", unstable / "unstable.json", unstable / "u.csv", "-u", "u", "--out", out
    )
    assert "diverges" in res.output and "2.5" in res.output and "sample" in res.output
    assert not out.exists()


@pytest.mark.filterwarnings("error")
def test_compare_with_a_horizon_longer_than_the_record(unstable):
    res = code(
        1,
        "compare",
        unstable / "unstable.json",
        unstable / "u.csv",
        "-u",
        "u",
        "-y",
        "y",
        "--k",
        "100000",
    )
    assert "--k 100000" in res.output and "3000 samples" in res.output
    res = code(
        0,
        "compare",
        unstable / "unstable.json",
        unstable / "u.csv",
        "-u",
        "u",
        "-y",
        "y",
        "--k",
        "50",
    )
    assert "fit of 50-step prediction" in res.output  # and no overflow warning (an error)
