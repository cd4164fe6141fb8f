"""What one call of a compiled (numba) function costs from Python, by its arguments (issue 26).

Every array argument is unboxed at every call, and tuples are typed element by element: this
measures an empty compiled function called with 1 to 45 one-dimensional arrays (separate or in
one tuple), a 3-d array, a nested tuple and a tuple mixing an array with scalars, best of 5
loops of 200 000 calls (wall time, one thread). ``step``'s update entry
(:func:`clpc.appraiser.step_kernel.update_row`) takes ten arguments, seven of them arrays,
for this reason.

Usage::

    OPENBLAS_NUM_THREADS=1 python benchmarks/numba_dispatch.py
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from typing import Any

import numba
import numpy as np


@numba.njit
def _one(a: Any) -> float:
    return float(a.shape[0])


@numba.njit
def _five(a: Any, b: Any, c: Any, d: Any, e: Any) -> float:
    return float(a.shape[0])


@numba.njit
def _head(t: Any) -> float:
    return float(t[0].shape[0])


@numba.njit
def _nested(t: Any) -> float:
    return float(t[0][0].shape[0])


@numba.njit
def _ten(a: Any, b: Any, c: Any, d: Any, e: Any, f: Any, g: Any, h: Any, i: Any, j: Any) -> int:
    return 0


def per_call(fn: Callable[..., Any], *args: Any, n: int = 200_000) -> float:
    """Best wall time of one call [us] over 5 loops of ``n`` calls."""
    fn(*args)  # compile
    best = float("inf")
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(n):
            fn(*args)
        best = min(best, (time.perf_counter() - t0) / n)
    return best * 1e6


def main() -> None:
    vec = np.zeros(10)
    rows = [
        ("1 array (1-d)", per_call(_one, vec)),
        ("1 array (3-d)", per_call(_one, np.zeros((3, 4, 5)))),
        ("5 arrays", per_call(_five, vec, vec, vec, vec, vec)),
        ("3 arrays + 2 ints", per_call(_five, vec, vec, vec, 1, 2)),
        (
            "10 arguments as update_row's (7 arrays, 3 ints)",
            per_call(_ten, np.zeros((50, 2)), 1, 2, 3, vec, np.zeros(4, np.int64), *[vec] * 4),
        ),
    ]
    for k in (1, 5, 10, 20, 45):
        arrays = tuple(np.zeros(10) for _ in range(k))
        rows.append((f"a tuple of {k} arrays", per_call(_head, arrays)))
    nested = tuple(tuple(np.zeros(3) for _ in range(5)) for _ in range(3))
    rows.append(("a tuple of 3 tuples of 5 arrays", per_call(_nested, nested)))
    rows.append(("(array, int, float) in one tuple", per_call(_head, (vec, 1, 2.0))))
    print(f"load average {os.getloadavg()[0]:.2f}")
    for label, us in rows:
        print(f"{label:50s} {us:6.2f} us")


if __name__ == "__main__":
    main()
