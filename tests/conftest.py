"""Shared fixtures: fixed seeds, known systems, rich inputs, hand-built models.

Every random number in the suite comes from ``numpy.random.default_rng(seed)`` with an
explicit seed, so every statistical claim is checked on the same draws every time.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np
import pytest
from scipy import signal

from clpc.lpc.regressors import Structure
from clpc.model import LinearModel

SEED = 20240607


@dataclass(frozen=True)
class System:
    """A known SISO system in the monic convention: ``den(z^-1) y = num(z^-1) u``."""

    den: np.ndarray  # [1, a1, ..., a_na]
    num: np.ndarray  # nk leading zeros, then [b0, ..., b_nb]
    na: int
    nb: int
    nk: int

    @property
    def truth(self) -> np.ndarray:
        """The monic parameter vector ``[den, num]`` that estimates are compared with."""
        return np.concatenate([self.den, self.num])

    def output(self, u: np.ndarray) -> np.ndarray:
        """Noise-free output from zero initial conditions."""
        return signal.lfilter(self.num, self.den, u)


@pytest.fixture
def rng() -> np.random.Generator:
    """A generator with the suite's fixed seed (a fresh one per test)."""
    return np.random.default_rng(SEED)


@pytest.fixture
def rich_input() -> Callable[..., np.ndarray]:
    """Rich (persistently exciting) input: white noise plus a random multisine.

    ``rich_input(T, seed=0, m=1)`` returns shape (T,) for ``m == 1``, else (T, m).
    """

    def make(n: int, seed: int = 0, m: int = 1) -> np.ndarray:
        gen = np.random.default_rng(seed)
        t = np.arange(n)
        cols = []
        for _ in range(m):
            freqs = gen.uniform(0.01, 0.45, size=5)
            phases = gen.uniform(0, 2 * np.pi, size=5)
            sines = np.sin(2 * np.pi * freqs[:, None] * t[None, :] + phases[:, None]).sum(0)
            cols.append(gen.standard_normal(n) + 0.3 * sines)
        out = np.column_stack(cols)
        return out[:, 0] if m == 1 else out

    return make


@pytest.fixture(scope="session")
def siso2() -> System:
    """na = nb = 2, nk = 0: poles 0.75 +- 0.37j (|p| = 0.84), zeros -0.37 and -1.63."""
    return System(np.array([1.0, -1.5, 0.7]), np.array([0.5, 1.0, 0.3]), 2, 2, 0)


@pytest.fixture(scope="session")
def siso_delay() -> System:
    """na = 3, nb = 1, nk = 2 (na != nb, delayed input)."""
    return System(np.array([1.0, -0.6, 0.2, -0.05]), np.array([0.0, 0.0, 1.0, 0.4]), 3, 1, 2)


@pytest.fixture(scope="session")
def eiv_system() -> System:
    """Order-2 system whose output has the input's standard deviation for white input.

    ``sum h_k^2 = 1`` (impulse response energy), so with a unit-variance white input the
    noise-free output has unit variance too: equal noise variances on u and y then also
    give equal signal-to-noise ratios, and the default per-channel scaling is consistent.
    """
    den = np.array([1.0, -1.2, 0.5])
    num = np.array([0.2, 0.3, -0.1])
    h = signal.lfilter(num, den, np.r_[1.0, np.zeros(4000)])
    return System(den, num / np.sqrt(h @ h), 2, 2, 0)


@pytest.fixture
def make_model() -> Callable[..., LinearModel]:
    """Build a SISO :class:`LinearModel` from monic ``den``/``num`` (and an intercept).

    ``make_model(den, num, nk=0, intercept=0.0, dt=1.0)``: ``num`` includes the ``nk``
    leading zeros. The paper vector is ``theta = [den; -num[nk:]] / norm`` (so that
    ``model.num == num`` and ``model.den == den``).
    """

    def make(
        den: np.ndarray,
        num: np.ndarray,
        nk: int = 0,
        intercept: float = 0.0,
        dt: float = 1.0,
    ) -> LinearModel:
        den = np.asarray(den, dtype=float)
        num = np.asarray(num, dtype=float)
        theta = np.concatenate([den, -num[nk:]])
        norm = np.linalg.norm(theta)
        structure = Structure(den.size - 1, num.size - nk - 1, nk)
        return LinearModel(
            theta=theta / norm,
            structure=structure,
            n_inputs=1,
            mode="siso",
            c=np.array([intercept / norm]),
            dt=dt,
        )

    return make


@pytest.fixture
def own_shm(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """The shared traces of this test in a folder of ``/dev/shm`` of its own.

    Tests that check the shared trace's file is removed look at ``shared_rows.SHM``; with
    ``-n 2`` another test may make its own files in ``/dev/shm`` at the same time. Without
    ``/dev/shm`` nothing is changed (those tests skip).
    """
    import shutil
    import uuid
    from pathlib import Path

    from clpc.distributed import shared_rows

    if not shared_rows.SHM.is_dir():
        yield
        return
    folder = Path(shared_rows.SHM) / f"clpc-test-{uuid.uuid4().hex}"
    folder.mkdir()
    monkeypatch.setattr(shared_rows, "SHM", folder)
    try:
        yield
    finally:
        shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture(scope="module")
def client() -> Iterator[object]:
    """A local Dask cluster of two worker processes, one per test module that asks for it."""
    from clpc.distributed import dask_client

    with dask_client(workers=2) as c:
        yield c


@pytest.fixture
def shm_files() -> object:
    """A function listing the shared traces in ``shared_rows.SHM`` (empty without it)."""
    from clpc.distributed import shared_rows

    def listed() -> set[object]:
        shm = shared_rows.SHM
        return set(shm.glob("clpc-trace-*")) if shm.is_dir() else set()

    return listed
