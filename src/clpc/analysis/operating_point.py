"""Does a CLPC trace show a nonlinear plant? Window operating points and three numbers.

A per-window number cannot see operating-point nonlinearity (issue 18: ``D`` is the
window's excitation energy, and the scale-free ``lambda_min / lambda_max`` only sees
nonlinearity *inside* a window). It takes a comparison *across* windows:

* **locality** - the spread (standard deviation) of the windows' mean operating points
  over the spread of the samples: near 1 the windows sit at different operating points,
  near 0 every window sweeps the whole range (an oscillator) and cannot isolate one;
* **mismatch** - in each window, the RMS one-step error of a reference (global) model over
  the RMS error of the window's own fit; a global model that fits every operating point
  stays near 1;
* **trend** - Spearman's rank correlation between each trusted window's DC gain and its
  operating point, with the relative spread of those gains
  (:func:`clpc.appraiser.spread.gain_spread`).

:func:`operating_point_diagnostics` gives them with a plain verdict and its thresholds.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.appraiser.levels import window_levels
from clpc.appraiser.spread import (
    GAIN_SPREAD_LIMIT,
    TREND_LIMIT,
    gain_spread,
    level_trend,
    window_dc_gains,
)
from clpc.core.compact import compact_repr
from clpc.data.signals import signals
from clpc.lpc.arx import ARX

__all__ = [
    "LOCALITY_LIMIT",
    "MISMATCH_LIMIT",
    "TREND_LIMIT",
    "OperatingPointReport",
    "locality",
    "operating_point_diagnostics",
    "window_means",
]

#: windows are local when their means spread at least this share of the samples' spread
LOCALITY_LIMIT = 0.5
#: a reference model mismatches a window when its RMS error is this many times the window's
MISMATCH_LIMIT = 1.5


def window_means(values: Any, index: Any, rows: Any) -> np.ndarray:
    """Mean of ``values[k - rows + 1 .. k]`` for each window (newest sample ``k``).

    Parameters
    ----------
    values : array_like, shape (T,)
    index, rows : array_like of int, shape (n_windows,)
        Newest sample and number of samples of each window (a trace's ``index``, ``rows``).

    Returns
    -------
    ndarray, shape (n_windows,)
    """
    v = np.asarray(values, dtype=np.float64)
    k = np.asarray(index, dtype=np.int64)
    r = np.maximum(np.asarray(rows, dtype=np.int64), 1)
    if k.size and (k.max() >= v.size or (k - r + 1).min() < 0):
        raise ValueError(
            f"the windows reach samples 0..{int(k.max())} but the record has {v.size}; "
            "pass the record the trace was computed on."
        )
    return window_levels(v.reshape(-1, 1), k, r)[:, 0]


def locality(window_ops: np.ndarray, samples: np.ndarray) -> float:
    """``std(window operating points) / std(samples)`` (0 when the samples are constant)."""
    s = float(np.std(samples))
    return float(np.std(window_ops) / s) if s > 0 else 0.0


@compact_repr
@dataclass(frozen=True)
class OperatingPointReport:
    """Operating-point diagnostics of a trace (one entry per window where arrays).

    Attributes
    ----------
    operating_point : ndarray
        Mean output ``y`` over each window.
    dc_gain : ndarray
        DC gain of each window's own estimate (nan where the window is not trusted).
    mismatch : ndarray
        Reference RMS one-step error over the window's own RMS error (nan: untrusted).
    locality, median_mismatch, rank_correlation, gain_spread : float
        The summary numbers (see the module).
    verdict : str
        Plain words, with each number beside its threshold.
    multimodel_recommended, windows_local : bool
    """

    operating_point: np.ndarray
    dc_gain: np.ndarray
    mismatch: np.ndarray
    locality: float
    median_mismatch: float
    rank_correlation: float
    gain_spread: float
    verdict: str
    multimodel_recommended: bool
    windows_local: bool

    def summary(self) -> dict[str, Any]:
        """The scalar numbers, thresholds and verdict (JSON-safe)."""
        return {
            "locality": self.locality,
            "locality_limit": LOCALITY_LIMIT,
            "median_mismatch": self.median_mismatch,
            "mismatch_limit": MISMATCH_LIMIT,
            "rank_correlation": self.rank_correlation,
            "trend_limit": TREND_LIMIT,
            "gain_spread": self.gain_spread,
            "gain_spread_limit": GAIN_SPREAD_LIMIT,
            "windows_local": self.windows_local,
            "multimodel_recommended": self.multimodel_recommended,
            "verdict": self.verdict,
        }


def _one_step_error(reference: Any, u: np.ndarray, y: np.ndarray) -> np.ndarray:
    pred = np.asarray(reference.predict(u, y, k=1), dtype=np.float64).reshape(y.shape)
    err = y - pred
    err[: reference.structure.max_lag] = 0.0
    return err


def operating_point_diagnostics(
    trace: Any, u: Any, y: Any = None, reference: Any = None
) -> OperatingPointReport:
    """Compare the windows of a SISO trace across operating points.

    Parameters
    ----------
    trace : clpc.Trace
        From ``CLPC.run(u, y)`` at the record's own sample time (no decimation).
    u, y : array_like, shape (T,)
        The record the trace was computed on; or an IOData of one experiment in the place
        of ``u`` (then ``y`` is left out).
    reference : LinearModel, optional
        The global model to test; default least squares (:class:`clpc.ARX`) of the
        trace's structure on the whole record.

    Returns
    -------
    OperatingPointReport
    """
    u, y = signals(u, y, what="operating_point_diagnostics")
    uu = np.asarray(u, dtype=np.float64).ravel()
    yy = np.asarray(y, dtype=np.float64).ravel()
    if trace.n_equations != 1 or trace.n_inputs != 1:
        raise ValueError("operating_point_diagnostics handles single-input single-output traces.")
    if uu.shape != yy.shape:
        raise ValueError(f"u and y must have the same length; got {uu.size} and {yy.size}.")
    s = trace.structure
    lean = ARX(na=s.na, nb=s.nb, nk=s.nk, uncertainty=False, assess=False)  # residuals only
    ref = reference or lean.fit(uu, yy, dt=trace.sample_time)
    ops = window_means(yy, trace.index, trace.rows)
    err2 = _one_step_error(ref, uu, yy) ** 2
    ref_rms = np.sqrt(np.maximum(window_means(err2, trace.index, trace.rows), 0.0))
    theta = trace.arrays["theta_estimate"][:, 0, :]
    a0 = np.abs(theta[:, 0])
    ok = np.asarray(trace.arrays["trusted"][:, 0], dtype=bool) & (a0 > 1e-12)
    own_rms = np.sqrt(np.maximum(trace.arrays["noise_variance"][:, 0], 0.0)) / np.where(ok, a0, 1)
    mismatch = np.where(ok & (own_rms > 0), ref_rms / np.where(own_rms > 0, own_rms, 1), np.nan)
    gains = np.where(ok, window_dc_gains(theta, s.na), np.nan)
    loc = locality(ops, yy[s.max_lag :])
    good = ok & np.isfinite(gains)
    med = float(np.nanmedian(mismatch)) if np.any(np.isfinite(mismatch)) else float("nan")
    rho = level_trend(ops[good], gains[good])
    spread = gain_spread(gains[good])
    local = loc >= LOCALITY_LIMIT
    vary = med >= MISMATCH_LIMIT and abs(rho) >= TREND_LIMIT
    numbers = (
        f"reference/own error {med:.2f} in the median window (limit {MISMATCH_LIMIT}); "
        f"gain vs level rank correlation {rho:+.2f} (limit +/-{TREND_LIMIT}); gain spread "
        f"{spread:.2f} (limit {GAIN_SPREAD_LIMIT}); window locality {loc:.2f} (limit "
        f"{LOCALITY_LIMIT})"
    )
    if not local:
        verdict = (
            "windows cannot isolate operating points: each window sweeps most of the output "
            f"range ({numbers}); a multi-model must take its centres from the samples"
        )
    elif vary:
        verdict = f"parameters vary with the output level: a multi-model is recommended ({numbers})"
    else:
        verdict = f"no operating-point dependence found: one global model suffices ({numbers})"
    return OperatingPointReport(
        operating_point=ops,
        dc_gain=gains,
        mismatch=mismatch,
        locality=loc,
        median_mismatch=med,
        rank_correlation=rho,
        gain_spread=spread,
        verdict=verdict,
        multimodel_recommended=bool(local and vary),
        windows_local=bool(local),
    )
