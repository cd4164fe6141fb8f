"""Issue 26's table: the CLPC appraiser's speed in every configuration, in one run.

Run as ``python benchmarks/bench_clpc.py --table`` (or this file directly). Every row is
measured in this process on the same data as ``bench_clpc.py`` (white Gaussian ``u`` through
the 2nd-order ARX system, equation noise 0.1, measurement noise 0.02; a second independent
white input for the MISO row), ``W = 201``, compiled kernel (warmed up first, never timed
compiling), one BLAS thread.

Columns: ``us/window`` is process CPU time per update (best of ``--repeat``); ``ref`` the
plain per-window reference at the same settings (``reference`` below: build the window's lag
matrix, center it, form the scatter, ``numpy.linalg.eigh``), timed on a prefix of windows;
``vs ref`` = ref / clpc (> 1: clpc is faster). ``vs p^2``: the cost per window over ``p^2``
(how the cost grows with the parameter count). The peers refit a fixed-order ARX on every
window (what an engineer would do with them to follow a time-varying plant): SIPPY
(``sippy_unipi.system_identification(y, u, "ARX", ARX_orders=[2, 3, 0])``) and sysidentpy
(``FROLS`` with all 6 candidate terms of ``ylag=2``, ``xlag=3``, ``LeastSquares``), each timed
on ``--peer-windows`` windows in a subprocess of the peers' venv (``--peers-python``; they are
never clpc dependencies). Exactness: every ``method='paper'`` row is compared with the
reference on its timed prefix (largest eigenvalue and ``D`` relative, ``theta`` up to sign on
windows whose two smallest eigenvalues are separated, ``lambda_1 / lambda_2 < 0.1``).
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import subprocess
import sys
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from scipy import signal

DEN = np.array([1.0, -1.5, 0.7])
NUM = np.array([0.5, 0.3, 0.1])
WINDOW = 201
SEED = 20240607


def record(n: int, n_inputs: int = 1, seed: int = SEED) -> tuple[np.ndarray, np.ndarray]:
    """``u`` (n, n_inputs), ``y`` (n,): the benchmark process (input 2 enters through 0.3 B)."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((n, n_inputs))
    y = signal.lfilter(NUM, DEN, u[:, 0]) + signal.lfilter([1.0], DEN, 0.1 * rng.standard_normal(n))
    for i in range(1, n_inputs):
        y += signal.lfilter(0.3 * NUM, DEN, u[:, i])
    return u, y + 0.02 * rng.standard_normal(n)


def reference(
    u: np.ndarray, y: np.ndarray, order: int, cluster: int, n_windows: int
) -> tuple[np.ndarray, np.ndarray]:
    """Plain per-window LPC of the first ``n_windows`` updates: (theta, eigenvalues).

    Rows ``z_n = [y(n) .. y(n-N), u_1(n) .. u_1(n-N), ...]``; update ``j`` uses lag rows
    ``[max(0, C j - W), C j)``; theta is the smallest eigenvector with ``a0 >= 0``.
    """
    p = (order + 1) * (1 + u.shape[1])
    thetas, eigs = np.empty((n_windows, p)), np.empty((n_windows, p))
    for j in range(1, n_windows + 1):
        m = cluster * j
        lo, hi = max(0, m - WINDOW) + order, m + order
        cols = [y[lo - i : hi - i] for i in range(order + 1)]
        for k in range(u.shape[1]):
            cols += [u[lo - i : hi - i, k] for i in range(order + 1)]
        lag = np.column_stack(cols)
        centered = lag - lag.mean(axis=0)
        w, v = np.linalg.eigh(centered.T @ centered)
        thetas[j - 1] = v[:, 0] if v[0, 0] >= 0 else -v[:, 0]
        eigs[j - 1] = w
    return thetas, eigs


