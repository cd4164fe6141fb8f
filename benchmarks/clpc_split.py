"""Where a CLPC window's time goes: the kernel's stages timed one by one, and the eigen-solve.

Run as ``python benchmarks/bench_clpc.py --split`` (or this file directly). The data are
``clpc_table.record`` (the ``bench_clpc.py`` process), ``N = 2`` (``p = 6``), ``W = 201``,
robust method, the kernel's own compiled functions (:mod:`clpc.appraiser.kernel`) called
from a compiled harness that stops after stage 1, 2, ... of the per-window loop of
``solve_windows``; a stage's cost is the difference of consecutive stops (CPU time per
window, best of 30 calls of 4000 windows, the stops timed in turn; the harness's loop
matches ``solve_windows`` line for line). The last
part times the alternative the issue suggested for the eigen-solve: cyclic Jacobi sweeps
started from the previous window's eigenvectors (``B = V^T A V``, sweeps until every
off-diagonal entry is below ``eps * max |B_ii|``), against the kernel's Householder + QL
(``small_eigh.sym_eig``) on the same matrices, with the eigenvalues compared; and LAPACK's
``dsyev`` called straight from compiled code (scipy's ``cython_lapack`` through
``numba.extending.get_cython_function_address``, work space allocated once) on them too.
"""

from __future__ import annotations

import ctypes
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numba
import numpy as np
from numba.extending import get_cython_function_address

sys.path.insert(0, str(Path(__file__).parent))
from clpc_table import WINDOW, record

from clpc.appraiser import blocks, row_sums, segments, window_chains
from clpc.appraiser import kernel as K
from clpc.core.rules import is_excited
from clpc.core.small_eigh import sym_eig


