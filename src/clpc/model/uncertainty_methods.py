"""The uncertainty methods of :class:`clpc.LinearModel` (a base class of it).

Each reads the model's ``info["covariance"]`` through :mod:`clpc.model.uncertainty`.
"""

from __future__ import annotations

import numpy as np

from clpc.model import uncertainty

__all__ = ["UncertaintyMethods"]


class UncertaintyMethods:
    """Covariance, confidence intervals and delta-method spreads of a model's responses."""

    @property
    def covariance(self) -> np.ndarray:
        """Covariance of ``np.r_[den[1:], num]`` per output, shape (n_outputs, q, q)."""
        return uncertainty.covariance(self)

    def confidence_interval(self, level: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
        """``(lo, hi)`` ordered like ``np.r_[den[1:], num]`` (rows per output if several).

        Parameters
        ----------
        level : float
            Two-sided confidence level in (0, 1) (default 0.95; Student's ``t`` quantile).

        Returns
        -------
        lo, hi : ndarray, shape (q,) for a SISO model, else (n_outputs, q)
            See :func:`clpc.model.uncertainty.confidence_interval`.
        """
        return uncertainty.confidence_interval(self, level)

    def pole_std(self, output: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """Poles and the std of their real and imaginary parts, shape (na, 2).

        Parameters
        ----------
        output : int
            Output index (default 0).

        Returns
        -------
        poles : ndarray of complex, shape (na,)
        std : ndarray, shape (na, 2)
            Standard deviation of ``(Re p, Im p)`` per pole (delta method).
        """
        return uncertainty.pole_std(self, output)

    def dc_gain_std(self) -> np.ndarray:
        """Standard deviation of :meth:`dc_gain`, shape (n_outputs, n_inputs)."""
        return uncertainty.dc_gain_std(self)

    def frequency_response_std(
        self, freqs: np.ndarray | int = 512, output: int = 0, input: int = 0
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(freqs_hz, response, std of |G|, std of arg G [rad])`` (delta method).

        Parameters
        ----------
        freqs : int or ndarray
            Number of frequencies up to Nyquist, or frequencies [Hz] (default 512).
        output, input : int
            Channel pair (default 0, 0).

        Returns
        -------
        freqs_hz : ndarray, shape (n_freqs,)
            Frequencies [Hz].
        response : ndarray of complex, shape (n_freqs,)
        magnitude_std : ndarray, shape (n_freqs,)
            Standard deviation of ``|G|`` (same units as ``|G|``).
        phase_std : ndarray, shape (n_freqs,)
            Standard deviation of ``arg G`` [rad].
        """
        return uncertainty.frequency_response_std(self, freqs, output, input)

    def summary(self) -> str:
        """Coefficients with +- one standard deviation, poles and DC gains, as text."""
        return uncertainty.summary(self)
