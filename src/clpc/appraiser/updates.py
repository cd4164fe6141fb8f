"""From buffered samples to trace rows: batches of windows through the kernel.

Windows are independent, so batches may be solved on threads (``n_jobs``); the FSM output
(accept or hold) then runs in time order over the solved batches.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.appraiser import engine, kernel
from clpc.appraiser.trace import PER_EQUATION, Trace
from clpc.core.rules import SolveSettings
from clpc.model.structure import Structure

__all__ = ["KernelSetup", "TraceLabels", "batches", "empty_arrays", "solve_updates"]

#: windows solved per kernel call (bounds the temporaries of one call)
WINDOWS_PER_BATCH = 2048


@dataclass(frozen=True)
class KernelSetup:
    """What the kernel needs, fixed for a record: the plan and the settings."""

    plan: kernel.WindowPlan
    settings: SolveSettings
    fsm: kernel.FsmSettings
    n_inputs: int
    plain: tuple[tuple[Any, ...], ...] = ()  #: (plan, settings, fsm) as plain tuples

    def __post_init__(self) -> None:
        # what the kernel's entry point takes (fast to type at every call)
        plain = (tuple(self.plan), tuple(self.settings), tuple(self.fsm))
        object.__setattr__(self, "plain", plain)


@dataclass(frozen=True)
class TraceLabels:
    """What a trace says about its appraiser besides the numbers."""

    structure: Structure
    n_inputs: int
    mode: str
    sample_time: float
    names: tuple[tuple[str, ...], tuple[str, ...]]
    meta: dict[str, Any]

    def trace(self, index: np.ndarray, rows: np.ndarray, arrays: dict[str, np.ndarray]) -> Trace:
        """A trace of updates ending at samples ``index`` with ``rows`` lag vectors each."""
        return Trace(
            index=np.asarray(index, dtype=np.int64),
            time=np.asarray(index, dtype=np.float64) * self.sample_time,
            rows=np.asarray(rows, dtype=np.int64),
            not_enough_data=arrays.pop("not_enough"),
            arrays=arrays,
            structure=self.structure,
            n_inputs=self.n_inputs,
            mode=self.mode,
            sample_time=self.sample_time,
            input_names=self.names[0],
            output_names=self.names[1],
            meta=dict(self.meta),
        )


def batches(j_first: int, j_last: int, n_jobs: int) -> list[tuple[int, int]]:
    """``(j0, count)`` pairs covering updates ``j_first .. j_last`` (equal thread shares)."""
    n_new = j_last - j_first + 1
    n_batches = -(-n_new // WINDOWS_PER_BATCH)
    if n_jobs > 1:
        n_batches = -(-n_batches // n_jobs) * n_jobs
    size = -(-n_new // n_batches)
    return [(j0, min(size, j_last + 1 - j0)) for j0 in range(j_first, j_last + 1, size)]


def solve_updates(
    setup: KernelSetup,
    samples: tuple[np.ndarray, int],
    updates: tuple[int, int],
    state: kernel.FsmState,
    threads: tuple[int, Callable[..., Any]] = (1, map),
) -> list[tuple[int, int, dict[str, np.ndarray]]]:
    """Solve updates ``updates = (j_first, j_last)`` and run the FSM output over them.

    Parameters
    ----------
    setup : KernelSetup
    samples : (buffer, first_row)
        Buffered samples (n, channels) and the absolute lag row of ``buffer[0]`` minus
        ``max_lag`` (see :func:`clpc.appraiser.kernel.solve_windows`).
    updates : (j_first, j_last)
    state : FsmState
        The carried FSM state, updated in place.
    threads : (n_jobs, map)
        Thread count and ``map`` or a thread pool's ``map`` (batches are independent).

    Returns
    -------
    list of (j0, count, arrays)
        Per batch, the per-equation arrays of :data:`clpc.appraiser.trace.PER_EQUATION`
        plus ``not_enough`` and ``n_rows``.
    """
    buf, first_row = samples
    n_jobs, mapper = threads
    parts = batches(updates[0], updates[1], n_jobs)
    if n_jobs == 1 or len(parts) == 1:  # solve and output in one kernel call per batch
        run = engine.update
        return [(j0, c, _arrays(*run(samples, (j0, c), setup, state))) for j0, c in parts]

    def solve(batch: tuple[int, int]) -> kernel.Solved:
        return engine.solve(buf, first_row, batch, setup.plan, setup.settings)

    solved = list(mapper(solve, parts))  # windows are independent: threads
    return [  # the FSM output runs in time order
        (j0, count, _arrays(sol, engine.output(sol, setup.fsm, state, setup.n_inputs)))
        for (j0, count), sol in zip(parts, solved, strict=True)
    ]


def _arrays(sol: kernel.Solved, fsm: kernel.FsmOutput) -> dict[str, np.ndarray]:
    """The per-update arrays of a trace part, from the kernel's two outputs."""
    return {
        "theta": fsm.theta,
        "c": fsm.c,
        "accepted": fsm.accepted,
        "has_model": fsm.has_model,
        "determined": fsm.determined,
        "trusted": fsm.trusted,
        "not_enough": fsm.not_enough,
        "den": fsm.den,
        "num": fsm.num,
        "stable": fsm.stable,
        "lambda_min": fsm.lambda_min,
        "lambda_max": fsm.lambda_max,
        "D": fsm.D,
        "eig_ratio": fsm.eig_ratio,
        "J": fsm.J,
        "theta_estimate": sol.theta,
        "eigenvalues": sol.eigenvalues,
        "separation": sol.separation,
        "a0_weight": sol.a0_weight,
        "noise_variance": sol.noise_variance,
        "n_null": sol.n_null,
        "n_input_relations": sol.n_input_relations,
        "degenerate": sol.degenerate,
        "excited": sol.excited,
        "n_rows": sol.n_rows,
    }


def empty_arrays(n_equations: int, p: int, structure: Structure, n_inputs: int) -> dict:
    """Zero-row per-equation arrays of the right shapes and types (an empty trace)."""
    s = structure
    shapes = {
        "theta": (p,),
        "theta_estimate": (p,),
        "den": (s.na + 1,),
        "num": (n_inputs, s.nk + s.nb + 1),
        "eigenvalues": (p,),
    }
    ints = ("n_null", "n_input_relations")
    bools = ("degenerate", "determined", "excited", "trusted", "accepted", "has_model", "stable")
    arrays: dict[str, np.ndarray] = {}
    for key in PER_EQUATION:
        dtype = np.int64 if key in ints else (np.bool_ if key in bools else np.float64)
        arrays[key] = np.zeros((0, n_equations, *shapes.get(key, ())), dtype=dtype)
    arrays["not_enough"] = np.zeros(0, dtype=np.bool_)
    return arrays
