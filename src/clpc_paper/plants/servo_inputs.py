"""Checks of the arguments of :func:`~clpc_paper.plants.simulate_servo` and its open-loop twin."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from clpc_paper.checks import REAL
from clpc_paper.plants.servo_parameters import ServoParameters

__all__: list[str] = []


def _check_signal(values: Any, name: str, unit: str) -> np.ndarray:
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(
            f"{name} must be a 1-D array of numbers [{unit}]; could not convert "
            f"{type(values).__name__}. Pass a list or numpy array of floats."
        ) from None
    if arr.ndim != 1:
        raise ValueError(
            f"{name} must be 1-D (one value per sample) [{unit}]; got shape {arr.shape}. "
            "Pass a flat array (e.g. arr.ravel())."
        )
    if arr.shape[0] == 0:
        raise ValueError(f"{name} must have at least one sample; got an empty array.")
    bad = ~np.isfinite(arr)
    if bad.any():
        first = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"{name} must be finite; got {int(bad.sum())} non-finite value(s), first at "
            f"index {first} ({arr[first]!r}). Remove or interpolate NaN/inf samples."
        )
    return np.ascontiguousarray(arr)


def _check_rates(sample_time: Any, inner_rate: Any, params: ServoParameters) -> tuple[float, int]:
    if isinstance(sample_time, bool) or not isinstance(sample_time, REAL):
        raise ValueError(
            f"sample_time must be a positive number of seconds; got {sample_time!r}. "
            "Pass e.g. 0.01."
        )
    sample_time = float(sample_time)
    if not (math.isfinite(sample_time) and sample_time > 0):
        raise ValueError(
            f"sample_time must be finite and > 0 [s]; got {sample_time!r}. Pass e.g. 0.01."
        )
    rate = params.controller_rate if inner_rate is None else inner_rate
    if isinstance(rate, bool) or not isinstance(rate, REAL):
        raise ValueError(f"inner_rate must be a positive number [Hz] or None; got {rate!r}.")
    rate = float(rate)
    if not (math.isfinite(rate) and rate > 0):
        raise ValueError(f"inner_rate must be finite and > 0 [Hz]; got {rate!r}. Pass e.g. 5000.")
    ratio = rate * sample_time
    steps = round(ratio)
    if steps < 1 or abs(ratio - steps) > 1e-9 * max(1.0, ratio):
        raise ValueError(
            "inner_rate must be an integer multiple of 1/sample_time; got inner_rate="
            f"{rate:g} Hz and sample_time={sample_time:g} s (ratio {ratio:g}). Pass e.g. "
            f"inner_rate={max(1, math.ceil(ratio)) / sample_time:g}."
        )
    if rate < 1000.0:
        raise ValueError(
            f"inner_rate must be >= 1000 Hz (the drive's loop rate); got {rate:g} Hz. "
            "Pass a faster rate, e.g. 5000."
        )
    return sample_time, int(steps)


def _streams(seed: Any, n: int) -> list[np.random.Generator]:
    """``n`` independent generators derived from ``seed`` (int, SeedSequence, Generator)."""
    if isinstance(seed, np.random.Generator):
        if hasattr(seed, "spawn"):
            return list(seed.spawn(n))
        seeds = seed.integers(0, 2**63 - 1, size=n)  # pragma: no cover - numpy < 1.25
        return [np.random.default_rng(int(s)) for s in seeds]  # pragma: no cover
    if isinstance(seed, np.random.SeedSequence):
        seq = seed
    else:
        if seed is not None and (
            isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0
        ):
            raise ValueError(
                f"seed must be None, a non-negative int, a SeedSequence or a Generator; got "
                f"{seed!r}. Pass e.g. seed=0."
            )
        seq = np.random.SeedSequence(None if seed is None else int(seed))
    return [np.random.default_rng(child) for child in seq.spawn(n)]


def _check_params(params: Any) -> ServoParameters:
    if params is None:
        return ServoParameters()
    if not isinstance(params, ServoParameters):
        raise ValueError(
            f"params must be a ServoParameters or None; got {type(params).__name__}. "
            "Build one with ServoParameters(...) or ServoParameters().replace(...)."
        )
    return params
