"""Signal analysis of the experiment: free run, stable inverse, error profiles, on-line k-step.

Every function works on the decimated signals (``SAMPLE_TIME``) of one identification and
returns arrays or plain JSON-ready dicts.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy import signal

from clpc import LinearModel, Trace, fit_percent
from clpc_paper.experiment.settings import A0_MIN, RAMP

__all__ = [
    "constant_windows",
    "error_profile",
    "excitation",
    "fit",
    "free_run",
    "inverse_noise",
    "linear_bound",
    "online_prediction",
    "stable_inverse",
]


def stable_inverse(model: LinearModel, y: Any) -> np.ndarray:
    """The input that explains ``y``, ``u = (A y - k) / B``, stable even for a non-minimum-phase B.

    Zeros of ``B`` inside the unit circle are inverted causally, zeros outside
    anti-causally (backwards in time), the classical stable inversion of a non-minimum-phase
    system: sampling a double integrator puts a zero outside the unit circle, so the causal
    inverse (:meth:`LinearModel.infer_input`) diverges. Offline only (uses future samples).

    Parameters
    ----------
    model : LinearModel
        SISO model (engineering convention ``den``/``num``, intercept).
    y : array_like, shape (T,)
        Measured output; the outputs before ``y[0]`` are taken equal to ``y[0]``.

    Returns
    -------
    ndarray, shape (T,)
        ``u_hat[m]`` estimates ``u[m - nk]``; the last few samples lack their future and are
        less accurate. Units of the model's input.
    """
    return _inverse_b(model, _a_of(model, y) - model.intercept[0])  # = B u


def _a_of(model: LinearModel, y: Any) -> np.ndarray:
    """``den(z) y`` with the outputs before ``y[0]`` equal to ``y[0]``."""
    yv = np.asarray(y, dtype=np.float64)
    na = model.structure.na
    return np.asarray(signal.lfilter(model.den, [1.0], np.r_[np.full(na, yv[0]), yv])[na:])


def _inverse_b(model: LinearModel, w: np.ndarray) -> np.ndarray:
    """``u`` with ``num(z) u = w``: zeros of num inside the circle forwards, outside backwards.

    The forward part starts at rest (the inputs before ``w[0]`` are 0, as in
    :meth:`LinearModel.infer_input`); the backward part starts in the steady state of the
    last sample (the inputs after the record equal the last one), so a record that ends
    settled has no end transient.
    """
    b = model.num[model.structure.nk :]
    roots = np.roots(b) if b.size > 1 else np.array([])
    outside = roots[np.abs(roots) >= 1.0]
    v = signal.lfilter([1.0], np.real(np.poly(roots[np.abs(roots) < 1.0])), w) / b[0]
    if outside.size == 0:
        return np.asarray(v)
    c = np.real(np.poly(outside))  # prod (1 - r z^-1) = [1, c1, ..., cm]
    m = outside.size
    # backwards in time: c_m x(n - m) = v(n) - sum_{k<m} c_k x(n - k), poles 1/r inside
    num_b, den_b = np.r_[np.zeros(m), 1.0], c[::-1]
    zi = signal.lfilter_zi(num_b, den_b) * v[-1]
    xr, _ = signal.lfilter(num_b, den_b, v[::-1], zi=zi)
    return np.asarray(xr[::-1])


def inverse_noise(model: LinearModel, position_error: Any) -> np.ndarray:
    """The part of :func:`stable_inverse` that the output's measurement error alone makes.

    ``stable_inverse`` is affine in ``y``: ``stable_inverse(y + e) = stable_inverse(y) +
    inverse_noise(e)``. Its response to ``e = y_measured - y_true`` (the resolver's noise
    and quantisation, decimated) is the torque error no model can remove - the estimate's
    noise level.

    Parameters
    ----------
    model : LinearModel
    position_error : array_like, shape (T,)
        Measured minus true output [rad].

    Returns
    -------
    ndarray, shape (T,)
        Units of the model's input [N m].
    """
    return _inverse_b(model, _a_of(model, position_error))


def linear_bound(u: np.ndarray, y: np.ndarray, half_width: int = 3) -> float | None:
    """Fit % of the best linear non-causal estimate of ``u`` from ``y`` (least squares).

    ``u(n)`` is regressed on ``y(n - h) ... y(n + h)`` and a constant over the same record
    it is scored on: an optimistic bound for any linear inverse with that support, the
    actuator-model inverse included (``h = 3`` covers an N = 2 model's ``A(z)`` with its
    delay). Fit on ``u[h:-h]``.
    """
    h = int(half_width)
    n = y.size - 2 * h
    cols = np.stack([y[h + s : h + s + n] for s in range(-h, h + 1)], axis=1)
    x = np.c_[cols, np.ones(n)]
    beta, *_ = np.linalg.lstsq(x, u[h : h + n], rcond=None)
    return fit(u[h : h + n], x @ beta)


def free_run(model: LinearModel, u: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Free-run simulation from the input, started from the measured initial conditions.

    Parameters
    ----------
    model : LinearModel
    u, y : ndarray, shape (T,)
        Input and measured output (only ``y[:max_lag]`` is used).

    Returns
    -------
    ndarray, shape (T,)
        ``y[:max_lag]`` then the simulation; may hold inf/nan for an unstable model.
    """
    lag = model.structure.max_lag
    out = np.array(y, dtype=np.float64, copy=True)
    with np.errstate(over="ignore", invalid="ignore"):
        out[lag:] = model.simulate(u[lag:], y_init=y[:lag], u_init=u[:lag])
    return out


