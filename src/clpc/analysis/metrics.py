"""Fit metrics: fit % (NRMSE as in MATLAB's ``compare``), RMSE, VAF, k-step fit, whiteness."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.core.compact import compact_repr
from clpc.data.signals import signals

__all__ = ["fit_percent", "kstep_fit", "rmse", "vaf", "whiteness_test"]


def _pair(y: Any, y_hat: Any) -> tuple[np.ndarray, np.ndarray, bool]:
    a = np.asarray(y, dtype=np.float64)
    b = np.asarray(y_hat, dtype=np.float64)
    if a.shape != b.shape:
        raise ValueError(f"y and y_hat must have the same shape; got {a.shape} and {b.shape}.")
    if a.size == 0:
        raise ValueError("y and y_hat are empty.")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError(
            "y and y_hat must be finite; a diverging (unstable) simulation gives inf/NaN."
        )
    one = a.ndim == 1
    return (a[:, None], b[:, None], one) if one else (a, b, one)


def _out(values: np.ndarray, one: bool) -> Any:
    return float(values[0]) if one else values


def fit_percent(y: Any, y_hat: Any) -> Any:
    """Normalised fit ``100 (1 - ||y - y_hat|| / ||y - mean(y)||)`` in percent.

    Parameters
    ----------
    y, y_hat : array_like, shape (T,) or (T, n_channels)
        Measured and modelled signals.

    Returns
    -------
    float or ndarray, shape (n_channels,)
        100 is a perfect fit, 0 is as good as the mean, negative is worse than the mean
        (``-inf`` when ``y`` is constant and the model is not exact).
    """
    a, b, one = _pair(y, y_hat)
    err = np.linalg.norm(a - b, axis=0)
    ref = np.linalg.norm(a - a.mean(axis=0), axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        fit = np.where(
            ref > 0,
            100.0 * (1.0 - err / np.where(ref > 0, ref, 1.0)),
            np.where(err == 0, 100.0, -np.inf),
        )
    return _out(fit, one)


def rmse(y: Any, y_hat: Any) -> Any:
    """Root-mean-square error, same units as ``y``; per channel for 2-D input.

    Parameters
    ----------
    y, y_hat : array_like, shape (T,) or (T, n_channels)
        Measured and modelled signals (same shape, finite).

    Returns
    -------
    float or ndarray, shape (n_channels,)
    """
    a, b, one = _pair(y, y_hat)
    return _out(np.sqrt(np.mean((a - b) ** 2, axis=0)), one)


def vaf(y: Any, y_hat: Any) -> Any:
    """Variance accounted for, ``100 (1 - var(y - y_hat) / var(y))`` in percent.

    A constant ``y`` gives 100 when the error is constant too, else ``-inf`` (as
    :func:`fit_percent`).

    Parameters
    ----------
    y, y_hat : array_like, shape (T,) or (T, n_channels)
        Measured and modelled signals (same shape, finite).

    Returns
    -------
    float or ndarray, shape (n_channels,)
    """
    a, b, one = _pair(y, y_hat)
    var = np.var(a, axis=0)
    err_var = np.var(a - b, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(
            var > 0,
            100.0 * (1.0 - err_var / np.where(var > 0, var, 1)),
            np.where(err_var == 0, 100.0, -np.inf),
        )
    return _out(out, one)


def kstep_fit(model: Any, u: Any, y: Any = None, k: int = 1) -> Any:
    """Fit % of the ``k``-step-ahead prediction (skips the first ``max_lag + k - 1`` samples).

    For integrating plants (a motor from torque to position) a free-run simulation drifts
    and says little; the ``k``-step fit measures what the model knows about the dynamics.

    Parameters
    ----------
    model : LinearModel
        The model whose :meth:`~clpc.LinearModel.predict` is scored.
    u : array_like, shape (T,) or (T, n_inputs), or IOData
        Input samples, or a record of one experiment (its inputs and outputs; then give
        ``k`` by keyword).
    y : array_like, shape (T,) or (T, n_outputs)
        Measured outputs (predicted from and scored against; required with array inputs).
    k : int
        Prediction horizon in samples (>= 1, default 1).

    Returns
    -------
    float or ndarray, shape (n_outputs,)
        Fit % (:func:`fit_percent`): a float for 1-D ``y``, else one per output.
    """
    u, y = signals(u, y, what="kstep_fit")
    y_arr = np.asarray(y, dtype=np.float64)
    y_hat = model.predict(u, y_arr, k=k)
    # the first k - 1 predictions after max_lag still lean on measured outputs newer than
    # n - k (the record has no earlier past): skip them so every scored sample is a true
    # k-step prediction
    start = model.structure.max_lag + k - 1
    return fit_percent(y_arr[start:], y_hat[start:])


@compact_repr
@dataclass(frozen=True)
class WhitenessResult:
    """Ljung-Box portmanteau test of residual whiteness."""

    statistic: float
    p_value: float
    lags: int
    autocorrelation: np.ndarray

    @property
    def is_white(self) -> bool:
        """Whiteness is not rejected at the 5 % level."""
        return self.p_value > 0.05


def whiteness_test(residuals: Any, lags: int = 20) -> WhitenessResult:
    """Ljung-Box test of whether the residuals are white.

    Parameters
    ----------
    residuals : array_like, shape (T,)
        Prediction errors, e.g. ``y - model.predict(u, y)``.
    lags : int
        Number of autocorrelation lags tested.

    Returns
    -------
    WhitenessResult
        ``Q = T (T + 2) sum_k rho_k^2 / (T - k)``, compared with chi-square(``lags``).
    """
    e = np.asarray(residuals, dtype=np.float64).ravel()
    if lags < 1 or e.size <= lags + 1:
        raise ValueError(f"need 1 <= lags < len(residuals) - 1; got lags={lags}, len={e.size}.")
    e = e - e.mean()
    denom = float(e @ e)
    if denom == 0:
        raise ValueError("residuals are constant: whiteness is undefined.")
    n = e.size
    spec = np.fft.rfft(e, 2 * n)
    acf = np.fft.irfft(spec * np.conj(spec))[: lags + 1] / denom
    # clpc.model loads scipy.signal and with it scipy.stats (~0.5 s): only where it is used
    from scipy import stats

    from clpc.model.residuals import ljung_box

    q = ljung_box(acf[1:], n)

    return WhitenessResult(float(q), float(stats.chi2.sf(q, lags)), lags, acf[1:])
