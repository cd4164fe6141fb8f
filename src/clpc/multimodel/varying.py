"""Free run of a difference equation whose coefficients change every sample."""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.multimodel.kernels import run_varying

__all__ = ["simulate_time_varying"]


def simulate_time_varying(den: Any, num: Any, intercept: Any, u: Any, y_init: Any) -> np.ndarray:
    """Simulate ``y(n) = k_n - sum_l den_n[l] y(n-l) + sum_l num_n[l] u(n-l)`` (SISO).

    Parameters
    ----------
    den : array_like, shape (T, na+1)
        Monic denominators (``den[:, 0] = 1``), one per sample.
    num : array_like, shape (T, L)
        Numerators (ascending powers of ``z^-1``, ``nk`` leading zeros), one per sample.
    intercept : array_like, shape (T,)
    u : array_like, shape (T,)
        Input; samples ``n < P = max(na, L - 1)`` only serve as initial inputs.
    y_init : array_like, shape (P,)
        Outputs of samples ``0 .. P-1`` (the free run starts at sample ``P``).

    Returns
    -------
    ndarray, shape (T,)
        ``y_init`` followed by the simulated outputs.
    """
    d = np.asarray(den, dtype=np.float64)
    nm = np.asarray(num, dtype=np.float64)
    uu = np.asarray(u, dtype=np.float64).ravel()
    t = uu.shape[0]
    if d.shape[0] != t or nm.shape[0] != t or np.shape(intercept) != (t,):
        raise ValueError("den, num, intercept and u must have one row per sample.")
    start = max(d.shape[1] - 1, nm.shape[1] - 1)
    y = np.zeros(t)
    y0 = np.asarray(y_init, dtype=np.float64).ravel()
    if y0.size != start:
        raise ValueError(f"y_init must hold the first {start} outputs; got {y0.size}.")
    y[:start] = y0
    return run_varying(
        (d, nm[:, None, :], np.asarray(intercept, dtype=np.float64)), uu[:, None], y, start
    )
