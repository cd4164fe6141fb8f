"""The least a CLPC window can cost on this machine in any design that re-solves its spectrum.

Issue 26 asks for 1e7 samples/s at ``C = 12`` on one core: 1.2 us per window. This script
times, on the scatter matrices of consecutive windows (``N = 2``, ``p = 6``, ``W = 201``,
``C = 12``; the ``bench_clpc.py`` record), the parts a window cannot do without, each in its
cheapest form we know, so that their sum is a floor for *any* design (sliding or not):

* **sliding scatter**: the window's scatter from the previous one by adding the ``C`` new lag
  vectors' outer products and removing the ``C`` old ones (raw moments, then centred: the
  cheapest possible update; no drift control counted);
* **tridiagonal reduction**: Householder, without accumulating the transformation;
* **eigenvalues only**: the root-free rational QL iteration (EISPACK's ``tqlrat``; no
  square root per rotation) on that tridiagonal;
* **one eigenvector**: inverse iteration for the smallest eigenvalue, warm-started from the
  previous window's vector (a Cholesky factorisation of ``A - sigma I`` and two solves per
  step, two steps).

The kernel's own eigen-solve (``small_eigh.sym_eig``, Householder + QL with all vectors) is
timed beside them on the same matrices, and the eigenvalues compared. The rules and the FSM
output (``benchmarks/clpc_split.py``: ~0.5 us + 0.13 us per window) come on top.

Run: ``OPENBLAS_NUM_THREADS=1 python benchmarks/clpc_floor.py`` (CPU time per window, best
of 15 calls on 3,300 windows, the parts timed in turn).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from clpc_split import cold_ql, interleaved
from clpc_table import WINDOW, record

CLUSTER = 12


@numba.njit
def sliding(rows, first, count, cluster):
    """Scatters of ``count`` windows, each from the previous by +C and -C outer products."""
    p = rows.shape[1]
    s, m = np.zeros((p, p)), np.zeros(p)
    for r in range(first - WINDOW, first):
        for a in range(p):
            m[a] += rows[r, a]
            for b in range(a, p):
                s[a, b] += rows[r, a] * rows[r, b]
    out = np.empty((count, p, p))
    for j in range(count):
        end = first + cluster * j
        for r in range(end - cluster if j else end, end):  # window 0: the sums above
            old = r - WINDOW
            for a in range(p):
                m[a] += rows[r, a] - rows[old, a]
                for b in range(a, p):
                    s[a, b] += rows[r, a] * rows[r, b] - rows[old, a] * rows[old, b]
        for a in range(p):
            for b in range(a, p):
                c = s[a, b] - m[a] * m[b] / WINDOW
                out[j, a, b] = c
                out[j, b, a] = c
    return out


@numba.njit
def tridiagonal(a, d, e):
    """Householder reduction of symmetric ``a`` to (d, e); e[i] couples i - 1 and i.

    ``small_eigh._tred2``'s reduction without its accumulation of the transformation (the
    kernel's solver needs the vectors, this floor does not).
    """
    n = a.shape[0]
    v = a.copy()
    for j in range(n):
        d[j] = v[n - 1, j]
    for i in range(n - 1, 0, -1):
        scale, h = 0.0, 0.0
        for k in range(i):
            scale += abs(d[k])
        if scale == 0.0:
            e[i] = d[i - 1]
            for j in range(i):
                d[j] = v[i - 1, j]
        else:
            for k in range(i):
                d[k] /= scale
                h += d[k] * d[k]
            f = d[i - 1]
            g = -math.sqrt(h) if f > 0 else math.sqrt(h)
            e[i] = scale * g
            h -= f * g
            d[i - 1] = f - g
            for j in range(i):
                e[j] = 0.0
            for j in range(i):
                f = d[j]
                g = e[j] + v[j, j] * f
                for k in range(j + 1, i):
                    g += v[k, j] * d[k]
                    e[k] += v[k, j] * f
                e[j] = g
            f = 0.0
            for j in range(i):
                e[j] /= h
                f += e[j] * d[j]
            hh = f / (h + h)
            for j in range(i):
                e[j] -= hh * d[j]
            for j in range(i):
                f, g = d[j], e[j]
                for k in range(j, i):
                    v[k, j] -= f * e[k] + g * d[k]
                d[j] = v[i - 1, j]
        d[i] = v[i, i]
    e[0] = 0.0


@numba.njit
def tqlrat(d, e2):
    """Eigenvalues (ascending, in ``d``) of the tridiagonal (d, e2 = squared couplings)."""
    n = d.shape[0]
    for i in range(1, n):
        e2[i - 1] = e2[i]
    e2[n - 1] = 0.0
    f, t, b, c = 0.0, 0.0, 0.0, 0.0
    for l in range(n):  # noqa: E741 - EISPACK's name
        h = abs(d[l]) + math.sqrt(e2[l])
        if t < h:
            t = h
            b = t * 2.0**-52
            c = b * b
        m = l
        while e2[m] > c:
            m += 1
        while m > l:
            s = math.sqrt(e2[l])
            g = d[l]
            p = (d[l + 1] - g) / (2.0 * s)
            r = math.sqrt(p * p + 1.0)
            d[l] = s / (p + (r if p >= 0 else -r))
            h = g - d[l]
            for i in range(l + 1, n):
                d[i] -= h
            f += h
            g = d[m] if d[m] != 0.0 else b
            h, s = g, 0.0
            for i in range(m - 1, l - 1, -1):
                p = g * h
                r = p + e2[i]
                e2[i + 1] = s * r
                s = e2[i] / r
                d[i + 1] = h + s * (h + d[i])
                g = d[i] - e2[i] / g
                if g == 0.0:
                    g = b
                h = g * p / r
            e2[l] = s * g
            d[l] = h
            if h == 0.0 or abs(e2[l]) <= abs(c / h):
                break
            e2[l] *= h
            if e2[l] == 0.0:
                break
        p = d[l] + f
        i = l  # insertion into the sorted d[0 .. l-1]
        while i > 0 and p < d[i - 1]:
            d[i] = d[i - 1]
            i -= 1
        d[i] = p


@numba.njit
def eigenvalues(mats):
    """Eigenvalues of each matrix: Householder, then the root-free QL."""
    n, p = mats.shape[0], mats.shape[1]
    d, e, vals = np.empty(p), np.empty(p), np.empty((n, p))
    for j in range(n):
        tridiagonal(mats[j], d, e)
        for i in range(p):
            e[i] *= e[i]
        tqlrat(d, e)
        vals[j] = d
    return vals


@numba.njit
def reduction_only(mats):
    """The Householder reduction of each matrix alone."""
    p = mats.shape[1]
    d, e, acc = np.empty(p), np.empty(p), 0.0
    for j in range(mats.shape[0]):
        tridiagonal(mats[j], d, e)
        acc += d[0]
    return acc


@numba.njit
def smallest_vectors(mats, lows):
    """Two warm-started inverse-iteration steps for each matrix's smallest eigenvector."""
    n, p = mats.shape[0], mats.shape[1]
    x, ell, out = np.ones(p) / math.sqrt(p), np.empty((p, p)), np.empty((n, p))
    for j in range(n):
        a = mats[j]
        sigma = lows[j] - 1e-9 * (abs(lows[j]) + 1e-300) - 1e-12 * a[0, 0]
        for c in range(p):  # Cholesky of a - sigma I (lower)
            acc = a[c, c] - sigma
            for k in range(c):
                acc -= ell[c, k] * ell[c, k]
            ell[c, c] = math.sqrt(max(acc, 1e-300))
            for r in range(c + 1, p):
                acc = a[r, c]
                for k in range(c):
                    acc -= ell[r, k] * ell[c, k]
                ell[r, c] = acc / ell[c, c]
        for _ in range(2):
            for r in range(p):  # L w = x
                acc = x[r]
                for k in range(r):
                    acc -= ell[r, k] * x[k]
                x[r] = acc / ell[r, r]
            for r in range(p - 1, -1, -1):  # L^T x = w
                acc = x[r]
                for k in range(r + 1, p):
                    acc -= ell[k, r] * x[k]
                x[r] = acc / ell[r, r]
            norm = math.sqrt(np.sum(x * x))
            for r in range(p):
                x[r] /= norm
        out[j] = x
    return out


