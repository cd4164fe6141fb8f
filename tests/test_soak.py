"""Soak test: a long stream with bad lines mixed in, through ``clpc stream`` in a real process.

The child's update count and last parameters must equal :meth:`clpc.CLPC.run` on the valid
samples, every bad line must be reported, and the child's resident memory must stay flat.
``CLPC_SOAK_LINES`` sets the length (default 1e6 lines for CI; run it once with 1e7 by hand,
see ``docs/inputs.md``).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import clpc

LINES = int(os.environ.get("CLPC_SOAK_LINES", 1_000_000))
BAD = [
    "1_5,2",
    "\u0661,2",
    "1" + "0" * 400 + ",1",
    "x,y",
    "1,2,3",
    "nan,1",
    "[" * 5000,
    "",
    "# a comment",
]
EVERY = 997  # one bad line after every EVERY samples


def _rss_kib(pid: int) -> int:
    with open(f"/proc/{pid}/status") as fh:
        for line in fh:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


@pytest.mark.slow
@pytest.mark.skipif(not os.path.exists("/proc/self/status"), reason="needs /proc for RSS")
def test_long_stream_with_bad_lines_matches_a_batch_run_in_flat_memory():
    rng = np.random.default_rng(2024)
    n = LINES
    u = rng.standard_normal(n)
    y = clpc.simulate_arx(np.array([1.0, -1.5, 0.7]), np.array([0.2, 0.5, 0.1]), u)
    y += 0.01 * rng.standard_normal(n)
    proc = subprocess.Popen(
        [sys.executable, "-m", "clpc", "stream", "--window-size", "201", "--cluster-size", "12"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    reported = []

    ul, yl = u.tolist(), y.tolist()

    def feed():
        block = 50_000
        for lo in range(0, n, block):
            parts = []
            for k in range(lo, min(lo + block, n)):
                if k and k % EVERY == 0:
                    parts.append(BAD[(k // EVERY) % len(BAD)] + "\n")
                parts.append(f"{ul[k]!r},{yl[k]!r}\n")
            proc.stdin.write("".join(parts).encode())
        proc.stdin.close()

    def drain_err():
        for line in proc.stderr:
            if b"(skipped)" in line:
                reported.append(line)

    rss = []

    def watch():
        while proc.poll() is None:
            try:
                rss.append(_rss_kib(proc.pid))
            except OSError:
                break
            time.sleep(0.2)

    threads = [threading.Thread(target=f, daemon=True) for f in (feed, drain_err, watch)]
    for t in threads:
        t.start()
    count, last = 0, None
    for line in proc.stdout:
        count += 1
        last = line
    proc.wait(timeout=600)
    for t in threads:
        t.join(timeout=60)
    assert proc.returncode == 0
    ref = clpc.CLPC(order=2, window_size=201, cluster_size=12).run(u, y)
    assert count == len(ref)
    got = json.loads(last)
    np.testing.assert_array_equal(np.asarray(got["theta"]), ref.theta[-1])
    assert got["index"] == ref.index[-1]
    n_bad = sum(
        1
        for k in range(1, n)
        if k % EVERY == 0
        and BAD[(k // EVERY) % len(BAD)].strip()
        and not BAD[(k // EVERY) % len(BAD)].startswith("#")
    )
    assert len(reported) == n_bad
    # flat memory: after the first fifth of the run the child's RSS grows by less than 25 MB
    assert len(rss) >= 5, rss
    settled = rss[len(rss) // 5 :]
    growth_mib = (max(settled) - settled[0]) / 1024
    print(
        f"\nsoak: {n} lines, {len(ref)} updates, {n_bad} bad lines, RSS {settled[0] / 1024:.0f}"
        f" -> {max(settled) / 1024:.0f} MiB (growth {growth_mib:.1f} MiB)"
    )
    assert growth_mib < 25, rss
