"""Free-run loops of blended and time-varying difference equations (compiled by numba).

A free run feeds each simulated output back, so it is sequential in time; these loops are
``numba.njit(cache=True)`` functions (with ``NUMBA_DISABLE_JIT=1`` the same code runs as
plain Python).

Every local model is stored in the monic form of :class:`clpc.LinearModel`: ``den``
(shape (M, na+1), ``den[:, 0] = 1``), ``num`` (shape (M, n_in, L), ``L = nk + nb + 1``,
lag ``l`` of input ``c`` at ``num[:, c, l]``) and ``icpt`` (shape (M,)). The one-step
equation of model ``i`` is ``y(n) = icpt_i - sum_{l>=1} den_il y(n-l) + sum_c sum_l
num_icl u_c(n-l)``.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["run_blend", "run_varying"]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _local_output(
    den: np.ndarray, num: np.ndarray, icpt: np.ndarray, i: int, y: np.ndarray, u: np.ndarray, n: int
) -> float:
    """Model ``i``'s one-step output at sample ``n`` from ``y[n-l]`` and ``u[n-l]``."""
    v = icpt[i]
    for lag in range(1, den.shape[1]):
        v -= den[i, lag] * y[n - lag]
    for c in range(num.shape[1]):
        for lag in range(num.shape[2]):
            v += num[i, c, lag] * u[n - lag, c]
    return v


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _blend_loop(
    den: np.ndarray,
    num: np.ndarray,
    icpt: np.ndarray,
    centres: np.ndarray,
    inv_w: np.ndarray,
    sched: np.ndarray,
    u: np.ndarray,
    y: np.ndarray,
    start: int,
) -> None:
    """Fill ``y[start:]`` with the blended free run (``y[:start]`` holds the initial outputs).

    ``sched = [kind, channel, lag]``: kind 0 schedules on ``y(n - lag)``, kind 1 on
    ``u_channel(n - lag)``; the validities are the normalised Gaussians of
    :func:`clpc.multimodel.validity.validity` (softmax form, the same operations).
    """
    m = den.shape[0]
    phi = np.empty(m)
    kind, chan, slag = sched[0], sched[1], sched[2]
    for n in range(start, y.shape[0]):
        psi = y[n - slag] if kind == 0 else u[n - slag, chan]
        top = -math.inf
        for i in range(m):
            d = (psi - centres[i]) * inv_w[i]
            phi[i] = -0.5 * d * d
            if phi[i] > top:
                top = phi[i]
        total = 0.0
        for i in range(m):
            phi[i] = math.exp(phi[i] - top)
            total += phi[i]
        acc = 0.0
        for i in range(m):
            acc += phi[i] * _local_output(den, num, icpt, i, y, u, n)
        y[n] = acc / total


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _varying_loop(
    den: np.ndarray, num: np.ndarray, icpt: np.ndarray, u: np.ndarray, y: np.ndarray, start: int
) -> None:
    """Fill ``y[start:]`` with a time-varying free run: sample ``n`` uses model ``n``."""
    for n in range(start, y.shape[0]):
        y[n] = _local_output(den, num, icpt, n, y, u, n)


def run_blend(
    models: tuple[np.ndarray, np.ndarray, np.ndarray],
    centres: np.ndarray,
    widths: np.ndarray,
    sched: tuple[int, int, int],
    u: np.ndarray,
    y: np.ndarray,
    start: int,
) -> np.ndarray:
    """Blended free run in place on ``y`` (float64, shape (T,)); returns ``y``.

    ``models = (den, num, icpt)`` (see the module), ``u`` shape (T, n_in); ``y[:start]``
    are the initial outputs (and ``u[:start]`` the initial inputs).
    """
    den, num, icpt = models
    inv_w = np.ascontiguousarray(1.0 / np.asarray(widths, dtype=np.float64))
    _blend_loop(
        np.ascontiguousarray(den),
        np.ascontiguousarray(num),
        np.ascontiguousarray(icpt),
        np.ascontiguousarray(centres, dtype=np.float64),
        inv_w,
        np.asarray(sched, dtype=np.int64),
        np.ascontiguousarray(u, dtype=np.float64),
        y,
        int(start),
    )
    return y


def run_varying(
    models: tuple[np.ndarray, np.ndarray, np.ndarray],
    u: np.ndarray,
    y: np.ndarray,
    start: int,
) -> np.ndarray:
    """Time-varying free run in place on ``y`` (shape (T,)): model arrays have T rows."""
    den, num, icpt = models
    _varying_loop(
        np.ascontiguousarray(den),
        np.ascontiguousarray(num),
        np.ascontiguousarray(icpt),
        np.ascontiguousarray(u, dtype=np.float64),
        y,
        int(start),
    )
    return y
