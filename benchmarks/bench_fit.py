"""Batch paths against the record length: time, peak memory and the ratio to numpy's lstsq.

Each row is one path at one record length T, run in this process after one warm-up on a
short record: ``LPC(order=2).fit``, ``ARX(order=2).fit``, ``OE(order=2).fit``, the evidence
a fit offers on demand (``model.assess()``: held-out refit, residual tests, jackknife),
``predict(k)`` at a short and a long horizon, and ``identify`` with order, delay and
estimator automatic (``--identify``, the slow one). The references, timed in the same run on
the same SISO lag matrix: ``numpy.linalg.lstsq`` of ``y(n)`` on the five other lag entries
("x lstsq"), and the bare LPC solve, ``numpy.linalg.svd`` of the centered lag matrix ("x svd").
Peak memory is the largest allocation traced by ``tracemalloc`` (numpy reports its arrays to
it) during the call, in MB; the lag matrix itself is 8 * 6 * T bytes (48 MB at 1e6).

Usage::

    python benchmarks/bench_fit.py                      # T = 5e3, 1e5, 1e6
    python benchmarks/bench_fit.py --sizes 5000 10000000
    python benchmarks/bench_fit.py --identify --sizes 3000 1000000
"""

from __future__ import annotations

import argparse
import time
import tracemalloc
from collections.abc import Callable
from typing import Any

import numpy as np

import clpc


def record(n: int, seed: int = 0) -> clpc.IOData:
    """A second-order plant with white input and output noise (SNR about 30 dB)."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = clpc.simulate_arx([1, -1.5, 0.7], [0.5, 0.2, 0.1], u) + 0.05 * rng.standard_normal(n)
    return clpc.IOData(u, y, dt=0.01)


def measure(fn: Callable[[], Any], repeat: int) -> tuple[float, float]:
    """Best wall time [s] of ``repeat`` calls and the peak traced memory [MB] of one."""
    tracemalloc.start()
    fn()
    peak = tracemalloc.get_traced_memory()[1] / 1e6
    tracemalloc.stop()
    best = np.inf
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best, peak


def lstsq_reference(data: clpc.IOData) -> Callable[[], Any]:
    """``lstsq`` of ``y(n)`` on the other entries of the order-2 lag vector."""
    u, y = data.u[:, 0], data.y[:, 0]
    rows = np.column_stack([y[2:], y[1:-1], y[:-2], u[2:], u[1:-1], u[:-2]])
    return lambda: np.linalg.lstsq(rows[:, 1:], rows[:, 0], rcond=None)


def svd_reference(data: clpc.IOData) -> Callable[[], Any]:
    """The bare LPC solve: the SVD of the centered order-2 lag matrix."""
    u, y = data.u[:, 0], data.y[:, 0]
    rows = np.column_stack([y[2:], y[1:-1], y[:-2], u[2:], u[1:-1], u[:-2]])
    return lambda: np.linalg.svd(rows - rows.mean(axis=0), full_matrices=False)


def paths(data: clpc.IOData, with_identify: bool) -> dict[str, Callable[[], Any]]:
    """The batch paths measured on ``data``."""
    u, y = data.u[:, 0], data.y[:, 0]
    model = clpc.LPC(order=2).fit(data)
    out: dict[str, Callable[[], Any]] = {
        "LPC fit": lambda: clpc.LPC(order=2).fit(data),
        "ARX fit": lambda: clpc.ARX(order=2).fit(data),
        "LPC fit + assess": lambda: clpc.LPC(order=2).fit(data).assess(),
        "predict k=10": lambda: model.predict(u, y, k=10),
        "predict k=T/10": lambda: model.predict(u, y, k=max(1, data.n_samples // 10)),
    }
    if data.n_samples <= 200_000:  # OE's search: seconds per 1e5 samples
        out["OE fit"] = lambda: clpc.OE(order=2).fit(data)
    if with_identify:
        out["identify auto"] = lambda: clpc.identify(
            data, estimator="auto", order="auto", nk="auto"
        )
    return out


def main() -> None:
    """Print one table row per path and record length."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[5_000, 100_000, 1_000_000])
    parser.add_argument("--identify", action="store_true", help="also identify (slow)")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    clpc.LPC(order=2).fit(record(2000)).assess()  # warm-up: imports, first calls
    head = f"{'path':<18} {'T':>9} {'time [s]':>10} {'peak [MB]':>10} {'x lstsq':>8} {'x svd':>8}"
    print(head)
    for n in args.sizes:
        data = record(n)
        ref, _ = measure(lstsq_reference(data), args.repeat)
        svd, _ = measure(svd_reference(data), args.repeat)
        print(f"{'numpy lstsq':<18} {n:>9} {ref:>10.4f} {'':>10} {1.0:>8.2f} {ref / svd:>8.2f}")
        print(f"{'numpy svd':<18} {n:>9} {svd:>10.4f} {'':>10} {svd / ref:>8.2f} {1.0:>8.2f}")
        for name, fn in paths(data, args.identify).items():
            repeat = 1 if name in ("identify auto", "OE fit") else args.repeat
            seconds, peak = measure(fn, repeat)
            ratios = f"{seconds / ref:>8.2f} {seconds / svd:>8.2f}"
            print(f"{name:<18} {n:>9} {seconds:>10.4f} {peak:>10.1f} {ratios}")


if __name__ == "__main__":
    main()
