"""Speed, memory and exactness of the CLPC appraiser (issue "CLPC appraiser", item 7).

Data: a white Gaussian input (persistently exciting of any order) through the 2nd-order ARX
system ``A(q) y = B(q) u + e`` with ``A = 1 - 1.5 q^-1 + 0.7 q^-2``, ``B = 0.5 + 0.3 q^-1 +
0.1 q^-2`` and equation noise ``e ~ N(0, 0.1^2)``, plus white measurement noise (std 0.02) on
``y``. Settings: ``order = N = 2`` (the paper's ``parameters_size = 3``), ``W = 201``, ``C = 12``.

Engines: every rule has one source (:mod:`clpc.core.rules`, kernel
:mod:`clpc.appraiser.kernel`), run compiled by numba (``compiled``, the default) or
uncompiled (``python``: numba's ``NUMBA_DISABLE_JIT=1``, for debugging; ~100x slower).
Everything is measured with ``compiled``; ``python`` gets one batch row at
``T <= --python-max`` (default 1e4, one repetition, in a worker process with
``NUMBA_DISABLE_JIT=1``) and an exactness check against ``compiled`` on 5e3 samples. The
compiled kernels are built on their first use in an environment (numba caches them on disk
under ``src/clpc/**/__pycache__``); the script loads them once at start-up, in this process
and in a fresh one per package (the time is printed), and every measurement warms up
before timing, so compilation is never timed. Only the public API is used (``clpc.CLPC``,
``run``, ``push``, ``step``, ``clpc.Trace``).

Paths timed on the same data:

* ``batch``      ``CLPC(...).run(u, y)`` (over the whole record; the trace is kept);
* ``push(C)``    ``push`` in chunks of C samples (traces consumed and dropped, as a stream);
* ``step``       ``step(u_k, y_k)`` per sample on a prefix, fed Python floats
  (``u.tolist()`` values, as a streaming user would; the conversion is not timed);
  ``push(1)`` the same with 1-sample arrays;
* ``ref eigh``   a plain per-window implementation: for every update build the window's lag
  matrix, center it, form the scatter, ``numpy.linalg.eigh``, take the smallest
  eigenvector (``_reference_eigh`` below); every speed ratio is against it;
* ``ref lstsq``  sliding-window least squares (per window ``numpy.linalg.lstsq``).

Comparisons: ``cluster_size=1`` vs the reference with C = 1, ``n_jobs=2`` vs 1 and
``method='paper'`` vs ``'robust'`` (batch). Exactness: ``method='paper'`` batch vs the
reference (D, eigenvalues, theta), ``push``/``step`` vs batch, ``python`` vs ``compiled``.

Baseline (``--baseline-src PATH``): the ``src`` directory of an older checkout of clpc, e.g.
``git worktree add /tmp/clpc-baseline <commit>`` then ``--baseline-src
/tmp/clpc-baseline/src``. Batch at every ``T``, batch with ``cluster_size=1`` and with
``method='paper'``, and ``step`` are then measured with both packages (compiled)
in fresh subprocess workers (this script with ``--worker``; the baseline's with
``PYTHONPATH=PATH``, so that its ``import clpc`` gets the old code, which is checked): one
worker per package and round runs them all, ``--baseline-rounds`` (3) rounds with the
packages' order alternating, the best of each kept; the table "New
vs baseline" shows both side by side, each against the reference of this run, and the speed
ratio new/baseline (> 1: the new code is faster); the exactness section compares their
traces. To benchmark a snapshot rather than the working tree, run the whole script with
``PYTHONPATH=<snapshot>/src`` (the baseline's workers override it).

Runs with ``T > 1e5`` each run in a fresh subprocess (clean RSS accounting), smaller ones in
this process; every measurement follows a small warm-up.
Timing: ``batch``, ``push(10000)``, ``ref eigh`` and ``step`` at ``T <= 1e6`` keep the best of
three repetitions (other jobs on the machine only ever slow a run down), runs at
``T <= 1e5`` repeat for at least 0.3 s (at most 5 repetitions); speed ratios use process CPU
time, samples/s wall time. References longer than ``--ref-cap`` are timed on a prefix and
extrapolated linearly (the cost per window does not depend on ``T``). Memory: the peak
added over the loaded data, from ``tracemalloc`` (an extra, untimed repetition) for
``T <= 1e5`` and from the kernel's peak RSS (``VmHWM`` after resetting it through
``/proc/self/clear_refs``; ``ru_maxrss`` otherwise) for larger runs. tracemalloc sees numpy's
arrays but not the compiled kernel's own scratch arrays (numba's allocator; well below 1 MB
per batch of windows); the RSS figures include them. ``trace`` is the size of the returned
:class:`clpc.Trace` (only ``batch`` keeps one; it grows with ``T``, ~310 bytes per update) and
``working`` = added - trace, the memory the computation itself needs.

Usage::

    python benchmarks/bench_clpc.py            # ~2-3 min: T = 1e4 .. 1e7
    python benchmarks/bench_clpc.py --quick    # ~30-60 s: T = 1e4, 1e5, short prefixes
    python benchmarks/bench_clpc.py --baseline-src /tmp/clpc-baseline/src   # + new vs old
    python benchmarks/bench_clpc.py --only-njobs --sizes 1e6   # n_jobs=2 vs 1 only
    python benchmarks/bench_clpc.py --profile --sizes 1e6      # cProfile of run and step
    python benchmarks/bench_clpc.py --sizes 1e4 1e5 1e6
    python benchmarks/bench_clpc.py --huge     # adds a 1e8-sample record streamed from .npy
    python benchmarks/bench_clpc.py --table    # issue 26's table (clpc_table.py), peers too
    python benchmarks/bench_clpc.py --split    # per-window cost split (clpc_split.py)
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import shutil
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np
from scipy import signal

sys.path.insert(0, str(Path(__file__).parent))
import clpc_table  # numpy and scipy only at import (clpc is imported when measured)

ORDER, WINDOW, CLUSTER = 2, 201, 12
DEN = np.array([1.0, -1.5, 0.7])
NUM = np.array([0.5, 0.3, 0.1])
EQ_NOISE, MEAS_NOISE = 0.1, 0.02
SEED = 20240607


def _engine_here() -> str:
    """``"python"`` when numba's ``NUMBA_DISABLE_JIT`` is set in this process, else compiled."""
    return "python" if os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0") else "compiled"


# ====================================================================== data
def _blocks(n: int, seed: int, block: int = 1_000_000):
    """The benchmark process, ``block`` samples at a time: yields ``(lo, u, y)``."""
    rng = np.random.default_rng(seed)
    zi_u = np.zeros(len(DEN) - 1)
    zi_e = np.zeros(len(DEN) - 1)
    for lo in range(0, n, block):
        m = min(block, n - lo)
        u = rng.standard_normal(m)
        e = EQ_NOISE * rng.standard_normal(m)
        yu, zi_u = signal.lfilter(NUM, DEN, u, zi=zi_u)
        ye, zi_e = signal.lfilter([1.0], DEN, e, zi=zi_e)
        yield lo, u, yu + ye + MEAS_NOISE * rng.standard_normal(m)


def generate(path_u: Path, path_y: Path, n: int) -> None:
    """Write ``n`` samples of u and y (float64, raw binary) block by block."""
    with open(path_u, "wb") as fu, open(path_y, "wb") as fy:
        for _, u, y in _blocks(n, SEED):
            u.tofile(fu)
            y.tofile(fy)


def generate_npy(path: Path, n: int) -> None:
    """The same process into one ``(n, 2)`` ``.npy`` file ``[u, y]`` (for ``--huge``)."""
    out = np.lib.format.open_memmap(path, mode="w+", dtype=np.float64, shape=(n, 2))
    for lo, u, y in _blocks(n, SEED + 1):
        out[lo : lo + u.size, 0] = u
        out[lo : lo + u.size, 1] = y
    out.flush()
    del out


