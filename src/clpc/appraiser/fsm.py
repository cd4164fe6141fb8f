"""The FSM's state transition: new samples in, the updates they complete out.

Functions of an appraiser ``a`` (:class:`clpc.CLPC`): the kernel's fixed setup for the
record, the lag rows of the current window, and :func:`consume`, which appends decimated
samples, solves the windows they close, runs the accept-or-hold output and forgets the
samples no later window needs.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.appraiser import kernel
from clpc.appraiser.buffer import SampleBuffer
from clpc.appraiser.engine import settings_for, window_plan
from clpc.appraiser.trace import Trace
from clpc.appraiser.updates import KernelSetup, TraceLabels, empty_arrays, solve_updates
from clpc.core.rules import trust_rows
from clpc.data import DataError
from clpc.lpc.regressors import miso_regressor
from clpc.lpc.solve import noise_covariance
from clpc.model.structure import check_mode, default_mode

__all__ = [
    "check_window",
    "consume",
    "empty_trace",
    "init_channels",
    "kernel_setup",
    "lag_rows",
    "mode",
    "time_step",
]


# ------------------------------------------------------------------ the record's layout
def mode(a: Any) -> str:
    """The MIMO mode in use (validated against the channel counts)."""
    assert a._n_in is not None and a._n_out is not None
    chosen = a.mimo or default_mode(a._n_in, a._n_out)
    check_mode(chosen, a._n_in, a._n_out)
    return str(chosen)


def n_blocks(a: Any) -> int:
    assert a._n_in is not None
    return a._n_in if mode(a) == "miso" else 1


def n_params(a: Any) -> int:
    return a.structure.n_params(n_blocks(a))


def min_rows(a: Any) -> int:
    return a.min_rows if a.min_rows is not None else 2 * n_params(a)


def noise(a: Any) -> np.ndarray | None:
    """The lag vector's known noise covariance, if any (:func:`clpc.lpc.solve.noise_covariance`)."""
    return noise_covariance(a.noise_cov, a.noise_ratio, a.structure, n_blocks(a))


def time_step(a: Any) -> float:
    """Seconds per (decimated) sample: sample_time, else the data's, else 1."""
    return a.sample_time or a._record_dt or a.data_sample_time or 1.0


def check_window(a: Any, p: int) -> None:
    """Refuse a window that can never hold ``min_rows`` lag vectors for ``p`` parameters."""
    need = a.min_rows if a.min_rows is not None else 2 * p
    if a.window_size < max(need, p + 1):
        raise ValueError(
            f"window_size={a.window_size} cannot hold the {max(need, p + 1)} lag vectors that "
            f"{p} parameters need (min_rows, default 2 p): every update would be 'not enough "
            f"data'. Use window_size >= {max(need, p + 1)} or fewer parameters."
        )


def init_channels(a: Any, n_in: int, n_out: int, names: Any = None) -> None:
    """Fix the record's channels on first data; later chunks must match them."""
    if a._n_in is None:
        a._n_in, a._n_out = n_in, n_out
        mode(a)  # validates
        p = n_params(a)
        check_window(a, p)
        a._buffer = SampleBuffer(n_in + n_out)
        a._last_theta = np.zeros((n_out, p))
        a._last_c = np.zeros(n_out)
        a._has_model = np.zeros(n_out, dtype=bool)
        if names is not None:
            a._names = names
    elif (n_in, n_out) != (a._n_in, a._n_out):
        raise DataError(
            f"the appraiser was fed {a._n_in} input(s) and {a._n_out} output(s); "
            f"this chunk has {n_in} and {n_out}. Call reset() to start a new record."
        )


