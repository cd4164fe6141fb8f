"""Excitation signals: swept sine, PRBS-like random steps, multisine.

Every generator returns ``offset + amplitude * shape`` as a 1-D float64 array sampled on
:func:`clpc_paper.plants.grid.time_grid` (``t_k = k * sample_time``); positions are in rad,
times in s, frequencies in Hz.

* :func:`chirp` - a swept sine (linear or logarithmic);
* :func:`prbs` - PRBS-like random steps with a minimum hold time (binary or multilevel);
* :func:`multisine` - a sum of sines with Schroeder (low crest factor) or random phases.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Literal

import numpy as np

from clpc_paper.checks import check_choice, check_int
from clpc_paper.checks import check_nonnegative as nonnegative
from clpc_paper.checks import check_positive as positive
from clpc_paper.checks import check_real as real
from clpc_paper.plants.grid import sample_grid

__all__ = ["chirp", "multisine", "prbs"]


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
    t, sample_time = grid = sample_grid(duration, sample_time)
    duration = positive(duration, "duration")
    amplitude = nonnegative(amplitude, "amplitude")
    offset = real(offset, "offset")
    for name, f in (("f0", f0), ("f1", f1)):
        f = positive(f, name)
        if f >= grid.nyquist:
            raise ValueError(
                f"{name} must be below the Nyquist frequency {grid.nyquist:g} Hz "
                f"(sample_time={sample_time:g} s); got {f:g} Hz. Lower it or sample faster."
            )
    law = check_choice(method, "method", ("linear", "logarithmic"))
    return offset + amplitude * np.sin(_sweep_phase(t, duration, float(f0), float(f1), law))


def _sweep_phase(t: np.ndarray, duration: float, f0: float, f1: float, law: str) -> np.ndarray:
    """Phase [rad] at ``t`` [s] of a sweep from ``f0`` to ``f1`` [Hz] over ``duration`` [s]."""
    if law == "linear":
        return 2 * np.pi * (f0 * t + 0.5 * (f1 - f0) / duration * t**2)
    if f0 == f1:
        return 2 * np.pi * f0 * t
    ratio = f1 / f0
    return 2 * np.pi * f0 * duration / math.log(ratio) * (ratio ** (t / duration) - 1)


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
    t, sample_time = sample_grid(duration, sample_time)
    amplitude = nonnegative(amplitude, "amplitude")
    min_hold = positive(min_hold, "min_hold")
    p = real(switch_probability, "switch_probability")
    if not 0 < p <= 1:
        raise ValueError(f"switch_probability must be in (0, 1]; got {p!r}. Pass e.g. 0.5.")
    offset = real(offset, "offset")
    check_choice(levels, "levels", ("binary", "uniform"))
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
    t, sample_time = grid = sample_grid(duration, sample_time)
    amplitude = nonnegative(amplitude, "amplitude")
    f_min = positive(f_min, "f_min")
    f_max = positive(f_max, "f_max")
    offset = real(offset, "offset")
    if not f_min <= f_max < grid.nyquist:
        raise ValueError(
            f"frequencies must satisfy 0 < f_min <= f_max < Nyquist ({grid.nyquist:g} Hz); "
            f"got f_min={f_min:g}, f_max={f_max:g}. Adjust them or sample faster."
        )
    n_tones = check_int(n_tones, "n_tones", low=1)
    spread = _SPACINGS[check_choice(spacing, "spacing", tuple(_SPACINGS))]
    freqs = spread(f_min, f_max, n_tones)
    k = np.arange(1, n_tones + 1)
    if check_choice(phases, "phases", ("schroeder", "random")) == "schroeder":
        phi = -np.pi * k * (k - 1) / n_tones
    else:
        phi = np.random.default_rng(seed).uniform(0.0, 2 * np.pi, n_tones)
    x = np.zeros(t.size)
    for f, ph in zip(freqs, phi, strict=True):
        x += np.sin(2 * np.pi * f * t + ph)
    peak = np.abs(x).max()
    if peak > 0:
        x *= amplitude / peak
    return offset + x


#: tone spacing laws of :func:`multisine`: ``law(f_min, f_max, n_tones)`` -> frequencies [Hz]
_SPACINGS: dict[str, Callable[[float, float, int], np.ndarray]] = {
    "log": np.geomspace,
    "linear": np.linspace,
}
