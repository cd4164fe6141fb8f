"""``clpc.Subspace`` against nfoursid and SIPPY (``sippy_unipi``), and against the record length.

Three tables, printed as Markdown:

1. **Noisy data, known truth.** A 4th-order SISO plant with two lightly damped modes
   (poles ``0.98 e^{+-0.3j}``, ``0.95 e^{+-1.2j}``), white input, white output noise at
   20 dB SNR, ``T = 2e3`` and ``2e4``, several seeds: the relative error of the frequency
   response over 400 frequencies (``||G_hat - G|| / ||G||``), the largest pole error
   (poles matched by sorting) and the fit time, each the mean over the seeds. Every
   estimator is given the true order 4 and 10 block rows (``horizon``, ``num_block_rows``,
   ``SS_f``); ``clpc auto`` chooses its own order (the count of seeds where it chose 4).
2. **Shipped records** (``clpc.datasets.load``): fitted on the first two thirds, scored by the
   free-run fit % of the last third (every model simulated from rest over the whole record,
   means of the fitting part removed for the peers and added back), all at the order
   ``Subspace(order="auto")`` chose on the fitting part; "clpc auto, D" is
   ``Subspace(feedthrough=True)`` at its own order (nfoursid always estimates ``D``, the
   others here do not).
3. **Scaling.** ``Subspace.fit`` at ``T = 1e4, 1e5, 1e6`` (order 4 and ``"auto"``): best
   wall time of a few calls and the ``tracemalloc`` peak [MB] of one (the record itself,
   ``16 T`` bytes, is built before tracing); the peers at the sizes they reach
   (``--peer-sizes``).

The peers are never clpc dependencies; install them in a separate environment::

    python3.11 -m venv /work/venv-peers
    /work/venv-peers/bin/pip install sippy_unipi nfoursid
    PYTHONPATH=src OPENBLAS_NUM_THREADS=1 /work/venv-peers/bin/python \\
        benchmarks/subspace_reference.py

(``OPENBLAS_NUM_THREADS=1``: on a shared two-core machine a threaded ``dgeqrf`` of a tall,
narrow matrix can be 100x slower than one thread when the cores are busy.) A peer that is
not installed is skipped.
"""

from __future__ import annotations

import argparse
import time
import tracemalloc
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy import signal

import clpc
from clpc.lpc.subspace import Subspace

_POLES = [0.98 * np.exp(0.3j), 0.95 * np.exp(1.2j)]
DEN = np.real(np.poly(np.r_[_POLES, np.conj(_POLES)]))
NUM = np.array([0.0, 0.5, -0.3, 0.2, 0.1])
GRID = np.linspace(0.0, np.pi, 400, endpoint=False)
FAST = {"uncertainty": False, "assess": False}
BLOCK_ROWS = 10


