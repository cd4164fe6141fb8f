"""The crank servo's records (issue 18): random levels by trapezoid moves, or a slow sweep."""

from __future__ import annotations

import numpy as np

from clpc_paper.plants.commands import trapezoid_moves
from clpc_paper.plants.excitation import prbs

__all__ = ["crank_commands"]


def crank_commands(
    n_levels: int,
    *,
    hold: float = 6.0,
    low: float = -0.5,
    high: float = 3.0,
    sample_time: float = 0.01,
    seed: int | np.random.Generator | None = None,
    sweep: bool = False,
) -> np.ndarray:
    """The scenario's commands: random levels reached by trapezoid moves, plus a PRBS dither.

    Parameters
    ----------
    n_levels : int
        Number of random levels (uniform in ``[low, high]`` rad), each held ``hold`` s.
        With ``sweep=True``: the number of slow triangle legs instead.
    hold : float
        Seconds per level (moves at 3 rad/s and 30 rad/s^2, then a dwell); with ``sweep``
        the duration of one leg.
    low, high : float
        Range of the levels [rad].
    sample_time : float
        [s].
    seed : int or Generator, optional
        Levels and dither.
    sweep : bool
        A slow triangle between ``low`` and ``high`` instead of levels.

    Returns
    -------
    ndarray, shape (round(n_levels * hold / sample_time),)
        Position command [rad]: the moves plus a +/-0.1 rad PRBS (held at least 50 ms).
    """
    if isinstance(n_levels, bool) or not isinstance(n_levels, int) or n_levels < 2:
        raise ValueError(f"n_levels must be an int >= 2; got {n_levels!r}.")
    if not high > low:
        raise ValueError(f"high must be above low; got low={low!r}, high={high!r}.")
    rng = np.random.default_rng(seed)
    duration = n_levels * hold
    if sweep:
        t = np.arange(round(duration / sample_time)) * sample_time
        phase = (t / hold) % 2.0
        base = low + (high - low) * np.where(phase < 1.0, phase, 2.0 - phase)
    else:
        levels = rng.uniform(low, high, n_levels)
        base = trapezoid_moves(
            duration,
            sample_time,
            positions=tuple(levels.tolist()),
            max_velocity=3.0,
            max_acceleration=30.0,
            dwell=hold - 1.0,
        )
    dither = prbs(duration, sample_time, amplitude=0.1, min_hold=0.05, seed=rng)
    n = min(base.shape[0], dither.shape[0])
    return np.ascontiguousarray(base[:n] + dither[:n])
