"""The sample grid every command generator is built on.

A signal of ``duration`` at ``sample_time`` holds ``n = floor(duration / sample_time) + 1``
samples at ``t_k = k * sample_time``, so both ends of ``[0, duration]`` are included when
``duration`` is a multiple of ``sample_time`` (the paper's 2 s window at 10 ms holds 201
samples, Table 1).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from clpc_paper.checks import check_nonnegative as nonnegative
from clpc_paper.checks import check_positive as positive

__all__ = ["EPS", "Grid", "first_index", "sample_grid", "time_grid"]

EPS = 1e-9  # relative tolerance when mapping instants to sample indices


class Grid(NamedTuple):
    """Validated sample instants of a generator."""

    t: np.ndarray  #: shape (n_samples,), sample instants [s]
    sample_time: float  #: sample period [s]

    @property
    def nyquist(self) -> float:
        """Nyquist frequency ``1 / (2 sample_time)`` [Hz]."""
        return 0.5 / self.sample_time


def sample_grid(duration: Any, sample_time: Any) -> Grid:
    """Check ``duration`` (>= 0) and ``sample_time`` (> 0) [s]; return the sample instants.

    Parameters
    ----------
    duration : float
        Length of the signal [s], >= 0.
    sample_time : float
        Sample period [s], > 0.

    Returns
    -------
    Grid
        ``t`` of shape ``(floor(duration / sample_time) + 1,)`` [s] and ``sample_time``.
    """
    duration = nonnegative(duration, "duration")
    sample_time = positive(sample_time, "sample_time")
    n = math.floor(duration / sample_time * (1 + EPS) + EPS) + 1
    return Grid(np.arange(n) * sample_time, sample_time)


def first_index(t: float, sample_time: float) -> int:
    """First sample index whose instant is at or after ``t`` [s] (with a small tolerance)."""
    return max(0, math.ceil(t / sample_time - EPS * max(1.0, t / sample_time)))


def time_grid(duration: float, sample_time: float = 0.01) -> np.ndarray:
    """Sample instants used by every generator.

    Parameters
    ----------
    duration : float
        Length of the signal [s], >= 0.
    sample_time : float, optional
        Sample period [s], > 0; default 0.01 s.

    Returns
    -------
    numpy.ndarray
        Shape ``(floor(duration / sample_time) + 1,)``: ``k * sample_time`` [s].

    Raises
    ------
    ValueError
        If ``duration`` is negative or ``sample_time`` is not positive.
    """
    return sample_grid(duration, sample_time).t
