"""``clpc stream`` in its environment: stop signals, closed pipes, cut lines (issue 28)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from click.testing import CliRunner

import clpc
from clpc.cli import cli

ARGS = ("--window-size", "51", "--cluster-size", "7")
posix = pytest.mark.skipif(os.name != "posix", reason="POSIX signals and pipes")


def _lines(n=900, seed=11):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = clpc.simulate_arx(np.array([1.0, -1.5, 0.7]), np.array([0.2, 0.5, 0.1]), u)
    y = y + 0.01 * rng.standard_normal(n)
    return [f"{a!r},{b!r}\n" for a, b in zip(u.tolist(), y.tolist(), strict=True)], u, y


def _child(*args):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    return subprocess.Popen(
        [sys.executable, "-m", "clpc", "stream", *ARGS, *map(str, args)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=env,
    )


@posix
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT, signal.SIGHUP])
def test_stop_signal_saves_the_state_and_resumes_bit_exactly(tmp_path, sig):
    """Formerly SIGINT exited 1 like a data error and nothing was saved."""
    lines, u, y = _lines()
    state = tmp_path / "s.json"
    proc = _child("--state", state)
    proc.stdin.write("".join(lines[:400]).encode())
    proc.stdin.flush()
    first = [proc.stdout.readline()]  # an update: the child is running and reading
    proc.send_signal(sig)
    out, err = proc.stdout.read(), proc.stderr.read()  # not communicate(): readline buffered
    assert proc.wait(timeout=60) == 128 + sig, err
    assert "Traceback" not in err.decode() and f"stopped by {signal.Signals(sig).name}" in (
        err.decode()
    )
    first += out.splitlines(keepends=True)
    seen = clpc.CLPC.load(str(state)).n_samples
    assert 0 < seen <= 400
    res = CliRunner().invoke(
        cli, ["stream", *ARGS, "--state", str(state)], input="".join(lines[seen:])
    )
    assert res.exit_code == 0, res.output
    got = [json.loads(x) for x in first] + [json.loads(x) for x in res.stdout.splitlines()]
    ref = clpc.CLPC(order=2, window_size=51, cluster_size=7).run(u, y)
    assert [g["index"] for g in got] == ref.index.tolist()
    np.testing.assert_array_equal(np.array([g["theta"] for g in got]), ref.theta)


@posix
def test_stop_signal_without_state_exits_with_its_code():
    lines, _, _ = _lines(100)
    proc = _child()
    proc.stdin.write("".join(lines).encode())
    proc.stdin.flush()
    assert proc.stdout.readline().startswith(b"{")  # running, its handlers set
    proc.send_signal(signal.SIGINT)
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 130
    assert err.strip().splitlines()[-1] == "clpc stream: stopped by SIGINT"


@posix
def test_reader_that_goes_away_ends_the_stream_quietly():
    """`clpc stream ... | head -1`: no traceback."""
    lines, _, _ = _lines(6000)
    text = "".join(lines)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    cmd = f"{sys.executable} -m clpc stream {' '.join(ARGS)} | head -1"
    res = subprocess.run(
        ["sh", "-c", cmd], input=text.encode(), capture_output=True, env=env, timeout=120
    )
    assert res.returncode == 0 and len(res.stdout.splitlines()) == 1
    assert b"Traceback" not in res.stderr and b"Error" not in res.stderr


@posix
@pytest.mark.parametrize(("redirect", "what"), [("<&-", "standard input"), (">&-", "output")])
def test_closed_standard_streams_give_one_line(redirect, what):
    """Formerly AttributeError tracebacks."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    cmd = f"{sys.executable} -m clpc stream --dt 0.1 {redirect}"
    res = subprocess.run(
        ["sh", "-c", cmd], input=b"1,2\n", capture_output=True, env=env, timeout=120
    )
    err = res.stderr.decode().strip().splitlines()
    assert res.returncode == 1 and len(err) == 1 and what in err[0], err


