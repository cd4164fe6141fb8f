"""Point-to-point moves with a trapezoidal velocity profile (used by ``trapezoid_moves``).

A move of ``distance`` accelerates at ``a_max`` to ``v_max``, cruises and decelerates at
``a_max``; when the distance is too short to reach ``v_max`` the velocity profile is a
triangle. Distances in rad, velocities in rad/s, accelerations in rad/s^2, times in s.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from clpc_paper.plants.grid import Grid, first_index

__all__ = ["MoveCycle", "fill_moves", "move_profile", "move_time"]


class MoveCycle(NamedTuple):
    """Targets visited cyclically, with the limits of every move."""

    positions: np.ndarray  #: shape (n_targets,), targets [rad], n_targets >= 2
    v_max: float  #: velocity limit [rad/s], > 0
    a_max: float  #: acceleration limit [rad/s^2], > 0
    dwell: float  #: rest at each target [s], >= 0

    def period(self) -> float:
        """Time of one tour of all the targets, moves plus dwells [s]."""
        targets = np.roll(self.positions, -1)
        return sum(
            move_time(abs(float(b - a)), self.v_max, self.a_max) + self.dwell
            for a, b in zip(self.positions, targets, strict=True)
        )


def move_time(distance: float, v_max: float, a_max: float) -> float:
    """Duration [s] of a move of ``distance`` [rad] (0 for no move)."""
    if distance <= 0:
        return 0.0
    if distance >= v_max * v_max / a_max:
        return distance / v_max + v_max / a_max
    return 2.0 * math.sqrt(distance / a_max)


def move_profile(tau: np.ndarray, distance: float, v_max: float, a_max: float) -> np.ndarray:
    """Travelled distance (>= 0) [rad] at ``tau`` [s], shape kept, after a move's start."""
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


def fill_moves(grid: Grid, cycle: MoveCycle, start: float) -> np.ndarray:
    """Position [rad], shape ``grid.t.shape``: ``positions[0]`` until ``start`` [s], then moves.

    Each move (and its dwell) covers the samples up to the start of the next one.
    """
    t, sample_time = grid
    pos = cycle.positions
    out = np.full(t.shape, pos[0])
    now = start
    i = 0
    t_end = t[-1]
    while now <= t_end:
        a, b = float(pos[i % pos.size]), float(pos[(i + 1) % pos.size])
        dist = abs(b - a)
        following = now + move_time(dist, cycle.v_max, cycle.a_max) + cycle.dwell
        window = slice(
            first_index(now, sample_time), min(t.size, first_index(following, sample_time))
        )
        tau = t[window] - now
        out[window] = a + math.copysign(1.0, b - a) * move_profile(
            tau, dist, cycle.v_max, cycle.a_max
        )
        now = following
        i += 1
    return out
