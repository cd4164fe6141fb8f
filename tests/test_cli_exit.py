"""The process entry (``python -m clpc``, the ``clpc`` script) ends like any Python program:
its exit codes, and its output flushed to the last line through a pipe."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest


def _clpc(args: list[str], *, stdin: str | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "clpc", *args],
        input=stdin,
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.fixture(scope="module")
def samples() -> str:
    rng = np.random.default_rng(0)
    u = rng.standard_normal(6000)
    y = np.convolve(u, [0.0, 0.5, 0.2])[:6000]
    return "u,y\n" + "".join(f"{a:.6g},{b:.6g}\n" for a, b in zip(u, y, strict=True))


@pytest.mark.parametrize(
    ("args", "code", "where"),
    [
        (["datasets"], 0, "stdout"),
        (["identify", "no-such-file.csv", "-u", "u", "-y", "y"], 1, "stderr"),
        (["identify", "--no-such-option"], 2, "stderr"),
    ],
)
def test_exit_codes_and_messages(args, code, where):
    done = _clpc(args)
    assert done.returncode == code
    assert getattr(done, where).strip()


def test_every_line_of_a_long_output_arrives_through_a_pipe(samples):
    args = ["stream", "--order", "1", "--window-size", "50", "--cluster-size", "5"]
    done = _clpc(args, stdin=samples)
    assert done.returncode == 0
    lines = done.stdout.splitlines()
    assert len(lines) > 1000  # one JSON line per update
    assert lines[-1].startswith("{") and lines[-1].endswith("}")