def record(n: int, seed: int, snr_db: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    """The 4th-order plant's input and noisy output."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = signal.lfilter(NUM, DEN, u)
    return u, y + rng.standard_normal(n) * np.std(y) * 10 ** (-snr_db / 20)


# ------------------------------------------------------------------ the estimators
StateSpace = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def clpc_fit(u: np.ndarray, y: np.ndarray, order: Any) -> StateSpace:
    """``Subspace(order=order, horizon=10)`` (``"auto"``: default horizon)."""
    horizon = None if order == "auto" else BLOCK_ROWS
    ss = Subspace(order=order, horizon=horizon, **FAST).fit(u, y).info["state_space"]
    return ss["A"], ss["B"], ss["C"], ss["D"]


def nfoursid_fit(u: np.ndarray, y: np.ndarray, order: int) -> StateSpace:
    """nfoursid's PO-MOESP (A, C) and least squares on its state sequence (B, D)."""
    import pandas as pd
    from nfoursid.nfoursid import NFourSID

    u2, y2 = np.atleast_2d(u.T).T, np.atleast_2d(y.T).T
    cols_u = [f"u{i}" for i in range(u2.shape[1])]
    cols_y = [f"y{i}" for i in range(y2.shape[1])]
    frame = pd.DataFrame(np.hstack([u2, y2]), columns=cols_u + cols_y)
    est = NFourSID(frame, output_columns=cols_y, input_columns=cols_u, num_block_rows=BLOCK_ROWS)
    est.subspace_identification()
    ss, _ = est.system_identification(rank=order)
    return ss.a, ss.b, ss.c, ss.d


def sippy_fit(method: str) -> Callable[[np.ndarray, np.ndarray, int], StateSpace]:
    """SIPPY's N4SID or MOESP at a fixed order (``SS_f`` future rows, D = 0)."""

    def fit(u: np.ndarray, y: np.ndarray, order: int) -> StateSpace:
        from sippy_unipi import system_identification

        model = system_identification(
            np.atleast_2d(y.T), np.atleast_2d(u.T), method,
            SS_f=BLOCK_ROWS, SS_fixed_order=order, SS_D_required=False,
        )  # fmt: skip
        return model.A, model.B, model.C, model.D

    return fit


def available() -> dict[str, Callable[[np.ndarray, np.ndarray, Any], StateSpace]]:
    """The estimators whose packages import."""
    out: dict[str, Callable[[np.ndarray, np.ndarray, Any], StateSpace]] = {"clpc": clpc_fit}
    try:
        import nfoursid  # noqa: F401

        out["nfoursid"] = nfoursid_fit
    except ImportError:
        print("nfoursid not installed: skipped")
    try:
        import sippy_unipi  # noqa: F401

        out["SIPPY N4SID"] = sippy_fit("N4SID")
        out["SIPPY MOESP"] = sippy_fit("MOESP")
    except ImportError:
        print("sippy_unipi not installed: skipped")
    return out


# ------------------------------------------------------------------------ scoring
def response(ss: StateSpace, output: int = 0, input: int = 0) -> np.ndarray:
    """``G(e^{jw})`` of one channel on :data:`GRID`."""
    a, b, c, d = (np.atleast_2d(np.asarray(x, dtype=float)) for x in ss)
    z = np.exp(1j * GRID)
    eye = np.eye(a.shape[0])
    return np.array(
        [c[output] @ np.linalg.solve(zk * eye - a, b[:, input]) + d[output, input] for zk in z]
    )


def pole_error(ss: StateSpace) -> float:
    """Largest distance between the sorted estimated poles and the true ones."""
    est = np.sort_complex(np.linalg.eigvals(np.atleast_2d(ss[0])))
    truth = np.sort_complex(np.roots(DEN))
    if est.size != truth.size:
        return float("nan")
    return float(np.max(np.abs(est - truth)))


def fit_pct(y: np.ndarray, sim: np.ndarray) -> float:
    """Free-run fit % (mean over the outputs)."""
    y, sim = np.atleast_2d(y.T).T, np.atleast_2d(sim.T).T
    return float(np.mean([clpc.fit_percent(y[:, j], sim[:, j]) for j in range(y.shape[1])]))


def free_run(ss: StateSpace, u: np.ndarray) -> np.ndarray:
    """Simulation from rest, shape (T, n_outputs)."""
    a, b, c, d = (np.atleast_2d(np.asarray(x, dtype=float)) for x in ss)
    _, y, _ = signal.dlsim((a, b, c, d, 1.0), u)
    return np.atleast_2d(y.T).T


# ------------------------------------------------------------------------- tables
def noisy_table(fits: dict[str, Any], sizes: list[int], seeds: int) -> None:
    print("\n### Noisy data (20 dB SNR), true order 4\n")
    print("| estimator | T | response error | pole error | seconds | order 4 chosen |")
    print("|---|---:|---:|---:|---:|---:|")
    truth = signal.freqz(NUM, DEN, worN=GRID)[1]
    rows = [(name, fit, 4) for name, fit in fits.items()] + [("clpc auto", clpc_fit, "auto")]
    for n in sizes:
        for name, fit, order in rows:
            errs, poles, secs, fours = [], [], [], 0
            for seed in range(seeds):
                u, y = record(n, 1000 + seed)
                start = time.perf_counter()
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    ss = fit(u, y, order)
                secs.append(time.perf_counter() - start)
                errs.append(np.linalg.norm(response(ss) - truth) / np.linalg.norm(truth))
                poles.append(pole_error(ss))
                fours += np.asarray(ss[0]).shape[0] == 4
            print(
                f"| {name} | {n} | {np.mean(errs):.2e} | {np.nanmean(poles):.2e} | "
                f"{np.median(secs):.4f} | {fours}/{seeds} |"
            )


def record_table(fits: dict[str, Any], names: list[str]) -> None:
    print("\n### Shipped records: free-run fit % on the last third\n")
    header = " | ".join(fits)
    print(f"| record | order | clpc auto | clpc auto, D | {header} |")
    print("|---|---:|---:|---:|" + "---:|" * len(fits))
    for name in names:
        data = clpc.datasets.load(name)
        data = data[0] if isinstance(data, tuple) else data
        split = round(data.n_samples * 2 / 3)
        fit_part = data[:split]
        model = Subspace(**FAST).fit(fit_part)
        order = model.info["order"]
        sim = np.asarray(model.simulate(data.u)).reshape(data.y.shape)
        cells = [f"{fit_pct(data.y[split:], sim[split:]):.1f}"]
        with_d = Subspace(feedthrough=True, **FAST).fit(fit_part)
        sim = np.asarray(with_d.simulate(data.u)).reshape(data.y.shape)
        cells.append(f"{fit_pct(data.y[split:], sim[split:]):.1f} (n={with_d.info['order']})")
        u_mean, y_mean = fit_part.u.mean(axis=0), fit_part.y.mean(axis=0)
        for fit in fits.values():
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    ss = fit(fit_part.u - u_mean, fit_part.y - y_mean, order)
                    sim = free_run(ss, data.u - u_mean) + y_mean
                    cells.append(f"{fit_pct(data.y[split:], sim[split:]):.1f}")
            except Exception as exc:  # a peer that fails on a record
                cells.append(f"failed ({type(exc).__name__})")
        print(
            f"| {name} ({data.n_inputs}x{data.n_outputs}) | {order} | " + " | ".join(cells) + " |"
        )


def measure(fn: Callable[[], Any], repeat: int) -> tuple[float, float, float]:
    """Best wall and CPU time [s] of ``repeat`` calls, peak traced memory [MB] of one."""
    tracemalloc.start()
    fn()
    peak = tracemalloc.get_traced_memory()[1] / 1e6
    tracemalloc.stop()
    wall = cpu = np.inf
    for _ in range(repeat):
        start, start_cpu = time.perf_counter(), time.process_time()
        fn()
        wall = min(wall, time.perf_counter() - start)
        cpu = min(cpu, time.process_time() - start_cpu)
    return wall, cpu, peak


def scaling_table(fits: dict[str, Any], sizes: list[int], peer_sizes: list[int]) -> None:
    print("\n### Scaling: fit time and tracemalloc peak\n")
    print("| estimator | T | seconds | CPU seconds | peak MB | record MB |")
    print("|---|---:|---:|---:|---:|---:|")
    for n in sizes:
        u, y = record(n, 7)
        data = clpc.IOData(u, y)
        repeat = 3 if n <= 100_000 else 1
        runs: list[tuple[str, Callable[[], Any], int]] = [
            (f"clpc order={o}", lambda o=o, d=data: Subspace(order=o, **FAST).fit(d), repeat)
            for o in (4, "auto")
        ]
        if n in peer_sizes:
            runs += [
                (f"{name} order=4", lambda f=fit, u=u, y=y: f(u, y, 4), 1)
                for name, fit in fits.items()
                if name != "clpc"
            ]
        for name, fn, times in runs:
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    wall, cpu, peak = measure(fn, times)
            except MemoryError as exc:  # nfoursid's N x N SVD
                tracemalloc.stop()
                print(f"| {name} | {n} | failed: {str(exc)[:60]} | | | {16 * n / 1e6:.1f} |")
                continue
            print(f"| {name} | {n} | {wall:.3f} | {cpu:.3f} | {peak:.1f} | {16 * n / 1e6:.1f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[2000, 20000])
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument(
        "--records", nargs="+", default=["dryer", "exchanger", "robot_arm", "cd_player_arm"]
    )
    parser.add_argument("--scale", type=int, nargs="+", default=[10_000, 100_000, 1_000_000])
    parser.add_argument("--peer-sizes", type=int, nargs="*", default=[10_000, 100_000])
    parser.add_argument(
        "--tables", nargs="+", default=["noisy", "records", "scale"],
        choices=["noisy", "records", "scale"],
    )  # fmt: skip
    args = parser.parse_args()
    fits = available()
    if "noisy" in args.tables:
        noisy_table(fits, args.sizes, args.seeds)
    if "records" in args.tables:
        record_table(fits, args.records)
    if "scale" in args.tables:
        scaling_table(fits, args.scale, args.peer_sizes)


if __name__ == "__main__":
    main()
