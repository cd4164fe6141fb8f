"""Position commands for the simulated servo (and any other plant).

Every generator returns a 1-D float64 array sampled on :func:`clpc_paper.plants.grid.time_grid`
(``t_k = k * sample_time``, both ends of ``[0, duration]`` included). Positions are in
rad, times in s.

* :func:`ramp_with_saturation` - the paper's Fig. 5 command: flat, a ramp, then held at a
  level (the saturation), optionally repeated up and down;
* :func:`steps` - piecewise-constant levels;
* :func:`trapezoid_moves` - repeated point-to-point moves with velocity and acceleration
  limits (trapezoidal velocity profile) and dwell.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from clpc_paper.checks import check_int
from clpc_paper.checks import check_nonnegative as nonnegative
from clpc_paper.checks import check_positive as positive
from clpc_paper.checks import check_real as real
from clpc_paper.plants.grid import EPS, first_index, sample_grid
from clpc_paper.plants.moves import MoveCycle, fill_moves

__all__ = ["ramp_with_saturation", "steps", "trapezoid_moves"]


def ramp_with_saturation(
    duration: float,
    sample_time: float = 0.01,
    *,
    start: float = 0.5,
    ramp_time: float = 0.9,
    level: float = 1.0,
    initial: float = 0.0,
    cycles: int = 1,
    hold_time: float = 1.0,
) -> np.ndarray:
    """Ramp-with-saturation position command (paper, Fig. 5).

    The command stays at ``initial`` until ``start``, rises linearly to ``level`` in
    ``ramp_time`` and then holds ("saturates") at ``level``. With ``cycles > 1`` it
    holds for ``hold_time``, ramps back to ``initial`` in ``ramp_time``, holds for
    ``hold_time`` and rises again, ``cycles`` rises in all; the last rise holds until the
    end.

    Parameters
    ----------
    duration : float
        Length [s].
    sample_time : float, optional
        Sample period [s]; default 0.01 s.
    start : float, optional
        Start of the first ramp [s]; default 0.5 s.
    ramp_time : float, optional
        Duration of each ramp [s], > 0; default 0.9 s (saturation at 1.4 s).
    level : float, optional
        Saturation level [rad]; default 1 rad.
    initial : float, optional
        Level before the ramp [rad]; default 0.
    cycles : int, optional
        Number of rising ramps, >= 1; default 1 (Fig. 5).
    hold_time : float, optional
        Hold at each end between ramps when ``cycles > 1`` [s]; default 1 s.

    Returns
    -------
    numpy.ndarray
        Shape ``(n_samples,)`` position command [rad].

    Raises
    ------
    ValueError
        If a parameter is out of range or the last ramp does not end within ``duration``.

    Notes
    -----
    The paper gives neither the level nor the slope of Fig. 5; the defaults (a 0.9 s ramp
    to 1 rad starting at 0.5 s, i.e. the corner at 1.4 s where the paper reports its
    largest identification error) are assumptions.
    """
    t, sample_time = sample_grid(duration, sample_time)
    start = nonnegative(start, "start")
    ramp_time = positive(ramp_time, "ramp_time")
    level = real(level, "level")
    initial = real(initial, "initial")
    hold_time = nonnegative(hold_time, "hold_time")
    cycles = check_int(cycles, "cycles", low=1)
    end_last = start + cycles * ramp_time + (cycles - 1) * (2 * hold_time + ramp_time)
    if end_last > t[-1] * (1 + EPS) + EPS:
        raise ValueError(
            f"the last ramp must end within the duration; it ends at {end_last:g} s with "
            f"start={start:g}, ramp_time={ramp_time:g}, hold_time={hold_time:g}, "
            f"cycles={cycles}, duration={duration:g}. Lengthen duration or reduce cycles."
        )
    times, values = _ramp_corners(start, ramp_time, hold_time, cycles, (initial, level))
    times.append(max(times[-1], t[-1]) + 1.0)
    values.append(level)
    return np.interp(t, times, values)


def _ramp_corners(
    start: float, ramp_time: float, hold_time: float, cycles: int, levels: tuple[float, float]
) -> tuple[list[float], list[float]]:
    """Corners ``(times [s], values [rad])`` of the ramps, up to the end of the last rise."""
    initial, level = levels
    times = [0.0, start]
    values = [initial, initial]
    now = start
    for c in range(cycles):
        now += ramp_time
        times.append(now)
        values.append(level)
        if c < cycles - 1:
            for target in (level, initial, initial):
                now += hold_time if target == values[-1] else ramp_time
                times.append(now)
                values.append(target)
    return times, values


def steps(
    duration: float,
    sample_time: float = 0.01,
    *,
    times: Sequence[float] = (0.1,),
    levels: Sequence[float] = (1.0,),
    initial: float = 0.0,
) -> np.ndarray:
    """Piecewise-constant command: ``levels[i]`` from ``times[i]`` on.

    Parameters
    ----------
    duration : float
        Length [s].
    sample_time : float, optional
        Sample period [s]; default 0.01 s.
    times : sequence of float, optional
        Switching instants [s], non-decreasing and >= 0; default ``(0.1,)``. An instant
        that falls between samples takes effect at the next sample.
    levels : sequence of float, optional
        Level after each switching instant [rad], same length as ``times``;
        default ``(1.0,)``.
    initial : float, optional
        Level before the first instant [rad]; default 0.

    Returns
    -------
    numpy.ndarray
        Shape ``(n_samples,)`` position command [rad].

    Raises
    ------
    ValueError
        If ``times`` and ``levels`` differ in length, ``times`` decreases or a value is
        not finite.
    """
    t, sample_time = sample_grid(duration, sample_time)
    times_a = np.asarray(times, dtype=np.float64).ravel()
    levels_a = np.asarray(levels, dtype=np.float64).ravel()
    if times_a.shape != levels_a.shape:
        raise ValueError(
            "times and levels must have the same length; got "
            f"{times_a.size} times and {levels_a.size} levels. Give one level per instant."
        )
    if not (np.all(np.isfinite(times_a)) and np.all(np.isfinite(levels_a))):
        raise ValueError("times and levels must be finite; got NaN or inf. Remove them.")
    if np.any(times_a < 0) or np.any(np.diff(times_a) < 0):
        raise ValueError(
            f"times must be >= 0 and non-decreasing; got {times_a.tolist()}. Sort them."
        )
    out = np.full(t.shape, real(initial, "initial"))
    for ti, li in zip(times_a, levels_a, strict=True):
        out[first_index(float(ti), sample_time) :] = li
    return out


def trapezoid_moves(
    duration: float,
    sample_time: float = 0.01,
    *,
    positions: Sequence[float] = (0.0, 1.0),
    max_velocity: float = 5.0,
    max_acceleration: float = 50.0,
    dwell: float = 0.5,
    start: float = 0.0,
) -> np.ndarray:
    """Repeated point-to-point moves with a trapezoidal velocity profile.

    The command holds ``positions[0]`` until ``start``, then moves to ``positions[1]``,
    ``positions[2]``, ..., ``positions[-1]``, ``positions[0]``, ... (cyclically), each move
    at most ``max_velocity`` and ``max_acceleration`` (a triangular velocity profile when
    the distance is too short to reach ``max_velocity``), with a ``dwell`` at each target,
    until ``duration``.

    Parameters
    ----------
    duration : float
        Length [s].
    sample_time : float, optional
        Sample period [s]; default 0.01 s.
    positions : sequence of float, optional
        Targets [rad], at least 2; default ``(0.0, 1.0)``.
    max_velocity : float, optional
        Velocity limit [rad/s], > 0; default 5 rad/s.
    max_acceleration : float, optional
        Acceleration limit [rad/s^2], > 0; default 50 rad/s^2.
    dwell : float, optional
        Rest at each target [s], >= 0; default 0.5 s.
    start : float, optional
        Start of the first move [s], >= 0; default 0.

    Returns
    -------
    numpy.ndarray
        Shape ``(n_samples,)`` position command [rad].

    Raises
    ------
    ValueError
        If a parameter is out of range, or the cycle of moves takes no time (all
        positions equal and no dwell).
    """
    grid = sample_grid(duration, sample_time)
    pos = np.asarray(positions, dtype=np.float64).ravel()
    if pos.size < 2 or not np.all(np.isfinite(pos)):
        raise ValueError(
            f"positions must hold at least 2 finite targets [rad]; got {pos.tolist()}. "
            "Pass e.g. (0.0, 1.0)."
        )
    cycle = MoveCycle(
        pos,
        positive(max_velocity, "max_velocity"),
        positive(max_acceleration, "max_acceleration"),
        nonnegative(dwell, "dwell"),
    )
    start = nonnegative(start, "start")
    if cycle.period() <= 0:
        raise ValueError(
            "the cycle of moves must take time; all positions are equal and dwell is 0. "
            "Give distinct positions or a positive dwell."
        )
    return fill_moves(grid, cycle, start)