def fit(y: np.ndarray, y_hat: np.ndarray) -> float | None:
    """Fit % or None when the estimate diverged (inf/nan)."""
    if not np.all(np.isfinite(y_hat)):
        return None
    return float(fit_percent(y, y_hat))


def error_profile(err: np.ndarray, dt: float, corner: float | None = None) -> dict[str, Any]:
    """How an identification error evolves: RMS of the first and last second, peak, per second.

    Parameters
    ----------
    err : ndarray, shape (T,)
        Error samples (measured minus estimated), any unit.
    dt : float
        Sample time [s].
    corner : float, optional
        The ramp's saturation corner [s]: adds ``corner_peak``, the largest ``|err|``
        within 0.15 s of it, and ``mean_before_ramp``, the mean error before the ramp starts.

    Returns
    -------
    dict
        ``rms_first_second``, ``rms_last_second``, ``rms``, ``peak``, ``peak_time`` [s],
        ``rms_per_second`` (list), or ``{"diverged": True}`` for a non-finite error.
    """
    if not np.all(np.isfinite(err)):
        return {"diverged": True}
    n = max(1, round(1.0 / dt))
    per = [float(np.sqrt(np.mean(err[i : i + n] ** 2))) for i in range(0, err.size, n)]
    k = int(np.argmax(np.abs(err)))
    out: dict[str, Any] = {
        "diverged": False,
        "rms_first_second": per[0],
        "rms_last_second": float(np.sqrt(np.mean(err[-n:] ** 2))),
        "rms": float(np.sqrt(np.mean(err**2))),
        "peak": float(np.abs(err[k])),
        "peak_time": k * dt,
        "rms_per_second": per,
    }
    if corner is not None:
        t = np.arange(err.size) * dt
        near = np.abs(t - corner) <= 0.15
        out["corner_time"] = corner
        out["corner_peak"] = float(np.abs(err[near]).max()) if near.any() else None
        rest = t < RAMP.start
        out["mean_before_ramp"] = float(err[rest].mean()) if rest.any() else None
    return out


def online_prediction(trace: Trace, u: np.ndarray, y: np.ndarray, k: int) -> dict[str, Any]:
    """Fit % of the appraiser's own time-varying model as a ``k``-step-ahead predictor.

    The prediction of ``y(n)`` uses the parameters held at sample ``n - k`` (the last
    update with ``index <= n - k``), the outputs measured up to ``n - k`` and the inputs up
    to ``n``: what an on-line CLPC knows when it predicts. Samples without a usable model
    (no update yet, or ``a0 < A0_MIN``) are left out; ``coverage`` is the share kept.

    Parameters
    ----------
    trace : Trace
        SISO trace.
    u, y : ndarray, shape (T,)
        Decimated input and output.
    k : int
        Horizon in samples.
    """
    s = trace.structure
    na = s.na
    lag = max(na, s.nb + s.nk)
    n = np.arange(lag + k, y.size)
    last = np.searchsorted(trace.index, n - k, side="right") - 1
    held = np.maximum(last, 0)
    theta = trace.arrays["theta"][held]  # (N, 1, p)
    ok = (last >= 0) & (theta[:, 0, 0] >= A0_MIN)
    theta[~ok, 0, 0] = 1.0  # no usable model: any nonzero a0 (these samples are left out)
    # the trace's monic den/num of the held theta; y(m) = kk - sum a_i y(m-i) + sum b_j u(m-j)
    a, b = trace.arrays["den"][held, 0, 1:], trace.arrays["num"][held, 0, 0]
    a[~ok], b[~ok] = 0.0, 0.0  # the samples left out predict kk (finite, no warnings)
    kk = trace.c[held] / theta[:, 0, 0]
    past = [y[n - k - i] for i in range(na)]  # past[i] = y(m - 1 - i) for m = n - k + 1
    for step in range(1, k + 1):
        m = n - k + step
        new = kk - sum(a[:, i] * past[i] for i in range(na))
        new = new + sum(b[:, j] * u[m - j] for j in range(s.nk, b.shape[1]))
        past = [new, *past[:-1]]
    if not ok.any():
        return {"fit": None, "coverage": 0.0}
    return {"fit": fit(y[n[ok]], past[0][ok]), "coverage": float(np.mean(ok))}


def excitation(command: np.ndarray, dt: float) -> dict[str, Any]:
    """Where the command's second difference is not zero (what excites an N = 2 model)."""
    d2 = np.abs(np.diff(command, 2))
    active = d2 > 1e-9 * max(float(np.ptp(command)), 1e-300)
    return {
        "samples": int(command.size),
        "sample_time": dt,
        "second_difference_nonzero_fraction": float(np.mean(active)),
        "second_difference_nonzero_samples": int(np.sum(active)),
    }


def constant_windows(trace: Trace, u: np.ndarray) -> np.ndarray:
    """Updates whose window holds an exactly constant input (nothing to identify).

    Parameters
    ----------
    trace : Trace
        SISO trace of the decimated record ``u``.
    u : ndarray, shape (T,)
        Decimated input (the position command).

    Returns
    -------
    ndarray of bool, shape (len(trace),)
    """
    lag = trace.structure.max_lag
    first = np.maximum(trace.index - trace.rows - lag + 1, 0)
    return np.array(
        [np.ptp(u[a : b + 1]) == 0.0 for a, b in zip(first, trace.index, strict=True)], dtype=bool
    )
