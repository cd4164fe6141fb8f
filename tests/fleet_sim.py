"""A simulated fleet of drive axes for the fleet tests: alike but for one axis's gain."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from clpc.lpc import simulate_arx

DEN = [1.0, -1.5, 0.7]  # a lightly damped second-order axis, dt = 1 ms
NUM = [0.0, 0.1, 0.05]
DT = 0.001


def axis_record(seed: int, n: int, gain: float = 1.0) -> pd.DataFrame:
    """One axis: a random +-1 input held for 10 samples, the plant's output with noise."""
    rng = np.random.default_rng(seed)
    u = np.repeat(rng.choice([-1.0, 1.0], n // 10 + 1), 10)[:n]
    y = simulate_arx(DEN, [gain * b for b in NUM], u, noise=0.01 * rng.standard_normal(n))
    return pd.DataFrame({"t": np.arange(n) * DT, "u": u, "y": y})


def write_partitioned(folder: Path, n_axes: int, n: int, odd: int, gain: float) -> list[str]:
    """A partitioned Parquet dataset ``folder/axis=A00/part.parquet``...; the axis names."""
    names = []
    for k in range(n_axes):
        name = f"A{k:02d}"
        part = folder / f"axis={name}"
        part.mkdir(parents=True)
        axis_record(k, n, gain if k == odd else 1.0).to_parquet(part / "part.parquet")
        names.append(f"axis={name}")
    return names


def write_csvs(folder: Path, n_axes: int, n: int) -> list[Path]:
    """``folder/axisK.csv`` for K < n_axes (no odd axis)."""
    folder.mkdir(parents=True, exist_ok=True)
    files = []
    for k in range(n_axes):
        f = folder / f"axis{k}.csv"
        axis_record(100 + k, n).to_csv(f, index=False)
        files.append(f)
    return files