def test_cut_last_line_is_not_a_sample():
    """Formerly `0.5,0.2` cut from `0.5,0.25` at the end of the stream was taken as a sample."""
    lines, u, y = _lines(400)
    text = "".join(lines)[:-3]  # the last line cut short, without its newline
    res = CliRunner().invoke(cli, ["stream", *ARGS], input=text)
    assert res.exit_code == 0, res.output
    assert "line 400: the last line has no newline" in res.stderr
    got = [json.loads(x) for x in res.stdout.splitlines()]
    ref = clpc.CLPC(order=2, window_size=51, cluster_size=7).run(u[:399], y[:399])
    assert [g["index"] for g in got] == ref.index.tolist()


def test_column_index_past_the_header_is_one_line():
    """Formerly an IndexError traceback."""
    res = CliRunner().invoke(cli, ["stream", "-u", "0", "-y", "2"], input="u,y\n1,2\n3,4\n")
    assert res.exit_code == 2 and "Traceback" not in res.output
    assert "column index 2 is past the header's 2 columns" in res.output


def _piped(text: bytes, env: dict[str, str], *args: str) -> subprocess.CompletedProcess:
    """``clpc stream`` in a real process, ``text`` piped to its standard input."""
    full = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path), **env)
    return subprocess.run(
        [sys.executable, "-m", "clpc", "stream", *ARGS, *args],
        input=text,
        capture_output=True,
        env=full,
        timeout=120,
    )


@posix
@pytest.mark.parametrize("on_error", ["skip", "stop"])
def test_a_line_over_the_line_limit_ends_the_stream_with_one_line(tmp_path, on_error):
    """Issue 28: a line is bounded by CLPC_MAX_LINE_BYTES; one over it is refused, not skipped."""
    lines, u, y = _lines(600)
    a, b = u[399].item(), y[399].item()
    lines[399] = f"{a!r}," + " " * (1000 - len(f"{a!r},{b!r}")) + f"{b!r}\n"  # at the limit
    lines[450] = "1," + "0" * 999 + "\n"  # 1,001 bytes: just over
    state = tmp_path / "s.json"
    res = _piped(
        "".join(lines).encode(),
        {"CLPC_MAX_LINE_BYTES": "1000"},
        "--on-error",
        on_error,
        "--state",
        str(state),
    )
    err = res.stderr.decode().strip().splitlines()
    assert res.returncode == 1 and len(err) == 1, err
    assert err[0].startswith("Error: standard input line 451 is longer than the line limit")
    assert "1,000 bytes" in err[0] and "CLPC_MAX_LINE_BYTES" in err[0]
    assert "Traceback" not in res.stderr.decode()
    # the 450 lines before it, the one at the limit included, were used and saved
    got = [json.loads(x) for x in res.stdout.splitlines()]
    ref = clpc.CLPC(order=2, window_size=51, cluster_size=7).run(u[:450], y[:450])
    assert [g["index"] for g in got] == ref.index.tolist()
    np.testing.assert_array_equal(np.array([g["theta"] for g in got]), ref.theta)
    assert clpc.CLPC.load(str(state)).n_samples == 450


@posix
def test_a_64_mib_line_is_refused_at_the_default_limit_quickly():
    """Formerly the whole line was held and re-copied per block: 24.7 s for 64 MiB."""
    lines, _, _ = _lines(100)
    text = "".join(lines[:60]).encode() + b"1," + b"0" * (64 << 20) + b"\n"
    start = time.perf_counter()
    res = _piped(text, {})
    took = time.perf_counter() - start
    err = res.stderr.decode().strip().splitlines()
    assert res.returncode == 1 and len(err) == 1, err
    assert "standard input line 61 is longer than the line limit of 4,194,304 bytes" in err[0]
    assert took < 15, took


def test_a_line_just_over_a_lowered_limit_in_one_read(monkeypatch):
    """The limit also holds when the long line arrives within one block (no pipe)."""
    monkeypatch.setenv("CLPC_MAX_LINE_BYTES", "20")
    res = CliRunner().invoke(cli, ["stream", "--dt", "1"], input="1,2\n# " + "x" * 19 + "\n")
    assert res.exit_code == 1 and "Traceback" not in res.output
    assert "line 2 is longer than the line limit of 20 bytes" in res.output
    res = CliRunner().invoke(cli, ["stream", "--dt", "1"], input="1,2\n# " + "x" * 18 + "\n")
    assert res.exit_code == 0 and "line limit" not in res.output  # 20 bytes: allowed
