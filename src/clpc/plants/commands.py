"""Position command generators for the simulated servo (and any other plant).

Every generator returns a 1-D float64 array sampled at ``t_k = k * sample_time`` for
``k = 0 .. n - 1`` with ``n = floor(duration / sample_time) + 1`` samples, so both ends of
``[0, duration]`` are included when ``duration`` is a multiple of ``sample_time`` (the
paper's 2 s window at 10 ms holds 201 samples, Table 1). :func:`time_grid` returns these
instants. Positions are in rad, times in s, frequencies in Hz.

* :func:`ramp_with_saturation` - the paper's Fig. 5 command: flat, a ramp, then held at a
  level (the saturation), optionally repeated up and down;
* :func:`steps` - piecewise-constant levels;
* :func:`trapezoid_moves` - repeated point-to-point moves with velocity and acceleration
  limits (trapezoidal velocity profile) and dwell;
* :func:`chirp` - a swept sine (linear or logarithmic);
* :func:`prbs` - PRBS-like random steps with a minimum hold time (binary or multilevel);
* :func:`multisine` - a sum of sines with Schroeder (low crest factor) or random phases.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, Literal

import numpy as np

__all__ = [
    "chirp",
    "multisine",
    "prbs",
    "ramp_with_saturation",
    "steps",
    "time_grid",
    "trapezoid_moves",
]

_EPS = 1e-9  # relative tolerance when mapping instants to sample indices


def _number(value: Any, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name} must be a real number; got {value!r}. Pass a float.")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} must be finite; got {value!r}. Pass a finite float.")
    return value


def _positive(value: Any, name: str) -> float:
    value = _number(value, name)
    if value <= 0:
        raise ValueError(f"{name} must be > 0; got {value!r}. Pass a positive value.")
    return value


def _nonnegative(value: Any, name: str) -> float:
    value = _number(value, name)
    if value < 0:
        raise ValueError(f"{name} must be >= 0; got {value!r}. Pass zero or a positive value.")
    return value


def _grid(duration: Any, sample_time: Any) -> tuple[np.ndarray, float]:
    duration = _nonnegative(duration, "duration")
    sample_time = _positive(sample_time, "sample_time")
    n = math.floor(duration / sample_time * (1 + _EPS) + _EPS) + 1
    return np.arange(n) * sample_time, sample_time


def _index(t: float, sample_time: float) -> int:
    """First sample index whose instant is at or after ``t`` (with a small tolerance)."""
    return max(0, math.ceil(t / sample_time - _EPS * max(1.0, t / sample_time)))


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
    return _grid(duration, sample_time)[0]


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
    t, sample_time = _grid(duration, sample_time)
    start = _nonnegative(start, "start")
    ramp_time = _positive(ramp_time, "ramp_time")
    level = _number(level, "level")
    initial = _number(initial, "initial")
    hold_time = _nonnegative(hold_time, "hold_time")
    if isinstance(cycles, bool) or not isinstance(cycles, (int, np.integer)) or cycles < 1:
        raise ValueError(f"cycles must be an integer >= 1; got {cycles!r}. Pass e.g. 1.")
    cycles = int(cycles)
    end_last = start + cycles * ramp_time + (cycles - 1) * (2 * hold_time + ramp_time)
    if end_last > t[-1] * (1 + _EPS) + _EPS:
        raise ValueError(
            f"the last ramp must end within the duration; it ends at {end_last:g} s with "
            f"start={start:g}, ramp_time={ramp_time:g}, hold_time={hold_time:g}, "
            f"cycles={cycles}, duration={duration:g}. Lengthen duration or reduce cycles."
        )
    bt = [0.0, start]
    bv = [initial, initial]
    now = start
    for c in range(cycles):
        now += ramp_time
        bt.append(now)
        bv.append(level)
        if c < cycles - 1:
            for target in (level, initial, initial):
                now += hold_time if target == bv[-1] else ramp_time
                bt.append(now)
                bv.append(target)
    bt.append(max(now, t[-1]) + 1.0)
    bv.append(level)
    return np.interp(t, bt, bv)


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
    t, sample_time = _grid(duration, sample_time)
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
    out = np.full(t.shape, _number(initial, "initial"))
    for ti, li in zip(times_a, levels_a, strict=True):
        out[_index(float(ti), sample_time) :] = li
    return out


def _move_profile(tau: np.ndarray, distance: float, v_max: float, a_max: float) -> np.ndarray:
    """Travelled distance (>= 0) at ``tau`` after the start of a trapezoidal move."""
    if distance <= 0:
        return np.zeros_like(tau)
    if distance >= v_max * v_max / a_max:  # trapezoid
        t_acc = v_max / a_max
        t_flat = (distance - v_max * t_acc) / v_max
        v_peak = v_max
    else:  # triangle
        t_acc = math.sqrt(distance / a_max)
        t_flat = 0.0
        v_peak = a_max * t_acc
    d_acc = 0.5 * a_max * t_acc * t_acc
    t_total = 2 * t_acc + t_flat
    s = np.empty_like(tau)
    a = tau < t_acc
    b = ~a & (tau < t_acc + t_flat)
    c = ~a & ~b & (tau < t_total)
    d = tau >= t_total
    s[a] = 0.5 * a_max * tau[a] ** 2
    s[b] = d_acc + v_peak * (tau[b] - t_acc)
    rem = t_total - tau[c]
    s[c] = distance - 0.5 * a_max * rem**2
    s[d] = distance
    return s


def _move_time(distance: float, v_max: float, a_max: float) -> float:
    if distance <= 0:
        return 0.0
    if distance >= v_max * v_max / a_max:
        return distance / v_max + v_max / a_max
    return 2.0 * math.sqrt(distance / a_max)


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
    t, sample_time = _grid(duration, sample_time)
    pos = np.asarray(positions, dtype=np.float64).ravel()
    if pos.size < 2 or not np.all(np.isfinite(pos)):
        raise ValueError(
            f"positions must hold at least 2 finite targets [rad]; got {pos.tolist()}. "
            "Pass e.g. (0.0, 1.0)."
        )
    v_max = _positive(max_velocity, "max_velocity")
    a_max = _positive(max_acceleration, "max_acceleration")
    dwell = _nonnegative(dwell, "dwell")
    start = _nonnegative(start, "start")
    targets = np.roll(pos, -1)
    cycle_time = sum(
        _move_time(abs(float(b - a)), v_max, a_max) + dwell
        for a, b in zip(pos, targets, strict=True)
    )
    if cycle_time <= 0:
        raise ValueError(
            "the cycle of moves must take time; all positions are equal and dwell is 0. "
            "Give distinct positions or a positive dwell."
        )
    out = np.full(t.shape, pos[0])
    now = start
    i = 0
    t_end = t[-1]
    while now <= t_end:
        a, b = float(pos[i % pos.size]), float(pos[(i + 1) % pos.size])
        dist = abs(b - a)
        t_move = _move_time(dist, v_max, a_max)
        following = now + t_move + dwell
        # this move (and its dwell) covers the samples up to the start of the next one
        window = slice(_index(now, sample_time), min(t.size, _index(following, sample_time)))
        tau = t[window] - now
        out[window] = a + math.copysign(1.0, b - a) * _move_profile(tau, dist, v_max, a_max)
        now = following
        i += 1
    return out


def chirp(
    duration: float,
    sample_time: float = 0.01,
    *,
    amplitude: float = 0.5,
    f0: float = 0.1,
    f1: float = 5.0,
    method: Literal["linear", "logarithmic"] = "logarithmic",
    offset: float = 0.0,
) -> np.ndarray:
    """Swept-sine position command ``offset + amplitude * sin(phi(t))``.

    The instantaneous frequency goes from ``f0`` at ``t = 0`` to ``f1`` at ``duration``,
    linearly or geometrically; the command starts at ``offset`` (zero phase).

    Parameters
    ----------
    duration : float
        Length [s], > 0.
    sample_time : float, optional
        Sample period [s]; default 0.01 s.
    amplitude : float, optional
        Amplitude [rad], >= 0; default 0.5 rad. Mind the servo's limits: the peak velocity
        is ``2 pi f1 amplitude`` and the peak acceleration ``(2 pi f1)^2 amplitude``.
    f0, f1 : float, optional
        Start and end frequencies [Hz], > 0 and below the Nyquist frequency
        ``1 / (2 sample_time)``; default 0.1 and 5 Hz.
    method : {"linear", "logarithmic"}, optional
        Frequency sweep law; default ``"logarithmic"``.
    offset : float, optional
        Mean position [rad]; default 0.

    Returns
    -------
    numpy.ndarray
        Shape ``(n_samples,)`` position command [rad].

    Raises
    ------
    ValueError
        If a frequency is not in ``(0, Nyquist)``, ``duration`` is 0 or ``method`` is
        unknown.
    """
    t, sample_time = _grid(duration, sample_time)
    duration = _positive(duration, "duration")
    amplitude = _nonnegative(amplitude, "amplitude")
    offset = _number(offset, "offset")
    nyquist = 0.5 / sample_time
    for name, f in (("f0", f0), ("f1", f1)):
        f = _positive(f, name)
        if f >= nyquist:
            raise ValueError(
                f"{name} must be below the Nyquist frequency {nyquist:g} Hz "
                f"(sample_time={sample_time:g} s); got {f:g} Hz. Lower it or sample faster."
            )
    f0, f1 = float(f0), float(f1)
    if method == "linear":
        phase = 2 * np.pi * (f0 * t + 0.5 * (f1 - f0) / duration * t**2)
    elif method == "logarithmic":
        if f0 == f1:
            phase = 2 * np.pi * f0 * t
        else:
            ratio = f1 / f0
            phase = 2 * np.pi * f0 * duration / math.log(ratio) * (ratio ** (t / duration) - 1)
    else:
        raise ValueError(
            f"method must be 'linear' or 'logarithmic'; got {method!r}. Pass one of them."
        )
    return offset + amplitude * np.sin(phase)


def prbs(
    duration: float,
    sample_time: float = 0.01,
    *,
    amplitude: float = 0.5,
    min_hold: float = 0.2,
    switch_probability: float = 0.5,
    levels: Literal["binary", "uniform"] = "binary",
    offset: float = 0.0,
    seed: int | np.random.Generator | None = None,
) -> np.ndarray:
    """PRBS-like random steps with a minimum hold time.

    Time is divided into clock periods of ``min_hold`` (rounded to a whole number of
    samples, at least one). At every clock tick after the first, with probability
    ``switch_probability``, the command jumps: to the opposite level (``"binary"``:
    ``offset ± amplitude``) or to a new level drawn uniformly in
    ``[offset - amplitude, offset + amplitude]`` (``"uniform"``, multilevel, useful for
    nonlinear systems). Hold times are therefore multiples of the clock, at least
    ``min_hold``, geometrically distributed; with probability 1/2 the binary signal has
    the flat spectrum of a maximum-length PRBS up to about ``0.44 / min_hold`` Hz.

    Parameters
    ----------
    duration : float
        Length [s].
    sample_time : float, optional
        Sample period [s]; default 0.01 s.
    amplitude : float, optional
        Half the peak-to-peak range [rad], >= 0; default 0.5 rad.
    min_hold : float, optional
        Clock period = minimum hold time [s], > 0; default 0.2 s.
    switch_probability : float, optional
        Probability of a jump at each clock tick, in (0, 1]; default 0.5.
    levels : {"binary", "uniform"}, optional
        Two-level or multilevel signal; default ``"binary"``.
    offset : float, optional
        Centre level [rad]; default 0.
    seed : int or numpy.random.Generator, optional
        Seed for ``numpy.random.default_rng``; the output is deterministic for a given
        integer seed.

    Returns
    -------
    numpy.ndarray
        Shape ``(n_samples,)`` position command [rad].

    Raises
    ------
    ValueError
        If a parameter is out of range or ``levels`` is unknown.
    """
    t, sample_time = _grid(duration, sample_time)
    amplitude = _nonnegative(amplitude, "amplitude")
    min_hold = _positive(min_hold, "min_hold")
    p = _number(switch_probability, "switch_probability")
    if not 0 < p <= 1:
        raise ValueError(f"switch_probability must be in (0, 1]; got {p!r}. Pass e.g. 0.5.")
    offset = _number(offset, "offset")
    if levels not in ("binary", "uniform"):
        raise ValueError(f"levels must be 'binary' or 'uniform'; got {levels!r}.")
    rng = np.random.default_rng(seed)
    clock = max(1, round(min_hold / sample_time))
    n_ticks = -(-t.size // clock)
    switch = rng.random(n_ticks) < p
    switch[0] = True
    if levels == "binary":
        first = 1.0 if rng.random() < 0.5 else -1.0
        flips = np.cumsum(switch[1:])
        values = np.concatenate(([first], first * (1.0 - 2.0 * (flips % 2))))
    else:
        draws = rng.uniform(-1.0, 1.0, n_ticks)
        values = draws[np.maximum.accumulate(np.where(switch, np.arange(n_ticks), 0))]
    return offset + amplitude * np.repeat(values, clock)[: t.size]


def multisine(
    duration: float,
    sample_time: float = 0.01,
    *,
    amplitude: float = 0.5,
    f_min: float = 0.1,
    f_max: float = 5.0,
    n_tones: int = 20,
    spacing: Literal["log", "linear"] = "log",
    phases: Literal["schroeder", "random"] = "schroeder",
    offset: float = 0.0,
    seed: int | np.random.Generator | None = None,
) -> np.ndarray:
    """Sum of equal-amplitude sines, scaled so that its peak deviation is ``amplitude``.

    Parameters
    ----------
    duration : float
        Length [s].
    sample_time : float, optional
        Sample period [s]; default 0.01 s.
    amplitude : float, optional
        Peak of ``|command - offset|`` [rad], >= 0; default 0.5 rad.
    f_min, f_max : float, optional
        Lowest and highest tone [Hz], ``0 < f_min <= f_max < 1 / (2 sample_time)``;
        default 0.1 and 5 Hz.
    n_tones : int, optional
        Number of tones, >= 1; default 20.
    spacing : {"log", "linear"}, optional
        Tone spacing; default ``"log"``.
    phases : {"schroeder", "random"}, optional
        Schroeder phases ``-pi k (k - 1) / n_tones`` (low crest factor, deterministic) or
        uniform random phases drawn with ``seed``; default ``"schroeder"``.
    offset : float, optional
        Mean position [rad]; default 0.
    seed : int or numpy.random.Generator, optional
        Seed for the random phases.

    Returns
    -------
    numpy.ndarray
        Shape ``(n_samples,)`` position command [rad].

    Raises
    ------
    ValueError
        If a parameter is out of range or an option is unknown.
    """
    t, sample_time = _grid(duration, sample_time)
    amplitude = _nonnegative(amplitude, "amplitude")
    f_min = _positive(f_min, "f_min")
    f_max = _positive(f_max, "f_max")
    offset = _number(offset, "offset")
    nyquist = 0.5 / sample_time
    if not f_min <= f_max < nyquist:
        raise ValueError(
            f"frequencies must satisfy 0 < f_min <= f_max < Nyquist ({nyquist:g} Hz); got "
            f"f_min={f_min:g}, f_max={f_max:g}. Adjust them or sample faster."
        )
    if isinstance(n_tones, bool) or not isinstance(n_tones, (int, np.integer)) or n_tones < 1:
        raise ValueError(f"n_tones must be an integer >= 1; got {n_tones!r}. Pass e.g. 20.")
    if spacing == "log":
        freqs = np.geomspace(f_min, f_max, int(n_tones))
    elif spacing == "linear":
        freqs = np.linspace(f_min, f_max, int(n_tones))
    else:
        raise ValueError(f"spacing must be 'log' or 'linear'; got {spacing!r}.")
    k = np.arange(1, int(n_tones) + 1)
    if phases == "schroeder":
        phi = -np.pi * k * (k - 1) / n_tones
    elif phases == "random":
        phi = np.random.default_rng(seed).uniform(0.0, 2 * np.pi, int(n_tones))
    else:
        raise ValueError(f"phases must be 'schroeder' or 'random'; got {phases!r}.")
    x = np.zeros(t.size)
    for f, ph in zip(freqs, phi, strict=True):
        x += np.sin(2 * np.pi * f * t + ph)
    peak = np.abs(x).max()
    if peak > 0:
        x *= amplitude / peak
    return offset + x
