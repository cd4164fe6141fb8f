"""The process entry (``python -m clpc``, the ``clpc`` script) ends without the interpreter's
teardown: the same output, flushed to the last line, and the same exit codes as with it."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest


def _clpc(args: list[str], *, full: bool, stdin: str | None = None) -> subprocess.CompletedProcess:
    env = dict(os.environ, CLPC_FULL_EXIT="1" if full else "0")
    return subprocess.run(
        [sys.executable, "-m", "clpc", *args],
        input=stdin,
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )


@pytest.fixture(scope="module")
def samples() -> str:
    rng = np.random.default_rng(0)
    u = rng.standard_normal(6000)
    y = np.convolve(u, [0.0, 0.5, 0.2])[:6000]
    return "u,y\n" + "".join(f"{a:.6g},{b:.6g}\n" for a, b in zip(u, y, strict=True))


@pytest.mark.parametrize(
    ("args", "code"),
    [
        (["datasets"], 0),
        (["identify", "no-such-file.csv", "-u", "u", "-y", "y"], 1),
        (["identify", "--no-such-option"], 2),
    ],
)
def test_exit_codes_and_messages_are_those_of_a_full_exit(args, code):
    fast, full = _clpc(args, full=False), _clpc(args, full=True)
    assert fast.returncode == full.returncode == code
    assert fast.stdout == full.stdout
    assert fast.stderr == full.stderr


def test_every_line_of_a_long_output_arrives_through_a_pipe(samples):
    args = ["stream", "--order", "1", "--window", "50", "--cluster", "5"]
    fast = _clpc(args, full=False, stdin=samples)
    full = _clpc(args, full=True, stdin=samples)
    assert fast.returncode == full.returncode == 0
    assert len(fast.stdout.splitlines()) > 1000  # one JSON line per update
    assert fast.stdout == full.stdout