# ------------------------------------------------------------------ updates
def kernel_setup(a: Any) -> KernelSetup:
    """The kernel's plan and settings (fixed per record)."""
    if a._setup is None:
        assert a._n_in is not None and a._n_out is not None
        s = a.structure
        miso = mode(a) == "miso"
        cov = noise(a)
        sizes = (a.window_size, a.cluster_size, min_rows(a))
        plan, n_channels = window_plan(s, (a._n_in, a._n_out, miso), sizes, cov)
        a._setup = KernelSetup(
            plan=plan,
            settings=settings_for((a.method, a.scaling), a.rule, cov, s.na, n_channels),
            fsm=kernel.FsmSettings(
                min_rows(a),
                a.guard,
                trust_rows(n_params(a), a.window_size) if a.trust_rows is None else a.trust_rows,
                a.rule.separation,
                s.na,
                s.nb,
                s.nk,
                not miso,
            ),
            n_inputs=a._n_in,
        )
    return a._setup


def labels(a: Any) -> TraceLabels:
    n_in, n_out = a._n_in or 1, a._n_out or 1
    names = a._names or (
        tuple(f"u{i}" for i in range(n_in)) if n_in > 1 else ("u",),
        tuple(f"y{i}" for i in range(n_out)) if n_out > 1 else ("y",),
    )
    return TraceLabels(
        structure=a.structure,
        n_inputs=n_in,
        mode=mode(a) if a._n_in is not None else "siso",
        sample_time=time_step(a),
        names=names,
        meta={"guard": a.guard, "gate": a.guard, "method": a.method, "scaling": a.scaling},
    )


# ================================================================= updates
def lag_rows(a: Any, buf: np.ndarray) -> np.ndarray:
    """Lag rows of every equation from decimated samples ``buf``: (E, n, p)."""
    assert a._n_in is not None and a._n_out is not None
    u, y = buf[:, : a._n_in], buf[:, a._n_in :]
    if buf.shape[0] <= a.structure.max_lag:
        return np.empty((a._n_out, 0, n_params(a)))
    miso = mode(a) == "miso"
    return np.stack(
        [
            miso_regressor(y[:, j], u if miso else u[:, j : j + 1], a.structure)
            for j in range(a._n_out)
        ]
    )


def consume(a: Any, new: np.ndarray) -> Trace:
    """Append decimated samples and compute the updates they complete."""
    if new.shape[0] == 0:
        return empty_trace(a)
    buf = a._buffer
    assert buf is not None and a._last_theta is not None
    assert a._last_c is not None and a._has_model is not None
    buf.append(new)
    a._n_seen += new.shape[0]
    s, c, w = a.structure, a.cluster_size, a.window_size
    j_last = max(a._n_seen - s.max_lag, 0) // c
    trace = empty_trace(a)
    if j_last > a._j_done:
        state = kernel.FsmState(a._last_theta, a._last_c, a._has_model)
        threads = (a.n_jobs, a._executor().map if a.n_jobs > 1 else map)
        parts = solve_updates(
            kernel_setup(a),
            (buf.data, buf.start - s.max_lag),
            (a._j_done + 1, j_last),
            state,
            threads,
        )
        if a._trace_labels is None:
            a._trace_labels = labels(a)
        trace_labels = a._trace_labels
        traces = []
        for j0, count, arrays in parts:
            index = s.max_lag + c * np.arange(j0, j0 + count) - 1
            traces.append(trace_labels.trace(index, arrays.pop("n_rows"), arrays))
        trace = traces[0] if len(traces) == 1 else Trace.concat(traces)
        a._j_done = j_last
    # keep only what the next window needs: rows from max(0, C (j+1) - W - C)
    buf.drop_before(max(0, c * (a._j_done + 1) - w - c))
    return trace


def empty_trace(a: Any) -> Trace:
    """A trace without updates, shaped for the appraiser's channels (cached once known)."""
    if a._empty is not None:
        return a._empty
    e = a._n_out or 1
    p = n_params(a) if a._n_in is not None else a.structure.n_params()
    arrays = empty_arrays(e, p, a.structure, a._n_in or 1)
    z = np.zeros(0, dtype=np.int64)
    empty = labels(a).trace(z, z, arrays)
    if a._n_in is not None:
        a._empty = empty
    return empty