def load(workdir: Path, n: int) -> tuple[np.ndarray, np.ndarray]:
    u = np.fromfile(workdir / "u.bin", dtype=np.float64, count=n)
    y = np.fromfile(workdir / "y.bin", dtype=np.float64, count=n)
    if u.size < n:
        raise SystemExit(f"data file holds {u.size} samples; {n} requested")
    return u, y


# ====================================================================== references
def _reference_eigh(
    u: np.ndarray, y: np.ndarray, cluster: int = CLUSTER, window: int = WINDOW, order: int = ORDER
) -> tuple[np.ndarray, np.ndarray]:
    """Plain per-window LPC: returns theta (n_updates, p) (a0 >= 0) and eigenvalues."""
    n_rows = len(u) - order
    n_updates = n_rows // cluster
    p = 2 * order + 2
    thetas = np.empty((n_updates, p))
    eigs = np.empty((n_updates, p))
    for j in range(1, n_updates + 1):
        m = cluster * j  # the update closes after lag vector m; rows [max(0, m - W), m)
        first = max(0, m - window)
        lo, hi = first + order, m + order  # sample index n of the first/after-last row
        cols = [y[lo - i : hi - i] for i in range(order + 1)]
        cols += [u[lo - i : hi - i] for i in range(order + 1)]
        lag = np.column_stack(cols)  # rows z_n = [y(n) .. y(n-N), u(n) .. u(n-N)]
        centered = lag - lag.mean(axis=0)
        scatter = centered.T @ centered
        w, v = np.linalg.eigh(scatter)
        theta = v[:, 0]
        thetas[j - 1] = theta if theta[0] >= 0 else -theta
        eigs[j - 1] = w
    return thetas, eigs


def _reference_lstsq(
    u: np.ndarray, y: np.ndarray, cluster: int = CLUSTER, window: int = WINDOW, order: int = ORDER
) -> np.ndarray:
    """Sliding-window least squares: theta = [1, x] / ||.|| per window."""
    n_rows = len(u) - order
    n_updates = n_rows // cluster
    p = 2 * order + 2
    thetas = np.empty((n_updates, p))
    for j in range(1, n_updates + 1):
        m = cluster * j
        first = max(0, m - window)
        lo, hi = first + order, m + order
        cols = [y[lo - i : hi - i] for i in range(order + 1)]
        cols += [u[lo - i : hi - i] for i in range(order + 1)]
        lag = np.column_stack(cols)
        centered = lag - lag.mean(axis=0)
        x, *_ = np.linalg.lstsq(centered[:, 1:], -centered[:, 0], rcond=None)
        theta = np.concatenate([[1.0], x])
        thetas[j - 1] = theta / np.linalg.norm(theta)
    return thetas


# ====================================================================== worker
def _status_mb() -> dict[str, float]:
    out = {}
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                key = line.split(":")[0]
                if key in ("VmHWM", "VmRSS", "RssAnon", "RssFile"):
                    out[key] = int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return out


def _reset_peak() -> bool:
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
        return True
    except OSError:
        return False


def _peak_rss_mb(can_reset: bool) -> float:
    if can_reset and "VmHWM" in _status_mb():
        return _status_mb()["VmHWM"]
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _trace_mb(trace) -> float:
    arrays = [trace.index, trace.time, trace.rows, trace.not_enough_data, *trace.arrays.values()]
    return sum(a.nbytes for a in arrays) / 2**20


def _execute(spec: dict, u, y) -> dict:
    """Run one path once; returns updates and the trace size.

    ``u``/``y`` are arrays, or lists of Python floats for ``step``.
    """
    import clpc

    kind = spec["kind"]
    kw = dict(
        order=ORDER,
        window_size=WINDOW,
        cluster_size=spec.get("cluster", CLUSTER),
        method=spec.get("method", "robust"),
        n_jobs=spec.get("n_jobs", 1),
    )
    if kind == "batch":
        tr = clpc.CLPC(**kw).run(u, y)
        return {"updates": len(tr), "trace_mb": _trace_mb(tr), "_keep": tr}
    if kind == "push":
        app = clpc.CLPC(**kw)
        chunk = spec["chunk"]
        n_up = 0
        for lo in range(0, len(u), chunk):
            n_up += len(app.push(u[lo : lo + chunk], y[lo : lo + chunk]))
        return {"updates": n_up, "trace_mb": 0.0}
    if kind == "step":
        app = clpc.CLPC(**kw)
        n_up = 0
        step = app.step
        for u_k, y_k in zip(u, y, strict=True):
            n_up += len(step(u_k, y_k))
        return {"updates": n_up, "trace_mb": 0.0}
    if kind == "ref_eigh":
        th, _ = _reference_eigh(u, y, cluster=spec.get("cluster", CLUSTER))
        return {"updates": th.shape[0], "trace_mb": 0.0}
    if kind == "ref_lstsq":
        th = _reference_lstsq(u, y, cluster=spec.get("cluster", CLUSTER))
        return {"updates": th.shape[0], "trace_mb": 0.0}
    raise ValueError(kind)