def main() -> None:
    """Print each part's CPU time per window and the floor they add up to."""
    u, y = record(40000)
    rows = np.ascontiguousarray(
        np.column_stack([y[2:], y[1:-1], y[:-2], u[2:, 0], u[1:-1, 0], u[:-2, 0]])
    )
    first = WINDOW + 2 * CLUSTER
    count = (rows.shape[0] - first) // CLUSTER
    mats = sliding(rows, first, count, CLUSTER)
    ends = first + CLUSTER * np.arange(count)
    windows = (rows[end - WINDOW : end] for end in ends)
    exact = np.array([(z - z.mean(axis=0)).T @ (z - z.mean(axis=0)) for z in windows])
    reference = np.linalg.eigh(exact)
    vals = eigenvalues(mats)
    vecs = smallest_vectors(mats, vals[:, 0])
    big = reference[0][:, -1:]
    agree_scatter = np.max(np.abs(mats - exact)) / np.max(big)
    agree_vals = np.max(np.abs(vals - reference[0]) / big)
    agree_vec = np.max(1.0 - np.abs(np.sum(vecs * reference[1][:, :, 0], axis=1)))
    lows = vals[:, 0].copy()
    t = interleaved(
        {
            "sliding": lambda: sliding(rows, first, count, CLUSTER),
            "sliding1": lambda: sliding(rows, first, count, 1),
            "reduction": lambda: reduction_only(mats),
            "eigenvalues": lambda: eigenvalues(mats),
            "vector": lambda: smallest_vectors(mats, lows),
            "kernel": lambda: cold_ql(mats),
        },
        rounds=15,
    )
    us = {k: v / count * 1e6 for k, v in t.items()}
    floor = us["sliding"] + us["eigenvalues"] + us["vector"]
    print(f"{count} consecutive windows, p = 6, W = {WINDOW}, C = {CLUSTER} (CPU us per window)")
    print(f"  sliding scatter (+C, -C outer products)    {us['sliding']:6.3f}")
    print(f"  the same at C = 1 (+1, -1)                 {us['sliding1']:6.3f}")
    print(f"  Householder reduction alone                {us['reduction']:6.3f}")
    print(f"  eigenvalues: reduction + root-free QL      {us['eigenvalues']:6.3f}")
    print(f"  smallest eigenvector, inverse iteration    {us['vector']:6.3f}")
    print(f"  sum: the spectrum part of a window         {floor:6.3f}")
    print(f"  the kernel's sym_eig (all vectors), as now {us['kernel']:6.3f}")
    print(
        f"agreement with numpy.linalg.eigh of the exact scatters: scatter {agree_scatter:.1e}, "
        f"eigenvalues {agree_vals:.1e} (of lambda_max), vector 1-|cos| {agree_vec:.1e}"
    )
    print(
        f"1e7 samples/s at C = {CLUSTER} leaves {CLUSTER / 10:.2f} us per window; the rules and "
        "the FSM output add ~0.6 us (clpc_split.py)"
    )


if __name__ == "__main__":
    main()
