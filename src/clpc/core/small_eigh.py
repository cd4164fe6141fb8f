"""Eigen-decomposition of one small symmetric matrix, in plain loops a compiler can speed up.

CLPC solves one 6x6 (``p x p``) eigenproblem per window. LAPACK's ``dsyev`` costs 3.4 us for
such a matrix even called straight from compiled code with its work space allocated once
(its own overhead: ``ilaenv``, scaling, blocked paths); the same algorithm written as loops
and compiled with numba (:mod:`clpc.appraiser.kernel`) costs about 1.6 us with the
eigenvectors (0.55 us the reduction, 0.95 us the QL iteration for the eigenvalues, ~0.1 us
applying its rotations to the vectors; ``benchmarks/clpc_split.py``) and runs inside the
per-window kernel without leaving compiled code.

The algorithm is the classic pair used by EISPACK (``tred2``/``tql2``) and its public-domain
Java translation JAMA: Householder reduction to tridiagonal form accumulating the
transformations, then the implicit QL iteration with Wilkinson-like shifts. It is backward
stable: eigenvalues carry an absolute error of a few ``eps * ||A||``, like LAPACK's
``dsyev``. The functions below are plain Python in numba's subset, registered with
``numba.extending.register_jitable``: the CLPC kernel compiles them into its loop.
"""

from __future__ import annotations

import math

import numpy as np
from numba.extending import register_jitable

__all__ = ["sym_eig"]

_EPS = 2.0**-52
_MAX_QL_ITERATIONS = 60  # per eigenvalue; a few are needed in practice


@register_jitable(error_model="numpy")
def sym_eig(a: np.ndarray, d: np.ndarray, v: np.ndarray, e: np.ndarray, vectors: bool) -> bool:
    """Eigenvalues (ascending) and, optionally, eigenvectors of a symmetric matrix.

    Parameters
    ----------
    a : ndarray, shape (n, n)
        Symmetric matrix (only read; the lower triangle is used).
    d : ndarray, shape (n,)
        Output: eigenvalues in ascending order.
    v : ndarray, shape (n, n)
        Work space, and output: column ``i`` is the unit eigenvector of ``d[i]`` (when
        ``vectors`` is true).
    e : ndarray, shape (n,)
        Work space.
    vectors : bool
        Whether to compute the eigenvectors (about twice the work).

    Returns
    -------
    bool
        False if the QL iteration did not converge (non-finite input); ``d`` is then
        meaningless.
    """
    n = a.shape[0]
    for i in range(n):
        for j in range(n):
            v[i, j] = a[i, j]
    _tred2(v, d, e, n)
    return _tql2(v, d, e, n, vectors)


@register_jitable(error_model="numpy")
def _tred2(v: np.ndarray, d: np.ndarray, e: np.ndarray, n: int) -> None:
    """Householder tridiagonalisation of ``v`` in place (``v`` becomes the transformation)."""
    for j in range(n):
        d[j] = v[n - 1, j]
    for i in range(n - 1, 0, -1):
        scale = 0.0
        h = 0.0
        for k in range(i):
            scale += abs(d[k])
        if scale == 0.0:
            e[i] = d[i - 1]
            for j in range(i):
                d[j] = v[i - 1, j]
                v[i, j] = 0.0
                v[j, i] = 0.0
        else:
            for k in range(i):
                d[k] /= scale
                h += d[k] * d[k]
            f = d[i - 1]
            g = math.sqrt(h)
            if f > 0:
                g = -g
            e[i] = scale * g
            h = h - f * g
            d[i - 1] = f - g
            for j in range(i):
                e[j] = 0.0
            for j in range(i):
                f = d[j]
                v[j, i] = f
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
                f = d[j]
                g = e[j]
                for k in range(j, i):
                    v[k, j] -= f * e[k] + g * d[k]
                d[j] = v[i - 1, j]
                v[i, j] = 0.0
        d[i] = h
    # accumulate the transformations
    for i in range(n - 1):
        v[n - 1, i] = v[i, i]
        v[i, i] = 1.0
        h = d[i + 1]
        if h != 0.0:
            for k in range(i + 1):
                d[k] = v[k, i + 1] / h
            for j in range(i + 1):
                g = 0.0
                for k in range(i + 1):
                    g += v[k, i + 1] * v[k, j]
                for k in range(i + 1):
                    v[k, j] -= g * d[k]
        for k in range(i + 1):
            v[k, i + 1] = 0.0
    for j in range(n):
        d[j] = v[n - 1, j]
        v[n - 1, j] = 0.0
    v[n - 1, n - 1] = 1.0
    e[0] = 0.0


@register_jitable(error_model="numpy")
def _tql2(v: np.ndarray, d: np.ndarray, e: np.ndarray, n: int, vectors: bool) -> bool:
    """Implicit QL iteration on the tridiagonal ``(d, e)``; rotations applied to ``v``."""
    for i in range(1, n):
        e[i - 1] = e[i]
    e[n - 1] = 0.0
    f = 0.0
    tst1 = 0.0
    for l in range(n):  # noqa: E741 - the classic algorithm's name
        tst1 = max(tst1, abs(d[l]) + abs(e[l]))
        m = l
        while m < n - 1:
            if abs(e[m]) <= _EPS * tst1:
                break
            m += 1
        if m > l:
            iterations = 0
            while True:
                iterations += 1
                if iterations > _MAX_QL_ITERATIONS:
                    return False
                g = d[l]
                p = (d[l + 1] - g) / (2.0 * e[l])
                r = math.sqrt(p * p + 1.0)
                if p < 0:
                    r = -r
                d[l] = e[l] / (p + r)
                d[l + 1] = e[l] * (p + r)
                dl1 = d[l + 1]
                h = g - d[l]
                for i in range(l + 2, n):
                    d[i] -= h
                f += h
                p = d[m]
                c = 1.0
                c2 = c
                c3 = c
                el1 = e[l + 1]
                s = 0.0
                s2 = 0.0
                for i in range(m - 1, l - 1, -1):
                    c3 = c2
                    c2 = c
                    s2 = s
                    g = c * e[i]
                    h = c * p
                    r = math.sqrt(p * p + e[i] * e[i])
                    e[i + 1] = s * r
                    s = e[i] / r
                    c = p / r
                    p = c * d[i] - s * g
                    d[i + 1] = h + s * (c * g + s * d[i])
                    if vectors:
                        for k in range(n):
                            h = v[k, i + 1]
                            v[k, i + 1] = s * v[k, i] + c * h
                            v[k, i] = c * v[k, i] - s * h
                p = -s * s2 * c3 * el1 * e[l] / dl1
                e[l] = s * p
                d[l] = c * p
                if not abs(e[l]) > _EPS * tst1:  # also stops on NaN (checked below)
                    break
        d[l] = d[l] + f
        e[l] = 0.0
    for i in range(n):
        if not math.isfinite(d[i]):
            return False
    # ascending order (selection sort; n is small)
    for i in range(n - 1):
        k = i
        p = d[i]
        for j in range(i + 1, n):
            if d[j] < p:
                k = j
                p = d[j]
        if k != i:
            d[k] = d[i]
            d[i] = p
            if vectors:
                for j in range(n):
                    p = v[j, i]
                    v[j, i] = v[j, k]
                    v[j, k] = p
    return True