def worker(spec: dict) -> dict:
    """One measurement in this (fresh) process."""
    import clpc

    workdir = Path(spec["workdir"])
    n = spec["n"]
    u, y = load(workdir, n)
    if spec["kind"] == "step":  # a streaming user's samples: Python floats
        u, y = u.tolist(), y.tolist()
    # warm-up: imports, loading the compiled kernel (compiling it if numba's cache is cold),
    # LAPACK and thread-pool start-up are not part of the measurement
    wu = min(n, 5000)
    _execute(spec, u[:wu], y[:wu])
    u_w, y_w = np.asarray(u[:wu], dtype=np.float64), np.asarray(y[:wu], dtype=np.float64)
    clpc.CLPC(
        order=ORDER, window_size=WINDOW, cluster_size=CLUSTER, n_jobs=spec.get("n_jobs", 1)
    ).run(u_w, y_w)
    can_reset = _reset_peak()
    base = _status_mb().get("VmRSS", resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
    base_peak = _peak_rss_mb(can_reset)
    times, cpus = [], []
    result: dict = {}
    min_time = spec.get("min_time", 0.0)
    while True:
        r0 = resource.getrusage(resource.RUSAGE_SELF)
        t0 = time.perf_counter()
        result = _execute(spec, u, y)
        t1 = time.perf_counter()
        r1 = resource.getrusage(resource.RUSAGE_SELF)
        times.append(t1 - t0)
        cpus.append((r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime))
        result.pop("_keep", None)
        enough = sum(times) >= min_time and len(times) >= spec.get("min_reps", 1)
        if enough or len(times) >= 5:
            break
    peak = _peak_rss_mb(can_reset)
    best = int(np.argmin(times))
    out = {
        "time": times[best],
        "cpu": min(cpus),
        "reps": len(times),
        "updates": result["updates"],
        "trace_mb": result["trace_mb"],
        "rss_added_mb": max(peak - base, 0.0),
        "rss_note": "" if can_reset and peak > base_peak - 1e-9 else "peak<=baseline",
        "clpc_file": clpc.__file__,
    }
    if spec.get("tracemalloc"):
        m = spec.get("tracemalloc_samples", n)
        tracemalloc.start()
        keep = _execute(spec, u[:m], y[:m])
        _, tpeak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        del keep
        out["tm_peak_mb"] = tpeak / 2**20
        out["tm_samples"] = m
    return out


def huge_worker(spec: dict) -> dict:
    """Stream a big .npy record (mmap) through push in chunks; report RSS and throughput."""
    import mmap

    import clpc

    path = spec["path"]
    chunk = spec["chunk"]
    data = np.load(path, mmap_mode="r")
    raw = getattr(data, "_mmap", None)
    offset = data.offset if hasattr(data, "offset") else 0
    n = data.shape[0]
    app = clpc.CLPC(order=ORDER, window_size=WINDOW, cluster_size=CLUSTER)
    app.push(data[:5000, 0], data[:5000, 1])  # warm-up (not timed)
    app.reset()
    can_reset = _reset_peak()
    base = _status_mb()
    max_anon = max_file = 0.0
    n_up = 0
    last_d = float("nan")
    t0 = time.perf_counter()
    for lo in range(0, n, chunk):
        block = data[lo : lo + chunk]
        tr = app.push(block[:, 0], block[:, 1])
        n_up += len(tr)
        if len(tr):
            last_d = float(tr.D[-1])
        del tr, block
        st = _status_mb()
        max_anon = max(max_anon, st.get("RssAnon", 0.0))
        max_file = max(max_file, st.get("RssFile", 0.0))
        if spec.get("drop_pages", True) and raw is not None:
            # the consumed part of the file need not stay mapped in this process
            end = offset + (lo + chunk) * 16
            end -= end % mmap.PAGESIZE
            if end > 0:
                raw.madvise(mmap.MADV_DONTNEED, 0, min(end, len(raw)))
    elapsed = time.perf_counter() - t0
    return {
        "n": n,
        "chunk": chunk,
        "time": elapsed,
        "updates": n_up,
        "last_D": last_d,
        "base_rss_mb": base.get("VmRSS", float("nan")),
        "peak_rss_mb": _peak_rss_mb(can_reset),
        "max_rss_anon_mb": max_anon,
        "max_rss_file_mb": max_file,
        "drop_pages": spec.get("drop_pages", True),
        "engine": _engine_here(),
    }


def parallel_capacity() -> float:
    """Wall-time speed-up of two concurrent busy processes over one (2 = two free cores)."""
    code = (
        "import time\nt0 = time.process_time()\nx = 0\n"
        "while time.process_time() - t0 < 0.4:\n    for i in range(10000):\n        x += i\n"
    )

    def wall(k: int) -> float:
        t0 = time.perf_counter()
        procs = [subprocess.Popen([sys.executable, "-c", code]) for _ in range(k)]
        for p in procs:
            p.wait()
        return time.perf_counter() - t0

    wall(1)  # warm the interpreter start-up caches
    one, two = wall(1), wall(2)
    return 2.0 * one / two


def profile(workdir: Path, n: int, n_step: int, top: int = 18) -> None:
    """cProfile of CLPC().run on n samples and of step on n_step samples (tottime order)."""
    import cProfile
    import io
    import pstats

    import clpc

    u, y = load(workdir, n)
    u_s, y_s = u[:n_step].tolist(), y[:n_step].tolist()
    app = clpc.CLPC(order=ORDER, window_size=WINDOW, cluster_size=CLUSTER)
    app.run(u[:5000], y[:5000])  # warm-up (compiles the kernel if numba's cache is cold)
    _steps(u_s[:2000], y_s[:2000])
    name = _engine_here()
    for title, stmt in (
        (
            f"CLPC({name}).run, T={fmt_n(n)}",
            lambda: clpc.CLPC(order=ORDER, window_size=WINDOW, cluster_size=CLUSTER).run(u, y),
        ),
        (f"step x {fmt_n(n_step)} (Python floats, {name})", lambda: _steps(u_s, y_s)),
    ):
        prof = cProfile.Profile()
        prof.enable()
        stmt()
        prof.disable()
        buf = io.StringIO()
        st = pstats.Stats(prof, stream=buf)
        st.strip_dirs().sort_stats("tottime").print_stats(top)
        print(f"## cProfile: {title}\n\n```")
        text = buf.getvalue()
        print(text[text.find("   ncalls") if "   ncalls" in text else 0 :].rstrip())
        print(f"```\n(total {st.total_tt:.2f} s under the profiler)\n")


def _steps(u: list[float], y: list[float]) -> None:
    import clpc

    step = clpc.CLPC(order=ORDER, window_size=WINDOW, cluster_size=CLUSTER).step
    for u_k, y_k in zip(u, y, strict=True):
        step(u_k, y_k)


def _git_state(root: Path | None = None) -> str:
    """Commit of the checkout at ``root`` (default: this one) and whether its src/ differs
    from it (read-only git calls)."""
    root = root or Path(__file__).resolve().parent.parent
    try:
        head = subprocess.run(
            ["git", "-C", str(root), "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", str(root), "status", "--porcelain", "--", "src"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "git state unknown"
    return f"commit {head}" + (", src/ modified" if dirty else "")


def run_worker(spec: dict, pythonpath: str | None = None, flag: str = "--worker") -> dict:
    """Run ``spec`` in a fresh interpreter (this script with ``flag``).

    ``pythonpath``: the ``src`` directory of another clpc checkout; the worker then runs
    with ``PYTHONPATH`` set to it alone, so its ``import clpc`` gets that code (it comes
    before the installed, editable package on ``sys.path``); checked from the worker's
    answer. ``spec["engine"] == "python"``: the worker runs with ``NUMBA_DISABLE_JIT=1``.
    """
    cmd = [sys.executable, os.path.abspath(__file__), flag, json.dumps(spec)]
    env = dict(os.environ)
    if pythonpath is not None:
        env["PYTHONPATH"] = pythonpath
    if spec.get("engine") == "python":
        env["NUMBA_DISABLE_JIT"] = "1"
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False, env=env)
    if proc.returncode != 0:
        raise RuntimeError(f"worker {spec} failed:\n{proc.stderr}")
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    first = out[0] if isinstance(out, list) else out
    if pythonpath is not None and "clpc_file" in first:
        got, want = Path(first["clpc_file"]).resolve(), Path(pythonpath).resolve()
        if want not in got.parents:
            raise RuntimeError(f"worker imported clpc from {got}, not from {want}")
    return out


def prime_worker(spec: dict) -> dict:
    """First use of the clpc on ``sys.path`` in this process: loads (or compiles) its kernels.

    Runs ``run``, ``push`` and ``step`` once, so that a later worker
    never compiles (numba caches on disk); returns the time it took and where clpc is.
    """
    import clpc

    u, y = load(Path(spec["workdir"]), 3000)
    t0 = time.perf_counter()
    kw = {"method": spec.get("method", "robust")}
    clpc.CLPC(order=ORDER, window_size=WINDOW, cluster_size=CLUSTER, **kw).run(u, y)
    clpc.CLPC(order=ORDER, window_size=WINDOW, cluster_size=1, **kw).run(u, y)
    app = clpc.CLPC(order=ORDER, window_size=WINDOW, cluster_size=CLUSTER, **kw)
    app.push(u[:1000], y[:1000])
    for u_k, y_k in zip(u[1000:].tolist(), y[1000:].tolist(), strict=True):
        app.step(u_k, y_k)
    return {
        "time": time.perf_counter() - t0,
        "clpc_file": clpc.__file__,
        "version": getattr(clpc, "__version__", "?"),
        "engine": _engine_here(),
    }


def dump_worker(spec: dict) -> dict:
    """Robust and 'paper' batch traces of the first ``n`` samples, saved to ``spec["out"]``."""
    import clpc

    u, y = load(Path(spec["workdir"]), spec["n"])
    arrays = {}
    for method in ("robust", "paper"):
        tr = clpc.CLPC(order=ORDER, window_size=WINDOW, cluster_size=CLUSTER, method=method).run(
            u, y
        )
        for key in ("theta", "theta_estimate", "D", "accepted"):
            arrays[f"{method}_{key}"] = np.asarray(getattr(tr, key))
    np.savez(spec["out"], **arrays)
    return {"clpc_file": clpc.__file__}


# ====================================================================== formatting
def fmt_n(x: float) -> str:
    if x <= 0:
        return "0"
    e = int(np.floor(np.log10(x)))
    m = x / 10**e
    return f"1e{e}" if abs(m - 1) < 1e-9 else f"{m:g}e{e}"


def fmt_rate(x: float) -> str:
    if x >= 1e6:
        return f"{x / 1e6:.2f} M"
    if x >= 1e3:
        return f"{x / 1e3:.1f} k"
    return f"{x:.0f}"


def table(head: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join("---" for _ in head) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


# ====================================================================== main
def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description="CLPC appraiser benchmark (issue item 7)")
    ap.add_argument(
        "--quick", action="store_true", help="~1 min run: T = 1e4, 1e5, shorter prefixes"
    )
    ap.add_argument(
        "--huge",
        action="store_true",
        help="also stream a 1e8-sample .npy record (mmap) in chunks of 1e6",
    )
    ap.add_argument(
        "--sizes",
        nargs="+",
        type=float,
        default=None,
        help="record lengths T (default 1e4 1e5 1e6 1e7; quick 1e4 1e5)",
    )
    ap.add_argument(
        "--slow-max",
        type=float,
        default=1e6,
        help="largest T for push(100) and the references (default 1e6)",
    )
    ap.add_argument(
        "--ref-cap",
        type=float,
        default=None,
        help="references longer than this are timed on a prefix and extrapolated "
        "linearly (default 1e6; quick 2e4)",
    )
    ap.add_argument(
        "--step-samples",
        type=float,
        default=None,
        help="prefix for step/push(1) (default 2e4; quick 3e3)",
    )
    ap.add_argument("--huge-samples", type=float, default=1e8, help="--huge: samples (1e8)")
    ap.add_argument("--huge-chunk", type=float, default=1e6, help="--huge: push chunk (1e6)")
    ap.add_argument(
        "--profile",
        action="store_true",
        help="only cProfile CLPC().run at T = max of --sizes (capped at 1e6) and step "
        "(uncompiled with NUMBA_DISABLE_JIT=1 in the environment)",
    )
    ap.add_argument(
        "--only-njobs",
        action="store_true",
        help="only the n_jobs=2 vs 1 comparison (batch, T = max of --sizes capped at 1e6)",
    )
    ap.add_argument(
        "--python-max",
        type=float,
        default=1e4,
        help="the uncompiled kernel (NUMBA_DISABLE_JIT=1, debugging only, very slow) gets a "
        "batch row at the sizes T <= this (default 1e4; 0: none)",
    )
    ap.add_argument(
        "--baseline-src",
        default=None,
        metavar="PATH",
        help="the src directory of an older clpc checkout (e.g. a git worktree); batch and "
        "step are then also measured with it, in subprocess workers with PYTHONPATH=PATH, "
        "and shown new vs baseline",
    )
    ap.add_argument(
        "--baseline-rounds",
        type=int,
        default=3,
        help="rounds of the new vs baseline measurements, each a worker per package, their "
        "order alternating; the best of each package is kept (default 3)",
    )
    ap.add_argument(
        "--table",
        action="store_true",
        help="only issue 26's table (benchmarks/clpc_table.py: every configuration, the "
        "reference and the peers in one run)",
    )
    ap.add_argument(
        "--split",
        action="store_true",
        help="only the per-window cost split of the kernel (benchmarks/clpc_split.py)",
    )
    clpc_table.add_arguments(ap)
    ap.add_argument("--workdir", default=None, help="where the data files go (default: temp)")
    ap.add_argument("--keep-data", action="store_true", help="keep the data files (--workdir)")
    ap.add_argument("--worker", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--huge-worker", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--prime-worker", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--dump-worker", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)

    if args.table:
        if args.peers_python and not Path(args.peers_python).exists():
            args.peers_python = ""
        print(clpc_table.table(args))
        return 0
    if args.split:
        import clpc_split  # compiles its harness on import

        clpc_split.main()
        return 0
    if args.worker:
        spec = json.loads(args.worker)
        if "multi" in spec:  # several measurements, one after the other, in this process
            print(json.dumps([worker(s) for s in spec["multi"]]))
        else:
            print(json.dumps(worker(spec)))
        return 0
    if args.huge_worker:
        print(json.dumps(huge_worker(json.loads(args.huge_worker))))
        return 0
    if args.prime_worker:
        print(json.dumps(prime_worker(json.loads(args.prime_worker))))
        return 0
    if args.dump_worker:
        print(json.dumps(dump_worker(json.loads(args.dump_worker))))
        return 0

    import importlib.util

    import clpc

    if importlib.util.find_spec("numba") is None:
        raise SystemExit("numba is not installed: the compiled engine (the default) needs it")
    baseline = str(Path(args.baseline_src).resolve()) if args.baseline_src else None
    if baseline is not None and not (Path(baseline) / "clpc" / "__init__.py").is_file():
        raise SystemExit(f"--baseline-src {args.baseline_src}: no clpc/__init__.py there")

    default_sizes = [1e4, 1e5] if args.quick else [1e4, 1e5, 1e6, 1e7]
    sizes = [int(s) for s in (args.sizes or default_sizes)]
    sizes = sorted(set(sizes))
    ref_cap = int(args.ref_cap or (2e4 if args.quick else 1e6))
    slow_max = int(args.slow_max)
    python_max = int(args.python_max)
    step_n = int(args.step_samples or (3e3 if args.quick else 2e4))
    t_cmp = min(max(sizes), int(1e6))  # n_jobs, method comparisons
    t_c1 = int(5e3 if args.quick else 1e5)  # cluster_size = 1
    t_check = int(1e4 if args.quick else 1e5)  # exactness check
    t_rep = 0.5 if args.quick else 3.0  # repeat the n_jobs/method runs for at least this long
    n_data = max([*sizes, step_n, t_c1, t_check])

    # the compiled kernel is measured throughout; "python" runs the same source uncompiled
    # (NUMBA_DISABLE_JIT=1 in a worker; debugging only, ~100x slower): one batch row at
    # T <= --python-max
    engines = ["compiled"]
    default_engine = "compiled"
    main_engine = engines[0]
    sel_engine = _engine_here()  # --profile / --only-njobs / --huge: this process's

    def eng_name(e: str) -> str:
        return f"{e} (default)" if e == default_engine else e

    t_start = time.perf_counter()
    workdir = Path(args.workdir or tempfile.mkdtemp(prefix="clpc-bench-"))
    workdir.mkdir(parents=True, exist_ok=True)
    print(f"# CLPC benchmark ({time.strftime('%Y-%m-%d %H:%M')})")
    try:
        import numba

        numba_v = f"numba {numba.__version__}"
    except ImportError:
        numba_v = "numba not installed"
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} logical cores, "
        f"{platform.platform()}; Python {platform.python_version()}, numpy {np.__version__}, "
        f"{numba_v}"
    )
    cli = " ".join(sys.argv[1:] if argv is None else argv)
    print(f"command: python benchmarks/bench_clpc.py {cli}")
    print(f"clpc: {clpc.__file__} ({_git_state(Path(clpc.__file__).resolve().parents[2])})")
    print(f"load average at start: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(
        f"data: white Gaussian u -> ARX A={DEN.tolist()}, B={NUM.tolist()}, "
        f"e~N(0,{EQ_NOISE}^2), +N(0,{MEAS_NOISE}^2) on y; N={ORDER}, W={WINDOW}, C={CLUSTER}, "
        "method='robust' unless stated"
    )
    print(
        f"engines: compiled; python (NUMBA_DISABLE_JIT=1, uncompiled, batch at "
        f"T <= {fmt_n(python_max)} only)"
    )
    if baseline is not None:
        print(f"baseline: {baseline} ({_git_state(Path(baseline).parent)}), compiled")
    gen0 = time.perf_counter()
    generate(workdir / "u.bin", workdir / "y.bin", n_data)
    print(f"(generated {fmt_n(n_data)} samples in {time.perf_counter() - gen0:.1f} s)")
    # the first use in an environment compiles the kernels (numba caches them on disk, under
    # src/clpc/**/__pycache__): load them once here and in a fresh process per package, so
    # no worker ever compiles (each also warms up before timing)
    u0, y0 = load(workdir, 5000)
    c0 = time.perf_counter()
    clpc.CLPC(order=ORDER, window_size=WINDOW, cluster_size=CLUSTER).run(u0, y0)
    c_here = time.perf_counter() - c0
    prime = {"workdir": str(workdir), "engine": "compiled"}
    c_new = run_worker(prime, flag="--prime-worker")["time"]
    print(
        f"(compiled engine: first call {c_here:.1f} s in this process, {c_new:.1f} s in a fresh "
        "one (run, push, step), loading or compiling the kernels; never timed below)"
    )
    if baseline is not None:
        pb = run_worker(prime, pythonpath=baseline, flag="--prime-worker")
        print(
            f"(baseline {pb['version']} from {pb['clpc_file']}, engine {pb['engine']!r}: first "
            f"calls in a fresh process {pb['time']:.1f} s; never timed below)"
        )
    print()

    def measure(kind: str, n: int, **kw) -> dict:
        spec = {"kind": kind, "n": n, "workdir": str(workdir), **kw}
        if n <= 1e5:
            spec.setdefault("min_time", 0.3)
            spec.setdefault("tracemalloc", True)
            if kind.startswith("ref") or kw.get("chunk") == 100:  # memory of one window
                spec.setdefault("tracemalloc_samples", min(n, 20000))
        if n <= 1e6 and (kind in ("batch", "ref_eigh", "step") or kw.get("chunk") == 10000):
            # contention by other jobs only ever slows a run down: keep the best of three
            spec.setdefault("min_reps", 3)
        # small runs in this process (no interpreter start-up); large ones in a fresh one
        in_here = n <= 1e5 and kw.get("engine", main_engine) == _engine_here()
        res = worker(spec) if in_here else run_worker(spec)
        res["n"] = n
        return res

    def mem(res: dict) -> float:
        return res.get("tm_peak_mb", res["rss_added_mb"])

    def mem_cell(res: dict) -> str:
        if "tm_peak_mb" in res:
            on = "" if res["tm_samples"] >= res["n"] else f" on {fmt_n(res['tm_samples'])}"
            return f"{res['tm_peak_mb']:.1f} (tm{on})"
        return f"{res['rss_added_mb']:.0f} (rss)"

    def work_cell(res: dict) -> str:
        digits = 1 if "tm_peak_mb" in res else 0
        return f"{mem(res) - res['trace_mb']:.{digits}f}"

    if args.profile:
        profile(workdir, t_cmp, step_n)
        if args.workdir is None:
            shutil.rmtree(workdir, ignore_errors=True)
        return 0

    if args.only_njobs:
        capacity = parallel_capacity()
        j1 = measure("batch", t_cmp, min_time=3.0, engine=sel_engine)
        j2 = measure("batch", t_cmp, n_jobs=2, min_time=3.0, engine=sel_engine)
        capacity = min(capacity, parallel_capacity())
        print(
            f"## n_jobs (T={fmt_n(t_cmp)}, engine {eng_name(sel_engine)}, best of up to 5; "
            f"machine capacity {capacity:.2f}x)\n"
        )
        print(
            table(
                ["n_jobs", "engine", "wall [s]", "CPU [s]", "CPU/wall", "samples/s", "speed-up"],
                [
                    [
                        str(k),
                        sel_engine,
                        f"{r['time']:.3f}",
                        f"{r['cpu']:.3f}",
                        f"{r['cpu'] / r['time']:.2f}",
                        fmt_rate(t_cmp / r["time"]),
                        f"{j1['time'] / r['time']:.2f}x",
                    ]
                    for k, r in ((1, j1), (2, j2))
                ],
            )
        )
        if args.workdir is None:
            shutil.rmtree(workdir, ignore_errors=True)
        return 0

    # ------------------------------------------------------------ main table
    # Ratios use process CPU time (robust to other jobs on the machine); samples/s use wall.
    results: dict[tuple[str, str, int], dict] = {}  # (label, engine, T)
    ref_cpu: dict[int, tuple[float, str]] = {}  # CPU seconds per sample of ref eigh
    rows = []
    for n in sizes:
        paths: list[tuple[str, str, dict]] = [("batch", e, {}) for e in engines]
        if n <= python_max:  # one repetition, no memory: it is slow
            paths.append(
                ("batch", "python", {"min_time": 0.0, "min_reps": 1, "tracemalloc": False})
            )
        if n <= slow_max:
            paths.append(("push(100)", main_engine, {"chunk": 100}))
        paths += [("push(10000)", e, {"chunk": 10000}) for e in engines]
        if n <= slow_max:
            paths += [("ref eigh", "-", {}), ("ref lstsq", "-", {})]
        for label, eng, kw in paths:
            kind = {"batch": "batch", "ref eigh": "ref_eigh", "ref lstsq": "ref_lstsq"}.get(
                label, "push"
            )
            note, m = "", n
            if kind.startswith("ref") and n > ref_cap:
                m = ref_cap
                note = f"timed on a {fmt_n(m)} prefix, extrapolated linearly"
            if eng != "-":
                kw = {**kw, "engine": eng}
            res = measure(kind, m, **kw)
            res.update(wall=res["time"] * n / m, cpu_t=res["cpu"] * n / m, T=n, note=note)
            results[(label, eng, n)] = res
            if label == "ref eigh":
                ref_cpu[n] = (res["cpu_t"] / n, note)
        if n not in ref_cpu and ref_cpu:
            big = max(ref_cpu)
            ref_cpu[n] = (ref_cpu[big][0], f"extrapolated from T={fmt_n(big)}")
        for label, eng, _ in paths:
            res = results[(label, eng, n)]
            res["ratio"] = ref_cpu[n][0] * n / res["cpu_t"] if n in ref_cpu else float("nan")
            note = res["note"]
            if not label.startswith("ref") and ref_cpu.get(n, (0, ""))[1]:
                note = "ratio vs ref " + ref_cpu[n][1]
            memory = [mem_cell(res), f"{res['trace_mb']:.1f}", work_cell(res)]
            if eng == "python":
                memory = ["-", f"{res['trace_mb']:.1f}", "-"]
                note = "uncompiled (debugging only), one repetition" + (note and f"; {note}")
            rows.append(
                [
                    label,
                    eng,
                    fmt_n(n),
                    f"{res['wall']:.3f}",
                    f"{res['cpu_t']:.3f}",
                    fmt_rate(n / res["wall"]),
                    f"{res['ratio']:.2f}x" if res["ratio"] < 1 else f"{res['ratio']:.1f}x",
                    *memory,
                    note,
                ]
            )
        print(f"  ... T={fmt_n(n)} done ({time.perf_counter() - t_start:.0f} s)", file=sys.stderr)

    # streaming per sample (chunk 1): step on Python floats with both engines, push(1)
    ref_small = min(ref_cpu) if ref_cpu else None
    per_sample = [("step", "step", e, {}) for e in engines]
    per_sample.append(("push(1)", "push", main_engine, {"chunk": 1}))
    for label, kind, eng, kw in per_sample:
        res = measure(kind, step_n, tracemalloc_samples=min(step_n, 5000), engine=eng, **kw)
        res.update(wall=res["time"], cpu_t=res["cpu"])
        results[(label, eng, step_n)] = res
        res["ratio"] = ref_cpu[ref_small][0] * step_n / res["cpu"] if ref_small else float("nan")
        fed = "Python floats" if kind == "step" else "1-sample arrays"
        rows.append(
            [
                label,
                eng,
                fmt_n(step_n),
                f"{res['time']:.3f}",
                f"{res['cpu']:.3f}",
                fmt_rate(step_n / res["time"]),
                f"{res['ratio']:.2f}x",
                mem_cell(res),
                "0.0",
                work_cell(res),
                f"{res['cpu'] / step_n * 1e6:.1f} us/sample CPU ({res['time'] / step_n * 1e6:.1f} "
                f"wall), {fed}, amortised over a {fmt_n(step_n)} prefix",
            ]
        )
    head = [
        "path",
        "engine",
        "T",
        "wall [s]",
        "CPU [s]",
        "samples/s (wall)",
        "vs ref eigh (CPU)",
        "peak added [MB]",
        "trace [MB]",
        "working [MB]",
        "note",
    ]
    print("## Throughput and memory\n")
    print(table(head, rows))
    print(
        "\n'vs ref eigh': speed relative to the plain per-window eigh reference at the same T, "
        "from process CPU time (unaffected by being descheduled when other jobs compete for "
        "the cores, though shared caches/SMT still slow it; wall time is shown too). "
        "'peak added': (tm) tracemalloc peak in an extra untimed repetition (it does not see "
        "the compiled kernel's own scratch arrays, < 1 MB); (rss) peak RSS added (VmHWM "
        "reset before the run). 'trace' is the returned Trace (kept by batch only; push/step "
        "traces are consumed and dropped); 'working' = peak added - trace. "
        "MB = 2^20 bytes throughout."
    )
    print()

    # ------------------------------------------------------------ comparisons
    cmp_rows = []
    c1_ref_n = min(t_c1, ref_cap)
    c1r = measure("ref_eigh", c1_ref_n, cluster=1)
    c1r_cpu, c1r_wall = c1r["cpu"] * t_c1 / c1_ref_n, c1r["time"] * t_c1 / c1_ref_n
    c1_ratio: dict[str, float] = {}
    for eng in engines:
        c1 = measure("batch", t_c1, cluster=1, engine=eng)
        c1_ratio[eng] = c1r_cpu / c1["cpu"]
        cmp_rows.append(
            [
                "cluster_size=1: batch vs ref eigh (C=1)",
                eng,
                fmt_n(t_c1),
                f"{fmt_rate(t_c1 / c1['time'])} vs {fmt_rate(t_c1 / c1r_wall)}",
                f"{c1_ratio[eng]:.2f}x (wall {c1r_wall / c1['time']:.2f}x)",
                f"{c1['cpu'] / c1['time']:.2f}",
            ]
        )
    capacity = parallel_capacity()
    # best of up to 5 (n_jobs is load-sensitive)
    j1 = measure("batch", t_cmp, min_time=t_rep, engine=main_engine)
    j2 = measure("batch", t_cmp, n_jobs=2, min_time=t_rep, engine=main_engine)
    capacity = min(capacity, parallel_capacity())
    cmp_rows.append(
        [
            "batch n_jobs=2 vs n_jobs=1 (wall)",
            main_engine,
            fmt_n(t_cmp),
            f"{fmt_rate(t_cmp / j2['time'])} vs {fmt_rate(t_cmp / j1['time'])}",
            f"{j1['time'] / j2['time']:.2f}x",
            f"{j2['cpu'] / j2['time']:.2f} (n_jobs=1: {j1['cpu'] / j1['time']:.2f})",
        ]
    )
    pp = measure("batch", t_cmp, method="paper", min_time=t_rep, engine=main_engine)
    cmp_rows.append(
        [
            "batch method='paper' vs 'robust'",
            main_engine,
            fmt_n(t_cmp),
            f"{fmt_rate(t_cmp / pp['time'])} vs {fmt_rate(t_cmp / j1['time'])}",
            f"{j1['cpu'] / pp['cpu']:.2f}x (wall {j1['time'] / pp['time']:.2f}x)",
            f"{pp['cpu'] / pp['time']:.2f}",
        ]
    )
    print("## Comparisons\n")
    print(
        f"(parallel capacity of the machine around the n_jobs runs, two busy processes vs "
        f"one: {capacity:.2f}x; below 2 means other jobs were using a core)\n"
    )
    print(
        table(
            [
                "comparison",
                "engine",
                "T",
                "samples/s wall (A vs B)",
                "speed-up A/B (CPU)",
                "CPU/wall (A)",
            ],
            cmp_rows,
        )
    )
    print()

    # ------------------------------------------------------------ new vs baseline
    base_ratio: dict[str, float] = {}  # path -> speed new/baseline (CPU)
    if baseline is not None:

        def ref_per_sample(n: int) -> float:
            # the reference's cost per window does not depend on T
            return ref_cpu[n][0] if n in ref_cpu else ref_cpu[max(ref_cpu)][0]

        pairs: list[tuple[str, str, int, dict, float]] = [
            ("batch", "batch", n, {}, ref_per_sample(n) * n) for n in sizes
        ]
        pairs.append(("batch cluster_size=1", "batch", t_c1, {"cluster": 1}, c1r_cpu))
        paper_ref = ref_per_sample(t_cmp) * t_cmp
        pairs.append(("batch method='paper'", "batch", t_cmp, {"method": "paper"}, paper_ref))
        pairs.append(("step", "step", step_n, {}, ref_per_sample(min(ref_cpu)) * step_n))
        specs = [
            {
                "kind": kind,
                "n": n,
                "workdir": str(workdir),
                "engine": "compiled",
                "min_time": 0.3 if n <= 1e5 else 0.0,
                "min_reps": 3 if n <= 1e6 else 1,
                **kw,
            }
            for _, kind, n, kw, _ in pairs
        ]
        # one worker per package and round runs every measurement (no RSS is reported here,
        # so they can share a process); the packages alternate, first new then baseline,
        # then the other way round, so that drift in the machine's load hits both
        rounds = max(args.baseline_rounds, 1)
        best = {pkg: [{"cpu": np.inf, "time": np.inf} for _ in pairs] for pkg in ("new", "old")}
        for r in range(rounds):
            order = [("new", None), ("old", baseline)]
            for pkg, path in order if r % 2 == 0 else order[::-1]:
                for b, res in zip(best[pkg], run_worker({"multi": specs}, path), strict=True):
                    b["cpu"], b["time"] = min(b["cpu"], res["cpu"]), min(b["time"], res["time"])
        base_rows = []
        for (label, kind, n, _, ref_t), new, old in zip(
            pairs, best["new"], best["old"], strict=True
        ):
            key = f"{label} T={fmt_n(n)}"
            base_ratio[key] = old["cpu"] / new["cpu"]
            note = ""
            if kind == "step":
                note = (
                    f"{new['cpu'] / n * 1e6:.1f} vs {old['cpu'] / n * 1e6:.1f} us/sample CPU, "
                    "Python floats"
                )
            base_rows.append(
                [
                    label,
                    fmt_n(n),
                    f"{new['cpu']:.3f}",
                    f"{old['cpu']:.3f}",
                    f"{fmt_rate(n / new['time'])} vs {fmt_rate(n / old['time'])}",
                    f"{ref_t / new['cpu']:.2f}x",
                    f"{ref_t / old['cpu']:.2f}x",
                    f"**{old['cpu'] / new['cpu']:.2f}x**",
                    f"{old['time'] / new['time']:.2f}x",
                    note,
                ]
            )
        print(f"## New vs baseline ({baseline})\n")
        print(
            table(
                [
                    "path",
                    "T",
                    "new CPU [s]",
                    "baseline CPU [s]",
                    "samples/s wall (new vs baseline)",
                    "new vs ref eigh (CPU)",
                    "baseline vs ref eigh (CPU)",
                    "speed new/baseline (CPU)",
                    "speed new/baseline (wall)",
                    "note",
                ],
                base_rows,
            )
        )
        print(
            f"\nBoth packages with engine='compiled', in fresh subprocess workers (this "
            f"script, PYTHONPATH={baseline} for the baseline), one per package and round "
            f"running every row; {rounds} rounds, the packages' order alternating, the best "
            "of each kept (each row: warm-up, then best of up to 5 repetitions); 'vs ref eigh' "
            "against the reference timed above in this run. speed new/baseline > 1: the new "
            "code is faster.\n"
        )

    # ------------------------------------------------------------ exactness
    u, y = load(workdir, t_check)
    th_ref, eig_ref = _reference_eigh(u, y)
    ls_ref = _reference_lstsq(u, y)
    sep = eig_ref[:, 0] / eig_ref[:, 1]
    ok = sep < 0.1
    d_ref = eig_ref[:, -1] - eig_ref[:, 0]
    ns = min(step_n, t_check)
    u_l, y_l = u[:ns].tolist(), y[:ns].tolist()
    exact_ok: dict[str, bool] = {}
    robust: dict[str, clpc.Trace] = {}
    paper: dict[str, clpc.Trace] = {}
    print(f"## Exactness (T={fmt_n(t_check)}, {th_ref.shape[0]} updates)\n")
    for eng in engines:

        def make(method: str = "robust", eng: str = eng) -> clpc.CLPC:
            return clpc.CLPC(order=ORDER, window_size=WINDOW, cluster_size=CLUSTER, method=method)

        tr = paper[eng] = make("paper").run(u, y)
        assert len(tr) == th_ref.shape[0], (len(tr), th_ref.shape)
        d_dev = np.abs(tr.D - d_ref) / np.abs(d_ref)
        th_b = tr.theta_estimate
        sign = np.sign(np.sum(th_b * th_ref, axis=1))
        th_dev = np.linalg.norm(th_b - sign[:, None] * th_ref, axis=1)
        eig_dev = np.max(np.abs(tr.eigenvalues - eig_ref) / eig_ref[:, -1:], axis=1)
        tr_r = robust[eng] = make().run(u, y)
        app = make()
        parts = [
            app.push(u[lo : lo + 10000], y[lo : lo + 10000]) for lo in range(0, t_check, 10000)
        ]
        tr_p = clpc.Trace.concat([p for p in parts if len(p)])
        app = make()
        sparts = [app.step(u_k, y_k) for u_k, y_k in zip(u_l, y_l, strict=True)]
        tr_s = clpc.Trace.concat([p for p in sparts if len(p)])
        tr_rs = make().run(u[:ns], y[:ns])
        worst = max(d_dev[ok].max(), th_dev[ok].max()) if ok.any() else float("nan")
        exact_ok[eng] = bool(worst <= 1e-9)
        print(f"engine {eng!r}:")
        print(
            f"- method='paper' batch vs per-window eigh reference, on the {int(ok.sum())} of "
            f"{ok.size} windows with lambda1/lambda2 < 0.1 (sign-aligned):"
        )
        print(
            f"  max rel. deviation of D = {d_dev[ok].max():.2e}; max ||theta - theta_ref|| = "
            f"{th_dev[ok].max():.2e} (target 1e-9: {'MET' if exact_ok[eng] else 'MISSED'})"
        )
        print(
            f"  all windows: max rel. deviation of D = {d_dev.max():.2e}, of the eigenvalues "
            f"(relative to lambda_max) = {eig_dev.max():.2e}; max ||theta - theta_ref|| = "
            f"{th_dev.max():.2e} (ill-separated windows included)"
        )
        print(
            f"- push(10000) vs batch (robust): max |theta diff| = "
            f"{np.abs(tr_p.theta - tr_r.theta).max():.1e}, max |D diff| = "
            f"{np.abs(tr_p.D - tr_r.D).max():.1e}; step (Python floats) vs batch on "
            f"{fmt_n(ns)} samples: max |theta diff| = "
            f"{np.abs(tr_s.theta - tr_rs.theta).max():.1e}, max |D diff| = "
            f"{np.abs(tr_s.D - tr_rs.D).max():.1e}"
        )

    def agreement(a: dict, b: dict) -> str:
        if a["D"].shape != b["D"].shape:
            return f"different numbers of updates ({a['D'].size} vs {b['D'].size})"
        d_rel = np.abs(a["D"] - b["D"]) / np.abs(b["D"])
        return (
            f"max |theta diff| = {np.abs(a['theta'] - b['theta']).max():.1e}, max "
            f"|theta_estimate diff| = "
            f"{np.abs(a['theta_estimate'] - b['theta_estimate']).max():.1e}, max rel. |D "
            f"diff| = {d_rel.max():.1e}; 'accepted' agrees on "
            f"{100 * np.mean(a['accepted'] == b['accepted']):.2f} % of the updates"
        )

    def arrays(tr: clpc.Trace) -> dict:
        return {k: np.asarray(getattr(tr, k)) for k in ("theta", "theta_estimate", "D", "accepted")}

    if python_max > 0:
        n_py = min(t_check, 5000)
        out = workdir / "python-trace.npz"
        spec_py = {"workdir": str(workdir), "n": n_py, "engine": "python", "out": str(out)}
        run_worker(spec_py, flag="--dump-worker")  # NUMBA_DISABLE_JIT=1 in the worker
        with np.load(out) as z:
            slow = {k: z[k] for k in z.files}
        for method in ("robust", "paper"):
            a = {k[len(method) + 1 :]: v for k, v in slow.items() if k.startswith(method + "_")}
            b = clpc.CLPC(order=ORDER, window_size=WINDOW, cluster_size=CLUSTER, method=method).run(
                u[:n_py], y[:n_py]
            )
            print(
                f"- python (NUMBA_DISABLE_JIT=1) vs compiled ({method} batch, "
                f"T={fmt_n(n_py)}): {agreement(a, arrays(b))}"
            )
    if baseline is not None:
        out = workdir / "baseline-trace.npz"
        run_worker(
            {"workdir": str(workdir), "n": t_check, "engine": "compiled", "out": str(out)},
            pythonpath=baseline,
            flag="--dump-worker",
        )
        with np.load(out) as z:
            old = {k: z[k] for k in z.files}
        for method, trs in (("robust", robust), ("paper", paper)):
            b = {k[len(method) + 1 :]: v for k, v in old.items() if k.startswith(method + "_")}
            print(
                f"- new vs baseline (compiled engines, {method} batch, T={fmt_n(t_check)}): "
                f"{agreement(arrays(trs[main_engine]), b)}"
            )
    err_ls = np.linalg.norm(ls_ref[-100:].mean(0) - _true_theta())
    errs = ", ".join(
        f"robust LPC ({eng}) {np.linalg.norm(tr.theta_estimate[-100:].mean(0) - _true_theta()):.3f}"
        for eng, tr in robust.items()
    )
    print(
        f"- sanity: mean of the last 100 windows vs the true theta: {errs}, "
        f"windowed LS {err_ls:.3f}\n"
    )

    # ------------------------------------------------------------ targets
    def get(label: str, eng: str, n: int) -> dict | None:
        return results.get((label, eng, n))

    def status(flags: dict[str, bool | str | None]) -> str:
        """'MET / MISSED' in the order of ``engines`` ('-': not measured)."""

        def word(v: bool | str | None) -> str:
            if v is None:
                return "-"
            return v if isinstance(v, str) else ("MET" if v else "MISSED")

        return " / ".join(word(flags.get(e)) for e in engines)

    tgt = []
    # batch vs ref at T <= 1e6
    t6 = max([n for n in sizes if n <= 1e6 and n in ref_cpu], default=None)
    if t6 is not None:
        ref6 = get("ref eigh", "-", t6)
        cells, flags = [], {}
        for eng in engines:
            b = get("batch", eng, t6)
            if b is None:
                cells.append("not run")
                flags[eng] = None
                continue
            wall_ratio = ref6["wall"] / b["wall"] if ref6 else float("nan")
            cells.append(f"{b['ratio']:.1f}x CPU ({wall_ratio:.1f}x wall) at T={fmt_n(t6)}")
            flags[eng] = b["ratio"] >= 6
        tgt.append(
            ["batch >= 6x the per-window reference at T=1e6 (aim 20x)", *cells, status(flags)]
        )
    tgt.append(
        [
            "cluster_size=1: batch >= 3x the reference",
            *[f"{c1_ratio[e]:.2f}x CPU at T={fmt_n(t_c1)}" for e in engines],
            status({e: c1_ratio[e] >= 3 for e in engines}),
        ]
    )
    cells, flags = [], {}
    for eng in engines:
        slow = {
            n: get("push(10000)", eng, n)["cpu_t"] / get("batch", eng, n)["cpu_t"]
            for n in sizes
            if get("push(10000)", eng, n) and get("batch", eng, n)
        }
        cells.append(
            "push/batch time = " + ", ".join(f"{v:.2f} (T={fmt_n(n)})" for n, v in slow.items())
        )
        flags[eng] = max(slow.values()) <= 2 if slow else None
    tgt.append(["push(10000) within 2x of batch", *cells, status(flags)])
    cells, flags = [], {}
    for eng in engines:
        st = get("step", eng, step_n)
        us = st["cpu"] / step_n * 1e6
        cells.append(f"{us:.1f} us CPU ({st['time'] / step_n * 1e6:.1f} us wall), Python floats")
        flags[eng] = us <= 10
    tgt.append(["step <= 10 us per sample amortised", *cells, status(flags)])
    cells, flags = [], {}
    for eng in engines:
        ms = {n: mem(get("push(10000)", eng, n)) for n in sizes if get("push(10000)", eng, n)}
        cells.append(f"max {max(ms.values()):.0f} MB for T = {fmt_n(min(ms))} .. {fmt_n(max(ms))}")
        flags[eng] = max(ms.values()) <= 100
    tgt.append(["memory added <= 100 MB whatever T: streaming push(10000)", *cells, status(flags)])
    cells, flags = [], {}
    for eng in engines:
        bs = {n: get("batch", eng, n) for n in sizes if get("batch", eng, n)}
        big = max(bs)
        work = max(mem(r) - r["trace_mb"] for r in bs.values())
        added = {n: mem(r) for n, r in bs.items()}
        over = [n for n, v in added.items() if v > 100]
        br = bs[big]
        cell = (
            f"working (added - trace) <= {work:.0f} MB at every T (bounded); added "
            f"{added[big]:.0f} MB at T={fmt_n(big)}, of which the returned trace is "
            f"{br['trace_mb']:.0f} MB ({br['trace_mb'] * 2**20 / max(br['updates'], 1):.0f} "
            "bytes per update, grows with T)"
        )
        if over:
            cell += (
                f"; added > 100 MB at T = {', '.join(fmt_n(n) for n in over)} because the "
                "returned trace grows with T: for bounded memory use push + "
                "clpc.appraiser.tracefile.TraceWriter"
            )
        cells.append(cell)
        flags[eng] = not over
    tgt.append(["memory added <= 100 MB whatever T: batch run()", *cells, status(flags)])
    cw = j2["cpu"] / j2["time"]
    nj = (
        f"CPU/wall {cw:.2f}, wall speed-up {j1['time'] / j2['time']:.2f}x at "
        f"T={fmt_n(t_cmp)} (machine capacity then {capacity:.2f}x)"
    )
    tgt.append(
        [
            "both cores used with n_jobs=2",
            *[nj if e == main_engine else "not measured" for e in engines],
            status(
                {
                    main_engine: "MET" if cw >= 1.6 else ("PARTLY" if cw > 1.15 else "MISSED"),
                }
            ),
        ]
    )
    tgt.append(
        [
            "exactness: method='paper' D and theta vs the reference <= 1e-9 (separated windows)",
            *[f"T={fmt_n(t_check)}, see Exactness" for _ in engines],
            status(exact_ok),
        ]
    )
    if base_ratio:
        low = min(base_ratio.values())
        tgt.append(
            [
                "batch and step speed not lower than the baseline (same run, CPU)",
                "speed new/baseline: "
                + ", ".join(f"{v:.2f}x ({k})" for k, v in base_ratio.items()),
                "MET" if low >= 1.0 else ("WITHIN NOISE (>= 0.95)" if low >= 0.95 else "MISSED"),
            ]
        )
    print("## Targets (issue 'CLPC appraiser', item 7)\n")
    print(
        table(
            [
                "target",
                *[eng_name(e) + " engine" for e in engines],
                "status (" + " / ".join(engines) + ")",
            ],
            tgt,
        )
    )
    print()

    # ------------------------------------------------------------ huge
    if args.huge:
        n_h, chunk = int(args.huge_samples), int(args.huge_chunk)
        path = workdir / "huge.npy"
        g0 = time.perf_counter()
        if not path.exists() or np.load(path, mmap_mode="r").shape[0] != n_h:
            generate_npy(path, n_h)
        gen_t = time.perf_counter() - g0
        cmd = [
            sys.executable,
            os.path.abspath(__file__),
            "--huge-worker",
            json.dumps({"path": str(path), "chunk": chunk, "engine": sel_engine}),
        ]
        proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
        if proc.returncode != 0:
            raise RuntimeError(proc.stderr)
        h = json.loads(proc.stdout.strip().splitlines()[-1])
        print(
            f"## Huge record: {fmt_n(n_h)} samples from a .npy file (mmap_mode='r'), "
            f"push in chunks of {fmt_n(chunk)}, engine {h['engine']!r}\n"
        )
        print(
            table(
                [
                    "samples",
                    "file [GB]",
                    "time [s]",
                    "samples/s",
                    "updates",
                    "RSS before [MB]",
                    "peak RSS [MB]",
                    "peak added [MB]",
                    "max RssAnon [MB]",
                    "max RssFile [MB]",
                ],
                [
                    [
                        fmt_n(h["n"]),
                        f"{path.stat().st_size / 1e9:.2f}",
                        f"{h['time']:.1f}",
                        fmt_rate(h["n"] / h["time"]),
                        str(h["updates"]),
                        f"{h['base_rss_mb']:.0f}",
                        f"{h['peak_rss_mb']:.0f}",
                        f"{h['peak_rss_mb'] - h['base_rss_mb']:.0f}",
                        f"{h['max_rss_anon_mb']:.0f}",
                        f"{h['max_rss_file_mb']:.0f}",
                    ]
                ],
            )
        )
        print(
            f"\n(file generated in {gen_t:.0f} s; consumed pages of the mapping are released "
            "with madvise(MADV_DONTNEED) after each chunk, so RSS shows the working set, not "
            "the page cache; RssAnon/RssFile sampled after each chunk)\n"
        )

    if not args.keep_data and args.workdir is None:
        shutil.rmtree(workdir, ignore_errors=True)
    print(
        f"(total {time.perf_counter() - t_start:.0f} s; load average at the end: "
        f"{' '.join(f'{x:.2f}' for x in os.getloadavg())})"
    )
    return 0


def _true_theta() -> np.ndarray:
    theta = np.concatenate([DEN, -NUM])
    return theta / np.linalg.norm(theta)


if __name__ == "__main__":
    sys.exit(main())
