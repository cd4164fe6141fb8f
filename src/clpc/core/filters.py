"""Linear filters of long signals without importing ``scipy.signal`` (0.6-0.8 s to import).

The model's simulation, prediction and frequency response need three operations, each
the same as its ``scipy.signal`` counterpart up to rounding (the tests compare them):

* :func:`fir` - ``lfilter(b, [1.0], x)``: a convolution (numpy);
* :func:`all_pole` - ``lfilter([1.0], den, x, zi=lfiltic([1.0], den, past))``: the
  recursion ``y(n) = x(n) - den_1 y(n-1) - ... - den_na y(n-na)`` started from the
  outputs before the first sample (compiled; ``scipy.signal.lfilter`` on the ``"python"``
  engine, where a Python loop over the samples would be far too slow);
* :func:`frequency_response` - ``freqz(b, a, worN=freqs, fs=fs)`` (numpy).

``scipy.signal`` is the reference, not a dependency of these paths: ``clpc track``'s
report and ``clpc simulate`` start without it.
"""

from __future__ import annotations

import numpy as np

from clpc.core.jit import compiled, kernel, resolve_engine

__all__ = ["all_pole", "fir", "frequency_response"]


def fir(b: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``y(n) = b_0 x(n) + b_1 x(n-1) + ...`` from rest (``scipy.signal.lfilter(b, [1], x)``).

    Parameters
    ----------
    b : ndarray, shape (m,)
        Coefficients, ascending powers of ``z^-1``.
    x : ndarray, shape (n,)
        Signal.

    Returns
    -------
    ndarray, shape (n,)
    """
    b = np.asarray(b, dtype=np.float64)
    x = np.asarray(x, dtype=np.float64)
    if x.size == 0 or b.size == 0:
        return np.zeros(x.shape)
    return np.convolve(x, b)[: x.size]


@kernel
def _all_pole_loop(den, x, past, y):  # numba's subset: no annotations
    na = den.size - 1
    for t in range(x.size):
        acc = x[t]
        for k in range(1, na + 1):
            if t >= k:
                acc -= den[k] * y[t - k]
            else:
                acc -= den[k] * past[k - t - 1]
        y[t] = acc


def all_pole(den: np.ndarray, x: np.ndarray, past: np.ndarray | None = None) -> np.ndarray:
    """``A(z) y = x``, started from the outputs before ``x[0]``.

    Parameters
    ----------
    den : ndarray, shape (na + 1,)
        ``A(z) = den_0 + den_1 z^-1 + ... + den_na z^-na`` (``den_0 != 0``; monic in the
        model's use).
    x : ndarray, shape (n,)
        Right-hand side.
    past : ndarray, shape (na,), optional
        ``y(-1), y(-2), ..., y(-na)`` (most recent first); zeros (rest) when omitted.

    Returns
    -------
    ndarray, shape (n,)

    Raises
    ------
    ValueError
        ``den[0]`` is 0 or not finite, or ``past`` has the wrong length.
    """
    den = np.ascontiguousarray(den, dtype=np.float64)
    x = np.ascontiguousarray(x, dtype=np.float64)
    na = den.size - 1
    if den.size == 0 or den[0] == 0.0 or not np.isfinite(den[0]):
        raise ValueError(f"den[0] must be a non-zero number; got den = {den.tolist()}.")
    if den[0] != 1.0:
        den, x = den / den[0], x / den[0]
    start = np.zeros(na) if past is None else np.ascontiguousarray(past, dtype=np.float64)
    if start.shape != (na,):
        raise ValueError(f"past must hold the last {na} outputs; got shape {start.shape}.")
    if na == 0:
        return x.copy()
    if resolve_engine("auto") == "python":
        from scipy import signal  # the reference; a Python loop over samples is too slow

        zi = signal.lfiltic([1.0], den, start)
        return np.asarray(signal.lfilter([1.0], den, x, zi=zi)[0])
    y = np.empty_like(x)
    compiled(_all_pole_loop)(den, x, start, y)
    return y


def frequency_response(
    b: np.ndarray, a: np.ndarray, freqs: np.ndarray | int, fs: float
) -> tuple[np.ndarray, np.ndarray]:
    """``H(f) = B(e^{-jw}) / A(e^{-jw})``, ``w = 2 pi f / fs`` (``scipy.signal.freqz``).

    Parameters
    ----------
    b, a : ndarray
        Numerator and denominator, ascending powers of ``z^-1``.
    freqs : int or ndarray
        Number of frequencies evenly spaced over ``[0, fs / 2)``, or frequencies [Hz].
    fs : float
        Sample rate [Hz].

    Returns
    -------
    freqs : ndarray, shape (n,)
        [Hz].
    response : ndarray of complex, shape (n,)
    """
    if isinstance(freqs, (int, np.integer)) and not isinstance(freqs, bool):
        f = np.arange(int(freqs)) * (fs / 2.0 / int(freqs))
    else:
        f = np.atleast_1d(np.asarray(freqs, dtype=np.float64))
    zinv = np.exp(-2j * np.pi * f / fs)
    poly = np.polynomial.polynomial.polyval
    return f, poly(zinv, np.asarray(b, dtype=np.float64)) / poly(
        zinv, np.asarray(a, dtype=np.float64)
    )
