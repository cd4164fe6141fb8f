"""Running a :class:`clpc.LinearModel` on data: free run, k-step prediction, input inference.

The model's methods of the same names call these functions (``model`` is a
:class:`clpc.LinearModel`; typed loosely here so that this module need not import it).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from clpc.core.filters import all_pole, fir
from clpc.data import DataError, IOData
from clpc.data.signals import signals
from clpc.model.errors import ModelError, as_2d, require_siso

__all__ = ["NOISE_MODELS", "forced", "infer_input", "noise_models", "predict", "simulate"]

#: Values of ``info["noise_model"]``: ``"equation-error"`` (``den y = num u + e``, white ``e``:
#: LPC, least squares; the default when the key is absent) and ``"output-error"``
#: (``y = num/den u + e``, white ``e``: :class:`clpc.OE`).
NOISE_MODELS = ("equation-error", "output-error")


def noise_models(model: Any) -> list[str]:
    """The noise model of each output, from ``info["noise_model"]``.

    ``info["noise_model"]`` is absent (equation error), one of :data:`NOISE_MODELS` for
    every output, or a list of them, one per output (a model that mixes estimators).

    Returns
    -------
    list of str, length ``n_outputs``

    Raises
    ------
    ModelError
        An unknown value or a list of the wrong length.
    """
    value = model.info.get("noise_model", "equation-error")
    out = [value] * model.n_outputs if isinstance(value, str) else list(value)
    if len(out) != model.n_outputs or any(v not in NOISE_MODELS for v in out):
        raise ModelError(
            f"info['noise_model'] must be one of {NOISE_MODELS} or a list of them, one per "
            f"output ({model.n_outputs}); got {value!r}."
        )
    return out


def forced(model: Any, u: np.ndarray, u_init: np.ndarray | None) -> np.ndarray:
    """``x_j(n) = sum_i num_ji * u_i + intercept_j``, shape (T, n_out)."""
    nums = model.numerators
    n_lag = nums.shape[2] - 1
    if u_init is None:
        u_ext = np.vstack([np.zeros((n_lag, model.n_inputs)), u])
    else:
        u0, _ = as_2d(u_init, model.n_inputs, "u_init")
        if u0.shape[0] < n_lag:
            raise ValueError(f"u_init must hold the last {n_lag} inputs before u[0].")
        u_ext = np.vstack([u0[u0.shape[0] - n_lag :], u])
    x = np.empty((u.shape[0], model.n_outputs))
    for j in range(model.n_outputs):
        acc = np.zeros(u_ext.shape[0])
        for i in range(model.n_inputs):
            acc += fir(nums[j, i], u_ext[:, i])
        x[:, j] = acc[n_lag:]
    return x


def simulate(
    model: Any,
    u: Any,
    *,
    y_init: Any | None = None,
    u_init: Any | None = None,
    include_offset: bool = True,
) -> np.ndarray:
    """Free-run simulation from the input alone (see :meth:`clpc.LinearModel.simulate`)."""
    stacked = _by_experiment(
        u, lambda part: simulate(model, part, include_offset=include_offset), y_init, u_init
    )
    if stacked is not None:
        return stacked
    u, _ = signals(u, what="simulate", needs_y=False)
    u2, was_1d = as_2d(u, model.n_inputs, "u")
    x = forced(model, u2, u_init)
    if include_offset:
        x = x + model.intercept[None, :]
    dens = model.denominators
    na = model.structure.na
    y0 = None
    if y_init is not None:
        y0, _ = as_2d(y_init, model.n_outputs, "y_init")
        if y0.shape[0] < na:
            raise ValueError(f"y_init must hold the last {na} outputs before u[0].")
        y0 = y0[y0.shape[0] - na :]
    y = np.empty_like(x)
    for j in range(model.n_outputs):
        y[:, j] = all_pole(dens[j], x[:, j], None if y0 is None else y0[::-1, j])
    return y[:, 0] if (was_1d and model.n_outputs == 1) else y


def _by_experiment(
    data: Any, run: Callable[[IOData], np.ndarray], *initial: Any
) -> np.ndarray | None:
    """``run`` on each experiment of a record of several, stacked; ``None`` for others."""
    if not (isinstance(data, IOData) and data.n_experiments > 1):
        return None
    if any(x is not None for x in initial):
        raise DataError(
            "initial conditions (y_init, u_init) are for one experiment; this record holds "
            f"{data.n_experiments}: simulate them one at a time (data.split())."
        )
    return np.concatenate([run(part) for part in data.split()])


def predict(model: Any, u: Any, y: Any = None, k: int = 1) -> np.ndarray:
    """``k``-step-ahead prediction ``y_hat(n | n-k)`` (:meth:`clpc.LinearModel.predict`).

    Equation-error outputs: the recursion below (measured outputs up to ``n - k``, the
    model's own predictions after). Output-error outputs (:func:`noise_models`): the free
    run from the input, started from the measured samples before ``max_lag`` - with white
    noise on the output the past outputs carry no information about the future noise, so
    that is the predictor for every ``k``.
    """
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
        raise ValueError(f"k must be an int in the range [1, inf); got {k!r}.")
    if y is None:
        stacked = _by_experiment(u, lambda part: predict(model, part, k=k))
        if stacked is not None:
            return stacked
    u, y = signals(u, y, what="predict")
    u2, _ = as_2d(u, model.n_inputs, "u")
    y2, y_1d = as_2d(y, model.n_outputs, "y")
    if u2.shape[0] != y2.shape[0]:
        raise ValueError(
            f"u and y must have the same length; got len(u)={u2.shape[0]}, len(y)={y2.shape[0]}."
        )
    start = model.structure.max_lag
    x = forced(model, u2, None) + model.intercept[None, :]
    n = y2.shape[0]
    out = y2.copy()
    oe = [j for j, v in enumerate(noise_models(model)) if v == "output-error"]
    for j in range(model.n_outputs):
        if j not in oe:
            out[start:, j] = _kstep(model.denominators[j], x[:, j], y2[:, j], start, k)
    if oe:
        sim = simulate(
            model,
            u2[start:],
            y_init=y2[:start] if model.structure.na else None,
            u_init=u2[:start] if start else None,
        )
        out[start:, oe] = np.asarray(sim).reshape(n - start, model.n_outputs)[:, oe]
    return out[:, 0] if (y_1d and model.n_outputs == 1) else out


def _kstep(den: np.ndarray, x: np.ndarray, y: np.ndarray, start: int, k: int) -> np.ndarray:
    """``y_hat(n | n-k)`` of one equation ``A(q) y = x + e`` for ``n >= start``, O(T) memory.

    With ``F_k`` the first ``k`` terms of ``1/A`` (so ``F_k A = 1 - q^-k G_k``), the
    ``k``-step predictor is the pair of filters ``y_hat = F_k x + (1 - F_k A) y``: it removes
    the ``k`` latest equation errors ``e(n) .. e(n-k+1)`` from ``y(n)``; ``1 - F_k A`` holds
    only the lags ``k .. k+na-1``, so it reads outputs measured up to ``n - k``. For
    ``n < start + k - 1`` fewer than ``k`` samples follow the first ``start`` measured ones:
    there the prediction is the free run from them (as the step-by-step recursion gives).

    Parameters
    ----------
    den : ndarray, shape (na + 1,)
        Monic ``A``.
    x : ndarray, shape (T,)
        Forced part ``B u + intercept``.
    y : ndarray, shape (T,)
        Measured output.
    start : int
        First predicted sample (``max_lag``).
    k : int
        Horizon [samples], ``k >= 1``.

    Returns
    -------
    ndarray, shape (T - start,)
    """
    na, n = den.size - 1, y.size
    impulse = np.zeros(min(k, n))
    impulse[0] = 1.0
    f_k = all_pole(den, impulse)  # F_k, the first k terms of 1/A
    tail = -np.convolve(f_k, den)  # 1 - F_k A: zero at lags 0 .. k-1
    tail[0] += 1.0
    out = np.empty(n - start)
    head = min(k - 1, n - start)  # the free run from the measured start
    past = y[start - na : start][::-1] if na else None
    out[:head] = all_pole(den, x[start : start + head], past)
    if head < n - start:
        full = _convolve_head(x, f_k, n) + _convolve_head(y, tail[:n], n)
        out[head:] = full[start + head :]
    return out


#: Below this many taps a direct convolution is cheaper than one by FFT.
DIRECT_TAPS = 64


def _convolve_head(x: np.ndarray, taps: np.ndarray, n: int) -> np.ndarray:
    """The first ``n`` samples of ``np.convolve(x, taps)``: direct, or by FFT (O(n) memory).

    The FFT length is the power of two that holds the whole convolution, so there is no
    wrap-around; its rounding is about ``1e-16 * log2(length) * max|x| * sum|taps|``.
    """
    if taps.size <= DIRECT_TAPS:
        return np.convolve(x, taps)[:n]
    size = 1 << (x.size + taps.size - 2).bit_length()
    return np.fft.irfft(np.fft.rfft(x, size) * np.fft.rfft(taps, size), size)[:n]


def infer_input(
    model: Any, y: Any, *, y_init: Any | None = None, allow_unstable: bool = False
) -> np.ndarray:
    """The input that explains a measured output (:meth:`clpc.LinearModel.infer_input`)."""
    require_siso(model, "infer_input")
    if isinstance(y, IOData):
        y = signals(y, what="infer_input")[1]
    y2, _ = as_2d(y, 1, "y")
    yv = y2[:, 0]
    s = model.structure
    num = model.num[s.nk :]
    if abs(num[0]) <= 1e-9 * max(np.max(np.abs(num)), 1e-300):
        raise ModelError(
            f"b0 is about 0 (num(z) after its nk leading zeros: {num.round(9).tolist()}): the "
            "current input does not reach the output after nk samples; increase nk by one and "
            "refit."
        )
    zeros = np.roots(num) if num.size > 1 else np.array([])
    if zeros.size and np.max(np.abs(zeros)) >= 1.0 and not allow_unstable:
        raise ModelError(
            f"the inverse model is unstable: num(z) has zeros {np.round(zeros, 4).tolist()} "
            "on or outside the unit circle (a non-minimum-phase model). Pass "
            "allow_unstable=True to compute it anyway."
        )
    if y_init is None:
        past = np.full(s.na, yv[0])
    else:
        past = np.asarray(y_init, dtype=np.float64).ravel()
        if past.size < s.na:
            raise ValueError(
                f"y_init must hold the last {s.na} outputs before y[0]; got {past.size}."
            )
        past = past[past.size - s.na :]
    y_ext = np.concatenate([past, yv])
    w = fir(model.den, y_ext)[s.na :] - model.intercept[0]
    u_hat = all_pole(num, w)
    return u_hat[s.nk :] if s.nk else u_hat


# ----------------------------------------------------------------- export
def observer_form(
    nums: list[np.ndarray], den: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Observer canonical state-space form of ``y = sum_i nums[i](z) / den(z) u_i``.

    Parameters
    ----------
    nums : list of ndarray, each shape (n + 1,)
        Numerators, ascending powers of ``z^-1`` (padded to the denominator's length).
    den : ndarray, shape (n + 1,)
        Monic denominator (``den[0] = 1``), ascending powers of ``z^-1``.

    Returns
    -------
    a : ndarray, shape (n, n)
    b : ndarray, shape (n, n_inputs)
    c : ndarray, shape (n,)
    d : ndarray, shape (n_inputs,)
        ``x(n+1) = a x(n) + b u(n)``, ``y(n) = c x(n) + d u(n)``; from a zero state its
        response equals ``lfilter(nums[i], den, u_i)`` summed over the inputs.
    """
    den = np.asarray(den, dtype=np.float64)
    n = den.size - 1
    num = np.array(nums, dtype=np.float64).reshape(len(nums), n + 1)
    a = np.zeros((n, n))
    a[:, 0] = -den[1:]
    a[: n - 1, 1:] = np.eye(n - 1)
    d = num[:, 0]
    b = (num[:, 1:] - np.outer(d, den[1:])).T
    c = np.zeros(n)
    if n:
        c[0] = 1.0
    return a, b, c, d
