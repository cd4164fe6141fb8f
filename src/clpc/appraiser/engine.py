"""The appraiser's engine: the kernel's inputs from the settings, and who runs the kernel.

``"compiled"`` runs :mod:`clpc.appraiser.kernel` through numba (the default),
``"python"`` runs the very same functions uncompiled (slow: for debugging and coverage).
``"auto"`` is ``"compiled"`` unless the environment variable ``CLPC_ENGINE`` says
otherwise.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from clpc.appraiser import kernel
from clpc.core.jit import compiled, numba_available
from clpc.core.rules import RobustRule, SolveSettings, solve_settings, transform_mode
from clpc.lpc.solve import fixed_transform
from clpc.model.structure import Structure

__all__ = ["ENGINES", "Engine", "resolve_engine", "window_plan"]

ENGINES = ("auto", "compiled", "python")


def resolve_engine(engine: Any) -> str:
    """The engine to use: ``engine``, with ``"auto"`` read from ``CLPC_ENGINE`` if set."""
    if engine == "auto":
        engine = os.environ.get("CLPC_ENGINE", "auto") or "auto"
    if engine not in ENGINES:
        raise ValueError(
            f"engine must be 'auto', 'compiled' or 'python' (argument or CLPC_ENGINE); got "
            f"{engine!r}."
        )
    if engine == "compiled" and not numba_available():
        raise ValueError(
            "engine='compiled' needs numba, which is not installed: pip install numba, "
            "or use engine='python' (slow)."
        )
    if engine == "auto":
        return "compiled" if numba_available() else "python"
    return str(engine)


def window_plan(
    structure: Structure,
    channels: tuple[int, int, bool],
    sizes: tuple[int, int, int],
    noise: np.ndarray | None,
) -> tuple[kernel.WindowPlan, int]:
    """Column maps of the lag rows and the transform of the solved problem.

    Parameters
    ----------
    structure : Structure
    channels : (n_inputs, n_outputs, miso)
        ``miso``: every equation uses every input (else the paper's pairing).
    sizes : (window, cluster, min_rows)
    noise : ndarray, shape (p,) or (p, p), optional
        Known noise covariance of the lag vector (weighted LPC).

    Returns
    -------
    plan : WindowPlan
    n_channels : int
        Channel blocks of a lag vector (the output, then one per input block).
    """
    n_in, n_out, miso = channels
    s = structure
    n_blocks = n_in if miso else 1
    p = s.n_params(n_blocks)
    col_channel = np.zeros(p, dtype=np.int64)
    for blk in range(n_blocks):
        col_channel[s.na + 1 + blk * (s.nb + 1) : s.na + 1 + (blk + 1) * (s.nb + 1)] = blk + 1
    # column a of equation e is buf[k - lag, chan] (buffer columns: inputs, then outputs)
    chan = np.empty((n_out, p), dtype=np.int64)
    lag = np.empty((n_out, p), dtype=np.int64)
    for e in range(n_out):
        chan[e, : s.na + 1] = n_in + e
        lag[e, : s.na + 1] = np.arange(s.na + 1)
        for i, inp in enumerate(range(n_in) if miso else [e]):
            cols = slice(s.na + 1 + i * (s.nb + 1), s.na + 1 + (i + 1) * (s.nb + 1))
            chan[e, cols] = inp
            lag[e, cols] = s.nk + np.arange(s.nb + 1)
    transform = np.eye(p) if noise is None else fixed_transform(noise, p)
    window, cluster, min_rows = sizes
    plan = kernel.WindowPlan(
        chan, lag, col_channel, np.ascontiguousarray(transform), window, cluster, min_rows
    )
    return plan, n_blocks + 1


def settings_for(
    method: tuple[str, str],
    rule: RobustRule,
    noise: np.ndarray | None,
    na: int,
    n_channels: int,
) -> SolveSettings:
    """The solve settings of an appraiser: ``method = (method, scaling)``.

    See :func:`clpc.core.rules.solve_settings` and :func:`clpc.core.rules.transform_mode`.
    """
    name, scaling = method
    mode = transform_mode(scaling, noise is not None)
    return solve_settings(rule, name == "robust", mode, na + 1, n_channels)


class Engine:
    """Runs the kernel compiled or as plain Python.

    Parameters
    ----------
    name : {"compiled", "python"}
    """

    def __init__(self, name: str) -> None:
        self.name = name
        if name == "compiled":
            self._solve = compiled(kernel.solve_windows)
            self._output = compiled(kernel.fsm_output)
        else:
            self._solve = kernel.solve_windows
            self._output = kernel.fsm_output

    def solve(
        self,
        samples: tuple[np.ndarray, np.ndarray],
        first_row: int,
        windows: tuple[int, int],
        plan: kernel.WindowPlan,
        settings: SolveSettings,
    ) -> kernel.Solved:
        """Solve ``windows = (j0, count)`` (see :func:`clpc.appraiser.kernel.solve_windows`)."""
        count = windows[1]
        e, p = plan.chan.shape
        out = kernel.Solved(
            theta=np.empty((count, e, p)),
            eigenvalues=np.empty((count, e, p)),
            c=np.empty((count, e)),
            noise_variance=np.empty((count, e)),
            separation=np.empty((count, e)),
            a0_weight=np.empty((count, e)),
            n_null=np.empty((count, e), dtype=np.int64),
            n_input_relations=np.empty((count, e), dtype=np.int64),
            degenerate=np.empty((count, e), dtype=np.bool_),
            excited=np.empty((count, e), dtype=np.bool_),
            n_rows=np.empty(count, dtype=np.int64),
        )
        self._solve(samples, first_row, windows, plan, settings, out)
        return out

    def output(
        self, solved: kernel.Solved, fs: kernel.FsmSettings, state: kernel.FsmState, n_inputs: int
    ) -> kernel.FsmOutput:
        """The FSM output of ``solved`` (``state`` is updated in place)."""
        count, e, p = solved.theta.shape

        def f(*shape: int) -> np.ndarray:
            return np.empty((count, *shape))

        def b(*shape: int) -> np.ndarray:
            return np.empty((count, *shape), dtype=np.bool_)

        out = kernel.FsmOutput(
            theta=f(e, p),
            c=f(e),
            accepted=b(e),
            has_model=b(e),
            determined=b(e),
            trusted=b(e),
            not_enough=b(),
            den=f(e, fs.na + 1),
            num=f(e, n_inputs, fs.nk + fs.nb + 1),
            stable=b(e),
            lambda_min=f(e),
            lambda_max=f(e),
            D=f(e),
            eig_ratio=f(e),
            J=f(e),
        )
        self._output(solved, fs, state, out)
        return out
