"""Linear filters of long signals without importing ``scipy.signal`` (0.6-0.8 s to import).

The model's simulation, prediction and frequency response need three operations, each
the same as its ``scipy.signal`` counterpart up to rounding (the tests compare them):

* :func:`fir` - ``lfilter(b, [1.0], x)``: a convolution (numpy);
* :func:`all_pole` - ``lfilter([1.0], den, x, zi=lfiltic([1.0], den, past))``: the
  recursion ``y(n) = x(n) - den_1 y(n-1) - ... - den_na y(n-na)`` started from the
  outputs before the first sample, solved as the banded lower-triangular system
  ``A y = x`` by LAPACK's ``dtbtrs`` (forward substitution, ``scipy.linalg.lapack``) in
  blocks of :data:`BLOCK` samples; nothing is compiled;
* :func:`frequency_response` - ``freqz(b, a, worN=freqs, fs=fs)`` (numpy).

``scipy.signal`` is the reference, not a dependency of these paths: ``clpc track``'s
report and ``clpc simulate`` start without it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["BLOCK", "all_pole", "fir", "frequency_response"]

#: Samples per banded solve of :func:`all_pole` (its band matrix holds ``na + 1`` rows of this).
BLOCK = 65536


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
    from scipy.linalg import lapack  # imported when used, as scipy.linalg elsewhere

    n = x.size
    y = np.empty(na + n)  # y(-na) .. y(-1), then the outputs
    y[:na] = start[::-1]
    size = min(BLOCK, max(n, 1))
    band = np.asfortranarray(np.repeat(den[:, None], size, axis=1))  # ab[k, j] = A[j + k, j]
    for lo in range(0, n, size):
        m = min(size, n - lo)
        rhs = x[lo : lo + m].copy()
        for k in range(1, na + 1):  # the outputs before the block, moved to the right side
            head = min(k, m)
            rhs[:head] -= den[k] * y[na + lo - k : na + lo - k + head]
        sol, info = lapack.dtbtrs(band[:, :m], rhs[:, None], uplo="L", diag="U")
        if info != 0:  # pragma: no cover - a unit-diagonal band cannot be singular
            raise RuntimeError(f"LAPACK dtbtrs failed (info = {info}).")
        y[na + lo : na + lo + m] = sol[:, 0]
    return y[na:]


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