def cpu(fn: Callable[[], Any], repeat: int) -> float:
    """Best process CPU seconds of ``repeat`` calls (after one warm-up call)."""
    fn()
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def wall(fn: Callable[[], Any], repeat: int) -> float:
    """Best wall seconds of ``repeat`` calls (after one warm-up call)."""
    fn()
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def exactness(trace: Any, u: np.ndarray, y: np.ndarray, order: int, n_ref: int) -> str:
    """``method='paper'`` trace vs :func:`reference` on the first ``n_ref`` windows."""
    theta_ref, eig_ref = reference(u, y, order, 12, n_ref)
    eig = trace.arrays["eigenvalues"][:n_ref, 0]
    theta = trace.arrays["theta_estimate"][:n_ref, 0]
    usable = ~trace.not_enough_data[:n_ref]
    top = eig_ref[usable, -1]
    d_ref = eig_ref[usable, -1] - eig_ref[usable, 0]
    d = trace.arrays["D"][:n_ref, 0][usable]
    sep = usable & (eig_ref[:, 0] < 0.1 * eig_ref[:, 1])
    sign = np.sign(np.sum(theta[sep] * theta_ref[sep], axis=1))[:, None]
    dt = np.max(np.abs(theta[sep] * sign - theta_ref[sep])) if sep.any() else float("nan")
    return (
        f"lambda_max {np.max(np.abs(eig[usable, -1] - top) / top):.1e}, "
        f"D {np.max(np.abs(d - d_ref) / d_ref):.1e}, theta {dt:.1e} ({sep.sum()} of {n_ref})"
    )


# ================================================================ the peers (their own venv)
def peer_worker(spec: dict) -> dict:
    """Seconds per window of SIPPY's and sysidentpy's fixed-order ARX refits (CPU, best of 3)."""
    u, y = record(spec["n"])
    u = u[:, 0]
    count, cluster = spec["windows"], spec["cluster"]
    out: dict[str, Any] = {}
    try:
        from sippy_unipi import system_identification

        def sippy() -> None:
            with contextlib.redirect_stdout(io.StringIO()):
                for j in range(1, count + 1):
                    lo = max(0, cluster * j - WINDOW) + 20
                    system_identification(
                        y[lo : lo + WINDOW], u[lo : lo + WINDOW], "ARX", ARX_orders=[2, 3, 0]
                    )

        out["SIPPY ARX"] = cpu(sippy, 3) / count
    except Exception as exc:
        out["SIPPY ARX"] = f"{type(exc).__name__}: {exc}"
    try:
        from sysidentpy.basis_function import Polynomial
        from sysidentpy.model_structure_selection import FROLS
        from sysidentpy.parameter_estimation import LeastSquares

        def frols() -> None:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                for j in range(1, count + 1):
                    lo = max(0, cluster * j - WINDOW) + 20
                    model = FROLS(
                        order_selection=False,
                        n_terms=6,
                        ylag=2,
                        xlag=3,
                        estimator=LeastSquares(),
                        basis_function=Polynomial(degree=1),
                    )
                    model.fit(X=u[lo : lo + WINDOW, None], y=y[lo : lo + WINDOW, None])

        out["sysidentpy FROLS"] = cpu(frols, 3) / count
    except Exception as exc:
        out["sysidentpy FROLS"] = f"{type(exc).__name__}: {exc}"
    return out


def peers(python: str | None, windows: int) -> dict:
    """:func:`peer_worker` in a subprocess of ``python`` (its own venv); {} without one."""
    if not python:
        return {}
    spec = json.dumps({"n": 20 * windows + 500, "windows": windows, "cluster": 12})
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    env.pop("PYTHONPATH", None)  # the peers do not need clpc
    cmd = [python, str(Path(__file__)), "--peer-worker", spec]
    done = subprocess.run(cmd, capture_output=True, text=True, env=env, check=False)
    if done.returncode != 0:
        return {"error": done.stderr.strip().splitlines()[-1:] or ["failed"]}
    return json.loads(done.stdout.strip().splitlines()[-1])


# ================================================================ the table
def parallel_capacity() -> float:
    """Wall speed-up of two concurrent busy processes over one (2 = two free cores)."""
    code = "import time\nt0 = time.process_time()\nwhile time.process_time() - t0 < 0.4: pass\n"

    def run(k: int) -> float:
        t0 = time.perf_counter()
        procs = [subprocess.Popen([sys.executable, "-c", code]) for _ in range(k)]
        for p in procs:
            p.wait()
        return time.perf_counter() - t0

    run(1)
    return 2.0 * run(1) / run(2)


