"""Preprocessing of sampled channels, experiment by experiment: detrend, filter, resample.

Each function takes the samples of one or more experiments stacked along axis 0 and the
length of each experiment, and works on every experiment separately (a filter's state, a
trend or a resampling never crosses from one experiment into the next). They back the
methods of :class:`Preprocessing`, a base class of :class:`~clpc.data.IOData`.
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction

import numpy as np

from clpc.data.experiments import RecordT
from clpc.data.validation import DataError, check_dt

__all__ = [
    "Preprocessing",
    "detrend_parts",
    "filter_parts",
    "resample_parts",
    "resample_ratio",
    "split_parts",
]


def split_parts(values: np.ndarray, lengths: Sequence[int]) -> list[np.ndarray]:
    """The experiments of ``values`` (views), one per entry of ``lengths``."""
    return np.split(values, np.cumsum(lengths)[:-1])


def detrend_parts(values: np.ndarray, lengths: Sequence[int], kind: str) -> np.ndarray:
    """Remove each experiment's mean (``"constant"``) or least-squares line (``"linear"``).

    Parameters
    ----------
    values : ndarray, shape (n, k)
    lengths : sequence of int
        Samples per experiment (summing to ``n``).
    kind : {"constant", "linear"}

    Returns
    -------
    ndarray, shape (n, k)
    """
    from scipy import signal

    if kind not in ("constant", "linear"):
        raise DataError(f"detrend kind must be 'constant' or 'linear'; got {kind!r}.")
    parts = [signal.detrend(p, axis=0, type=kind) for p in split_parts(values, lengths)]
    return np.concatenate(parts)


def filter_parts(
    values: np.ndarray,
    lengths: Sequence[int],
    dt: float,
    cutoff: float | Sequence[float],
    btype: str = "lowpass",
    order: int = 4,
    zero_phase: bool = True,
) -> np.ndarray:
    """Butterworth-filter every channel of every experiment.

    Parameters
    ----------
    values : ndarray, shape (n, k)
    lengths : sequence of int
        Samples per experiment.
    dt : float
        Sample time [s].
    cutoff : float or (float, float)
        Cut-off frequency [Hz] (two for ``"bandpass"``/``"bandstop"``), below the Nyquist
        frequency ``1 / (2 dt)``.
    btype : {"lowpass", "highpass", "bandpass", "bandstop"}
    order : int
        Filter order (doubled in effect by ``zero_phase``).
    zero_phase : bool
        Filter forwards and backwards (``scipy.signal.sosfiltfilt``: no delay, which an
        identification that estimates the delay needs) instead of causally (``sosfilt``).

    Returns
    -------
    ndarray, shape (n, k)

    Raises
    ------
    DataError
        A cut-off at or above the Nyquist frequency, or an experiment too short for the
        zero-phase filter's padding.
    """
    from scipy import signal

    nyquist = 0.5 / dt
    edges = np.atleast_1d(np.asarray(cutoff, dtype=np.float64))
    if not np.all((edges > 0) & (edges < nyquist)):
        raise DataError(
            f"cutoff must lie in (0, {nyquist:g}) Hz (the Nyquist frequency of dt = {dt:g} s); "
            f"got {edges.tolist()} Hz."
        )
    sos = signal.butter(
        order, edges if edges.size > 1 else edges[0], btype, fs=1.0 / dt, output="sos"
    )
    out = []
    for part in split_parts(values, lengths):
        if zero_phase:
            pad = 3 * (2 * sos.shape[0] + 1)
            if part.shape[0] <= pad:
                raise DataError(
                    f"an experiment of {part.shape[0]} samples is too short for a zero-phase "
                    f"filter of order {order} (needs more than {pad}); use zero_phase=False."
                )
            out.append(signal.sosfiltfilt(sos, part, axis=0))
        else:
            out.append(signal.sosfilt(sos, part, axis=0))
    return np.concatenate(out)


def resample_ratio(dt: float, new_dt: float, max_denominator: int = 1000) -> Fraction:
    """``dt / new_dt`` as a fraction ``up / down`` with ``down <= max_denominator``.

    Raises
    ------
    DataError
        The ratio is not such a fraction within 1e-9 (relative).
    """
    ratio = Fraction(dt / new_dt).limit_denominator(max_denominator)
    if abs(float(ratio) - dt / new_dt) > 1e-9 * dt / new_dt:
        raise DataError(
            f"cannot resample from dt = {dt:g} s to {new_dt:g} s: the ratio {dt / new_dt:.12g} "
            f"is not a fraction up/down with down <= {max_denominator}."
        )
    return ratio


def resample_parts(
    values: np.ndarray, lengths: Sequence[int], dt: float, new_dt: float
) -> tuple[np.ndarray, list[int]]:
    """Every experiment at the sample time ``new_dt`` (polyphase FIR, anti-aliased).

    ``scipy.signal.resample_poly`` by ``up / down = dt / new_dt``; the first sample of every
    experiment stays where it was.

    Returns
    -------
    values : ndarray, shape (m, k)
    lengths : list of int
        Samples per experiment after resampling.
    """
    from scipy import signal

    ratio = resample_ratio(dt, new_dt)
    parts = [
        signal.resample_poly(p, ratio.numerator, ratio.denominator, axis=0)
        for p in split_parts(values, lengths)
    ]
    if any(p.shape[0] == 0 for p in parts):
        raise DataError(f"an experiment is too short to resample to dt = {new_dt:g} s.")
    return np.concatenate(parts), [p.shape[0] for p in parts]


class Preprocessing:
    """``detrend``, ``filter`` and ``resample`` of a record; a base class of ``IOData``."""

    def detrend(self: RecordT, kind: str = "constant") -> RecordT:
        """Remove each channel's mean (``"constant"``) or line (``"linear"``) per experiment.

        Parameters
        ----------
        kind : {"constant", "linear"}
            Remove the mean (default) or the least-squares straight line.

        Returns
        -------
        IOData
        """
        both = detrend_parts(np.hstack([self.u, self.y]), self.experiments, kind)
        n_in = self.u.shape[1]
        return self._with(both[:, :n_in], both[:, n_in:])

    def filter(
        self: RecordT,
        cutoff: float | Sequence[float],
        btype: str = "lowpass",
        order: int = 4,
        zero_phase: bool = True,
    ) -> RecordT:
        """Butterworth-filter every channel (see :func:`filter_parts`).

        ``zero_phase=True`` (default) filters forwards and backwards, so the filter adds no
        delay (a causal filter would shift the estimated delay ``nk``).

        Parameters
        ----------
        cutoff : float or (float, float)
            Cut-off frequency [Hz] (two for ``"bandpass"``/``"bandstop"``), below the
            Nyquist frequency ``1 / (2 dt)``.
        btype : {"lowpass", "highpass", "bandpass", "bandstop"}
            Filter type; default ``"lowpass"``.
        order : int
            Butterworth order (default 4; doubled in effect by ``zero_phase``).
        zero_phase : bool
            Filter forwards and backwards (no delay, default) instead of causally.

        Returns
        -------
        IOData
        """
        both = filter_parts(
            np.hstack([self.u, self.y]), self.experiments, self.dt, cutoff, btype, order, zero_phase
        )
        n_in = self.u.shape[1]
        return self._with(both[:, :n_in], both[:, n_in:])

    def resample(self: RecordT, dt: float) -> RecordT:
        """The record at sample time ``dt`` [s] (polyphase, anti-aliased; per experiment).

        Parameters
        ----------
        dt : float
            New sample time [s], > 0; ``self.dt / dt`` must be a fraction ``up / down``
            with ``down <= 1000``.

        Returns
        -------
        IOData
        """
        new_dt = check_dt(dt)
        both, parts = resample_parts(np.hstack([self.u, self.y]), self.experiments, self.dt, new_dt)
        n_in = self.u.shape[1]
        return self._with(both[:, :n_in], both[:, n_in:], new_dt, parts)