@numba.njit
def stages(samples, first_row, windows, plan, s, upto):
    """``solve_windows`` of equation 0 stopped after stage ``upto`` (1 .. 6)."""
    j0, count = windows
    p = plan.chan.shape[1]
    window, cluster, size = plan.window, plan.cluster, plan.block
    first = -first_row
    b_lo = -(-max(0, cluster * j0 - window) // size)
    n_blocks = max(0, cluster * (j0 + count - 1) // size - b_lo)
    b_mean, b_scat, b_step = np.empty((n_blocks, p)), np.empty((n_blocks, p, p)), np.empty(n_blocks)
    t_mean, t_scat = np.empty((1, p)), np.empty((1, p, p))
    h_mean, h_scat = np.empty((1, p)), np.empty((1, p, p))
    mean, scat, z = np.empty(p), np.empty((p, p)), np.empty((size, p))
    seg = segments.segment_blocks(window, size)
    chain, rows = window_chains.chains_of(window_chains.new_chains(plan), 0)
    chained = size > cluster
    work, theta, eig = K.new_work(p), np.empty(p), np.empty(p)
    chan, lag = plan.chan[0], plan.lag[0]
    acc = 0.0
    for b in range(n_blocks):
        lo = (b_lo + b) * size
        blocks.piece_stats(samples, chan, lag, first, (lo, lo + size), z, (b_mean[b], b_scat[b]))
        b_step[b] = blocks.piece_step(samples, chan[0], first, (lo, lo + size))
    if upto < 2:
        return acc
    for w in range(count):
        e = cluster * (j0 + w)
        start = max(0, e - window)
        full_lo = -(-start // size)
        full_hi = max(e // size, full_lo)
        t_end = min(full_lo * size, e)
        h_start = min(max(full_hi * size, t_end), e)
        t_size, h_size = t_end - start, e - h_start
        where = (chan, lag, first)
        tail = (float(t_size), t_mean, t_scat, 0)
        if t_size > 0 and chained and t_end == (start // size + 1) * size:
            i_t = row_sums.tail_row(samples, where, start, size, rows)
            tail = (float(t_size), rows.tail_mean, rows.tail_scat, i_t)
        elif t_size > 0:
            blocks.piece_stats(samples, chan, lag, first, (start, t_end), z, (t_mean[0], t_scat[0]))
        head = (float(h_size), h_mean, h_scat, 0)
        if h_size > 0 and chained and h_start % size == 0:
            i_h = row_sums.head_row(samples, where, e, size, rows)
            head = (float(h_size), rows.head_mean, rows.head_scat, i_h)
        elif h_size > 0:
            blocks.piece_stats(samples, chan, lag, first, (h_start, e), z, (h_mean[0], h_scat[0]))
        step = blocks.piece_step(samples, chan[0], first, (start, t_end))
        step = min(step, blocks.piece_step(samples, chan[0], first, (h_start, e)))
        acc += tail[1][tail[3], 0] + head[1][head[3], 0] + step
        if upto < 3:
            continue
        n_s, i_s, n_p, i_p, f_step = segments.full_blocks(
            (b_mean, b_scat, b_step, b_lo, size), (full_lo, full_hi), (seg, chain)
        )
        step = min(step, f_step)
        pieces = (
            tail,
            (n_s, chain.suffix_mean, chain.suffix_scat, i_s),
            (n_p, chain.prefix_mean, chain.prefix_scat, i_p),
            head,
        )
        n_w = segments.merge_pieces(pieces, chain.dev, (mean, scat))
        acc += scat[0, 0] + step
        if upto < 4:
            continue
        if upto == 4:  # the eigen-solve alone
            sym_eig(scat, work.vals, work.vecs, work.ework, True)
            acc += work.vals[0]
            continue
        res = K.solve_one(scat, mean, n_w, plan, s, work, (theta, eig))
        acc += res[0]
        if upto < 6:
            continue
        acc += is_excited(scat, n_w, step, s.n_out_cols)
    return acc


@numba.njit
def warm_jacobi(mats):
    """Eigenvalues of each matrix by Jacobi sweeps from the previous one's eigenvectors."""
    n, p = mats.shape[0], mats.shape[1]
    v, b, tmp = np.empty((p, p)), np.empty((p, p)), np.empty((p, p))
    d, e = np.empty(p), np.empty(p)
    sym_eig(mats[0], d, v, e, True)  # a cold start for the first
    vals = np.empty((n, p))
    sweeps = 0
    for j in range(n):
        a = mats[j]
        for i in range(p):
            for k in range(p):
                acc = 0.0
                for m in range(p):
                    acc += a[i, m] * v[m, k]
                tmp[i, k] = acc
        for i in range(p):
            for k in range(p):
                acc = 0.0
                for m in range(p):
                    acc += v[m, i] * tmp[m, k]
                b[i, k] = acc
        norm = 0.0
        for i in range(p):
            norm = max(norm, abs(b[i, i]))
        for _ in range(30):
            off = 0.0
            for i in range(p):
                for k in range(i + 1, p):
                    off = max(off, abs(b[i, k]))
            if off <= 2.0**-52 * norm:
                break
            sweeps += 1
            for i in range(p - 1):
                for k in range(i + 1, p):
                    if b[i, k] == 0.0:
                        continue
                    th = (b[k, k] - b[i, i]) / (2.0 * b[i, k])
                    t = 1.0 / (abs(th) + math.sqrt(th * th + 1.0))
                    t = -t if th < 0 else t
                    c = 1.0 / math.sqrt(t * t + 1.0)
                    sn = t * c
                    for m in range(p):
                        bi, bk = b[m, i], b[m, k]
                        b[m, i], b[m, k] = c * bi - sn * bk, sn * bi + c * bk
                    for m in range(p):
                        bi, bk = b[i, m], b[k, m]
                        b[i, m], b[k, m] = c * bi - sn * bk, sn * bi + c * bk
                    for m in range(p):
                        vi, vk = v[m, i], v[m, k]
                        v[m, i], v[m, k] = c * vi - sn * vk, sn * vi + c * vk
        for i in range(p):
            vals[j, i] = b[i, i]
    return vals, sweeps


@numba.njit
def cold_ql(mats):
    """Eigenvalues and vectors of each matrix by the kernel's solver (values returned)."""
    n, p = mats.shape[0], mats.shape[1]
    d, e, v = np.empty(p), np.empty(p), np.empty((p, p))
    vals = np.empty((n, p))
    for j in range(n):
        sym_eig(mats[j], d, v, e, True)
        vals[j] = d
    return vals


_VOID = ctypes.c_void_p
#: LAPACK's dsyev (jobz, uplo, n, a, lda, w, work, lwork, info), all by pointer
_DSYEV = ctypes.CFUNCTYPE(None, *([_VOID] * 9))(
    get_cython_function_address("scipy.linalg.cython_lapack", "dsyev")
)


@numba.njit
def lapack_dsyev(mats):
    """Eigenvalues and vectors of each matrix by LAPACK's dsyev (work space allocated once)."""
    n, p = mats.shape[0], mats.shape[1]
    a, d, work = np.empty((p, p)), np.empty(p), np.empty(64 * p)
    jobz, uplo = np.array([ord("V")], np.int8), np.array([ord("L")], np.int8)
    size, lwork, info = np.array([p], np.int32), np.array([64 * p], np.int32), np.zeros(1, np.int32)
    vals = np.empty((n, p))
    for j in range(n):
        for i in range(p):
            for k in range(p):
                a[i, k] = mats[j, i, k]
        _DSYEV(
            jobz.ctypes, uplo.ctypes, size.ctypes, a.ctypes, size.ctypes, d.ctypes, work.ctypes,
            lwork.ctypes, info.ctypes,
        )  # fmt: skip
        vals[j] = d
    return vals


def interleaved(jobs: dict[str, Callable[[], Any]], rounds: int = 30) -> dict[str, float]:
    """Best process CPU seconds of each job, the jobs timed in turn, round after round.

    On a shared machine a slow spell then hits every job alike, and the best of many short
    calls is taken: consecutive stops of the harness are compared under the same conditions.
    """
    best = dict.fromkeys(jobs, float("inf"))
    for fn in jobs.values():
        fn()  # warm-up (compilation)
    for _ in range(rounds):
        for name, fn in jobs.items():
            t0 = time.process_time()
            fn()
            best[name] = min(best[name], time.process_time() - t0)
    return best


def split(cluster: int, n: int = 60000) -> list[tuple[str, float]]:
    """Per-window microseconds of each stage at ``cluster``."""
    import clpc

    u, y = record(n)
    appraiser = clpc.CLPC(order=2, window_size=WINDOW, cluster_size=cluster)
    appraiser.run(u[:1000, 0], y[:1000])
    setup = appraiser._state.kernel_setup()
    buf = np.ascontiguousarray(np.column_stack([u[:, 0], y]))
    count = min(4000, (n - 400) // cluster - 30)
    windows = (20, count)
    solved = K.Solved(*K.outputs(count, setup)[0])
    fsm = K.FsmOutput(*K.outputs(count, setup)[1])
    state = K.FsmState(np.zeros((1, 6)), np.zeros(1), np.zeros(1, bool))
    jobs: dict[str, Callable[[], Any]] = {
        str(k): (lambda k=k: stages(buf, -2, windows, setup.plan, setup.settings, k))
        for k in range(1, 7)
    }
    jobs["total"] = lambda: K.solve_windows(
        buf, -2, windows, setup.plan, setup.settings, solved, K.new_cache(setup.plan.chan.shape, 0)
    )
    jobs["fsm"] = lambda: K.fsm_output(solved, setup.fsm, state, fsm)
    t = interleaved(jobs)
    out = [
        ("block statistics (once per block)", t["1"]),
        ("tail and head pieces (rows chained when C < B), steps", t["2"] - t["1"]),
        ("full blocks' sums and the merge (Chan, Golub and LeVeque)", t["3"] - t["2"]),
        ("eigen-solve sym_eig (tred2 + tql2, vectors)", t["4"] - t["3"]),
        ("rest of solve_one (scales, checks, solve_from_eig)", t["5"] - t["4"]),
        ("is_excited", t["6"] - t["5"]),
        ("fsm_output (accept/hold, monic, stability)", t["fsm"]),
        ("solve_windows as called (stages 1-6)", t["total"]),
    ]
    return [(name, sec / count * 1e6) for name, sec in out]


def jacobi_vs_ql(n: int = 40000) -> str:
    """Warm-started Jacobi against the kernel's cold Householder + QL on consecutive windows."""
    u, y = record(n)
    rows = np.column_stack([y[2:], y[1:-1], y[:-2], u[2:, 0], u[1:-1, 0], u[:-2, 0]])
    mats = []
    for j in range(17, n // 12 - 2):
        z = rows[12 * j - WINDOW : 12 * j]
        z = z - z.mean(axis=0)
        mats.append(z.T @ z)
    a = np.array(mats)
    vals_j, sweeps = warm_jacobi(a)
    vals_q = cold_ql(a)
    vals_l = lapack_dsyev(a)
    t = interleaved(
        {
            "jacobi": lambda: warm_jacobi(a),
            "ql": lambda: cold_ql(a),
            "lapack": lambda: lapack_dsyev(a),
        },
        rounds=15,
    )
    t_j, t_q, t_l = t["jacobi"], t["ql"], t["lapack"]
    dev = np.max(np.abs(np.sort(vals_j, axis=1) - vals_q) / vals_q[:, -1:])
    dev_l = np.max(np.abs(vals_l - vals_q) / vals_q[:, -1:])
    return (
        f"{len(a)} consecutive windows (C = 12): Householder + QL (cold) {t_q / len(a) * 1e6:.2f} "
        f"us/window; Jacobi from the previous window's eigenvectors {t_j / len(a) * 1e6:.2f} "
        f"us/window ({sweeps / len(a):.2f} sweeps per window to eps); eigenvalues agree to "
        f"{dev:.1e} of lambda_max; LAPACK dsyev called from compiled code "
        f"{t_l / len(a) * 1e6:.2f} us/window (eigenvalues agree to {dev_l:.1e})"
    )


def main() -> None:
    """Print the split at C = 12 and C = 1, and the Jacobi comparison."""
    for cluster in (12, 1):
        print(f"C = {cluster}: per window [us] (CPU)")
        for name, us in split(cluster):
            print(f"  {name:52s} {us:6.3f}")
    print(jacobi_vs_ql())


if __name__ == "__main__":
    main()