def table(args: Any) -> str:
    """Measure every row; returns the markdown."""
    import clpc

    n, repeat, n_ref = int(args.samples), args.repeat, args.ref_windows
    u, y = record(n)
    u1 = u[:, 0]
    rows: list[list[str]] = []
    notes: list[str] = []

    def ref_cost(order: int, cluster: int, uu: np.ndarray) -> float:
        return cpu(lambda: reference(uu, y, order, cluster, n_ref), max(1, repeat // 2)) / n_ref

    def row(
        name: str, p: int, n_up: int, seconds: float, ref: float | None, extra: str = ""
    ) -> None:
        us = seconds / n_up * 1e6
        ratio = f"{ref * 1e6 / us:.1f}x" if ref else "-"
        ref_cell = f"{ref * 1e6:.1f}" if ref else "-"
        rows.append([name, str(p), f"{us:.2f}", ref_cell, ratio, f"{us / p**2:.3f}", extra])

    # C = 12, default and paper
    ref12 = ref_cost(2, 12, u1[:, None])
    default = clpc.CLPC(order=2, window_size=WINDOW, cluster_size=12)
    t_run = cpu(lambda: default.run(u1, y), repeat)
    n_up = len(default.run(u1, y))
    row("run, C=12 (default, robust)", 6, n_up, t_run, ref12, f"{n / t_run / 1e6:.2f} M samples/s")
    paper = clpc.CLPC(order=2, window_size=WINDOW, cluster_size=12, method="paper")
    t = cpu(lambda: paper.run(u1, y), repeat)
    row("run, C=12, method='paper'", 6, n_up, t, ref12)
    notes.append(f"paper N=2 vs reference: {exactness(paper.run(u1, y), u, y, 2, n_ref)}")
    # C = 1
    n1 = min(n, 20 * n_ref)
    one = clpc.CLPC(order=2, window_size=WINDOW, cluster_size=1)
    t = cpu(lambda: one.run(u1[:n1], y[:n1]), repeat)
    row("run, C=1", 6, len(one.run(u1[:n1], y[:n1])), t, ref_cost(2, 1, u1[:, None]))

    # push(10000) vs run
    def pushed() -> None:
        a = clpc.CLPC(order=2, window_size=WINDOW, cluster_size=12)
        for lo in range(0, n, 10000):
            a.push(u1[lo : lo + 10000], y[lo : lo + 10000])

    t = cpu(pushed, repeat)
    row("push(10000), C=12", 6, n_up, t, ref12, f"push / run = {t / t_run:.2f}")
    # step
    n_step = min(n, 20000)
    ul, yl = u1[:n_step].tolist(), y[:n_step].tolist()

    def stepped() -> None:
        a = clpc.CLPC(order=2, window_size=WINDOW, cluster_size=12)
        f = a.step
        for uk, yk in zip(ul, yl, strict=True):
            f(uk, yk)

    t = cpu(stepped, repeat)
    per = t / n_step * 1e6
    row("step (Python floats), C=12", 6, (n_step - 2) // 12, t, ref12, f"{per:.2f} us/sample")

    def stepped_read() -> None:  # an update's arrays are sliced when first read
        a = clpc.CLPC(order=2, window_size=WINDOW, cluster_size=12)
        f = a.step
        for uk, yk in zip(ul, yl, strict=True):
            part = f(uk, yk)
            if len(part):
                part.theta, part.D  # noqa: B018 - what a monitoring loop reads

    t = cpu(stepped_read, repeat)
    per = t / n_step * 1e6
    row("step, theta and D read, C=12", 6, (n_step - 2) // 12, t, ref12, f"{per:.2f} us/sample")
    ul1, yl1 = ul[:2000], yl[:2000]

    def stepped1() -> None:
        a = clpc.CLPC(order=2, window_size=WINDOW, cluster_size=1)
        f = a.step
        for uk, yk in zip(ul1, yl1, strict=True):
            f(uk, yk)

    t = cpu(stepped1, repeat)
    row("step (Python floats), C=1", 6, 1998, t, None, f"{t / 2000 * 1e6:.1f} us/sample")
    # n_jobs = 2 (wall)
    cap = parallel_capacity()
    two = clpc.CLPC(order=2, window_size=WINDOW, cluster_size=12, n_jobs=2)
    w1, w2 = wall(lambda: default.run(u1, y), repeat), wall(lambda: two.run(u1, y), repeat)
    row(
        "run, C=12, n_jobs=2 (wall)",
        6,
        n_up,
        w2,
        ref12,
        f"{w1 / w2:.2f}x over n_jobs=1 (machine: {cap:.2f}x for two busy processes)",
    )
    # orders 1..5 and the MISO row
    for order in range(1, 6):
        p = 2 * order + 2
        a = clpc.CLPC(order=order, window_size=WINDOW, cluster_size=12)
        t = cpu(lambda a=a: a.run(u1, y), repeat)
        row(f"run, C=12, order {order}", p, n_up, t, ref_cost(order, 12, u1[:, None]))
        if order == 2:  # already compared above
            continue
        b = clpc.CLPC(order=order, window_size=WINDOW, cluster_size=12, method="paper")
        notes.append(
            f"paper N={order} vs reference: {exactness(b.run(u1, y), u1[:, None], y, order, n_ref)}"
        )
    u2, y2 = record(n, n_inputs=2)
    a = clpc.CLPC(order=2, window_size=WINDOW, cluster_size=12, mimo="miso")
    t = cpu(lambda: a.run(u2, y2), repeat)
    p_miso = 9
    ref2 = cpu(lambda: reference(u2, y2, 2, 12, n_ref), max(1, repeat // 2)) / n_ref
    row("run, C=12, 2-input MISO, order 2", p_miso, len(a.run(u2, y2)), t, ref2)
    b = clpc.CLPC(order=2, window_size=WINDOW, cluster_size=12, mimo="miso", method="paper")
    notes.append(f"paper MISO vs reference: {exactness(b.run(u2, y2), u2, y2, 2, n_ref)}")
    # the peers
    found = peers(args.peers_python, args.peer_windows)
    us_default = t_run / n_up * 1e6
    for name, value in found.items():
        if isinstance(value, float):
            faster = f"clpc run C=12 is {value * 1e6 / us_default:.0f}x faster"
            cells = [f"{value * 1e6:.0f}", f"{ref12 * 1e6:.1f}", f"{ref12 / value:.2f}x"]
            rows.append([f"{name}: ARX refit per window", "6", *cells, "-", faster])
        else:
            notes.append(f"{name}: {value}")
    head = [
        "configuration",
        "p",
        "us/window (CPU)",
        "ref eigh us/window",
        "vs ref",
        "us / p^2",
        "note",
    ]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    lines += [
        "",
        f"T = {n:.0e} samples (C=1 rows: {n1:.0e}; step: {n_step:.0e} and 2e3), W = {WINDOW}, "
        f"reference on the first {n_ref} windows; load average at the end {load}.",
    ]
    lines += ["", "Exactness (method='paper' vs the reference, max relative deviation):"]
    lines += [f"- {note}" for note in notes]
    return "\n".join(lines)


def add_arguments(ap: Any) -> None:
    """The table's options (shared with ``bench_clpc.py --table``)."""
    ap.add_argument("--table-samples", dest="samples", type=float, default=1e5)
    ap.add_argument("--table-repeat", dest="repeat", type=int, default=5, help="best of (5)")
    ap.add_argument("--ref-windows", type=int, default=1000, help="reference prefix (1000)")
    ap.add_argument("--peer-windows", type=int, default=100, help="windows per peer (100)")
    ap.add_argument(
        "--peers-python",
        default="/work/venv-peers/bin/python",
        help="python of the venv holding sippy_unipi and sysidentpy ('' for none)",
    )


def main(argv: list[str] | None = None) -> int:
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_arguments(ap)
    ap.add_argument("--peer-worker", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.peer_worker:
        print(json.dumps(peer_worker(json.loads(args.peer_worker))))
        return 0
    if args.peers_python and not Path(args.peers_python).exists():
        args.peers_python = ""
    print(table(args))
    return 0


if __name__ == "__main__":
    sys.exit(main())
