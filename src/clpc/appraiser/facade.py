"""CLPC: the paper's appraiser (section V), a finite-state machine over time windows.

Semantics (``docs/clpc.md`` says the same):

* Samples are numbered ``k = 0, 1, 2, ...`` (after decimation to ``sample_time``). The lag
  vector ``z_k`` exists once ``k >= max_lag`` (``max_lag = N`` for the paper's structure).
* ``window_size`` ``W`` is the number of lag vectors (rows of M, eq. 36) in one LPC.
  The counter counts lag vectors; each time it reaches ``cluster_size`` ``C`` (the
  paper's ``data_cluster_dimension``) the appraiser re-runs LPC on the window and resets the
  counter; between updates the outputs hold their last values.
* The window grows from the first lag vector until it holds ``W`` of them, then slides
  (the rising D of the paper's Fig. 6). Update ``j`` (``j = 1, 2, ...``) closes after lag
  vector ``m = C j`` and uses rows ``[max(0, m - W), m)``; its ``index`` is the newest
  sample, ``k = max_lag + m - 1``.
* An update with fewer than ``min_rows`` rows is flagged ``not_enough_data``; degenerate
  windows (nothing varies, a constant channel) are flagged ``degenerate``; with ``gate=True``
  an estimate the window does not determine (see :mod:`clpc.solve`) is not accepted. An
  update that is not accepted holds the last accepted parameters; parameters are never NaN
  (zeros, with ``has_model=False``, until a first estimate is accepted).
* ``sample_time``: data sampled faster by an integer factor are low-pass filtered (causal
  4th-order Butterworth at 0.8 of the new Nyquist frequency, filter state carried across
  chunks) and every factor-th sample is kept (samples ``0, f, 2f, ...``).

The state (the last window of samples, the counter, the last parameters, the filter state) is
the paper's FSM state; :meth:`CLPC.state_dict` / :meth:`CLPC.from_state_dict` serialise it.
"""

from __future__ import annotations

import importlib.util
import json
import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict
from typing import Any

import numpy as np
from scipy import signal

from clpc.appraiser.sliding import window_scatter
from clpc.appraiser.trace import PER_EQUATION, Trace
from clpc.data import DataError, IOData, as_iodata
from clpc.lpc.estimator import solution_info, structure_blocks
from clpc.lpc.regressors import Structure, check_mode, default_mode, miso_regressor
from clpc.lpc.solve import RobustRule, fixed_transform, solve_scatter

__all__ = ["CLPC"]

_WINDOWS_PER_BATCH = 2048
# scalar sample types step() takes without building arrays
_SCALAR_TYPES = frozenset({float, int, np.float64, np.float32, np.int64, np.int32})
# per-window statistics a solve hands to the FSM output logic
_SOLVE_KEYS = (
    "eigenvalues",
    "lambda_min",
    "lambda_max",
    "D",
    "eig_ratio",
    "separation",
    "noise_variance",
    "J",
    "c",
    "n_null",
    "n_input_relations",
    "degenerate",
    "determined",
)
# an estimate whose y(n) coefficient is below this in the solved (whitened) problem does not
# determine y(n): it has no usable monic form and is never accepted
_MIN_A0_WEIGHT = 1e-3


def numba_available() -> bool:
    """Whether numba can be imported (the compiled CLPC engine)."""
    return importlib.util.find_spec("numba") is not None


def _resolve_engine(engine: Any) -> str:
    """The engine to use: ``engine``, with ``"auto"`` read from ``CLPC_ENGINE`` if set."""
    if engine == "auto":
        engine = os.environ.get("CLPC_ENGINE", "auto") or "auto"
    if engine not in ("auto", "compiled", "numpy"):
        raise ValueError(
            f"engine must be 'auto', 'compiled' or 'numpy' (argument or CLPC_ENGINE); got "
            f"{engine!r}."
        )
    if engine == "compiled" and not numba_available():
        raise ValueError(
            "engine='compiled' needs numba, which is not installed: pip install 'clpc[fast]', "
            "or use engine='numpy'."
        )
    if engine == "auto":
        return "compiled" if numba_available() else "numpy"
    return engine


def _positive_int(value: Any, name: str, low: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        raise ValueError(f"{name} must be an int in the range [{low}, inf); got {value!r}.")
    return int(value)


class CLPC:
    """The Cluster LPC appraiser: streaming ``step``/``push`` and a vectorised ``run``.

    Parameters
    ----------
    parameters_size : int
        Size of ``a`` and ``b`` (``N + 1``); the paper's Table 1 uses 3 (``N = 2``).
    window_size : int
        ``W``: lag vectors per LPC (Table 1: 201).
    cluster_size : int
        ``C``: lag vectors between updates (Table 1: 12). The paper's name
        ``data_cluster_dimension`` is accepted too.
    sample_time : float, optional
        Sample time [s] the appraiser works at (Table 1: 0.01). Default: the data's.
    data_cluster_dimension : int, optional
        Alias of ``cluster_size``.
    na, nb, nk : int, optional
        Separate orders and input delay (override ``parameters_size``).
    method, noise_ratio, noise_cov, rule
        LPC options (see :class:`clpc.LPC`).
    mimo : {"siso", "paired", "miso"}, optional
        Multi-channel structure (default ``"siso"`` for 1x1 data, else ``"miso"``).
    gate : bool
        Accept an estimate only when the window determines it (default ``False``: every
        computable estimate is accepted, as in the paper).
    min_rows : int, optional
        Fewest rows for a usable estimate (default ``2 p``).
    data_sample_time : float, optional
        Sample time of the data given to :meth:`step`/:meth:`push` [s] (default
        ``sample_time``); :meth:`run` takes it from the record.
    n_jobs : int
        Threads for the batched solves (windows are independent).
    chunk_samples : int
        Samples processed at a time by :meth:`push` (bounds memory).
    engine : {"auto", "compiled", "numpy"}
        ``"compiled"``: the numba kernel of :mod:`clpc.window_kernel` (needs numba, the
        ``fast`` extra; about 2x faster in batch, 10x in :meth:`step`); ``"numpy"``: the
        vectorised numpy/LAPACK engine; ``"auto"`` (default): compiled when numba is
        installed (the environment variable ``CLPC_ENGINE`` overrides ``"auto"``). Both
        give the same numbers to ~1e-12, not bit for bit.
    """

    def __init__(
        self,
        parameters_size: int = 3,
        window_size: int = 201,
        cluster_size: int | None = None,
        sample_time: float | None = None,
        *,
        data_cluster_dimension: int | None = None,
        na: int | None = None,
        nb: int | None = None,
        nk: int = 0,
        method: str = "robust",
        mimo: str | None = None,
        noise_ratio: float | None = None,
        noise_cov: Any = None,
        rule: RobustRule | None = None,
        gate: bool = False,
        min_rows: int | None = None,
        data_sample_time: float | None = None,
        n_jobs: int = 1,
        chunk_samples: int = 65536,
        engine: str = "auto",
    ) -> None:
        if cluster_size is not None and data_cluster_dimension is not None:
            if cluster_size != data_cluster_dimension:
                raise ValueError(
                    "cluster_size and data_cluster_dimension are the same setting; got "
                    f"{cluster_size} and {data_cluster_dimension}. Pass one of them."
                )
        cluster = cluster_size if cluster_size is not None else data_cluster_dimension
        self.parameters_size = _positive_int(parameters_size, "parameters_size", 2)
        self.window_size = _positive_int(window_size, "window_size", 2)
        self.cluster_size = _positive_int(12 if cluster is None else cluster, "cluster_size")
        order = self.parameters_size - 1
        self.structure = Structure(order if na is None else na, order if nb is None else nb, nk)
        if method not in ("robust", "paper"):
            raise ValueError(f"method must be 'robust' or 'paper'; got {method!r}.")
        self.method = method
        self.mimo = mimo
        self.noise_ratio = noise_ratio
        self.noise_cov = None if noise_cov is None else np.asarray(noise_cov, dtype=float)
        self.rule = rule or RobustRule()
        self.gate = bool(gate)
        self.min_rows = None if min_rows is None else _positive_int(min_rows, "min_rows", 2)
        self.sample_time = None if sample_time is None else _positive(sample_time, "sample_time")
        self.data_sample_time = (
            None if data_sample_time is None else _positive(data_sample_time, "data_sample_time")
        )
        self.n_jobs = _positive_int(n_jobs, "n_jobs")
        self.chunk_samples = _positive_int(chunk_samples, "chunk_samples", 1024)
        self._max_lag = self.structure.max_lag
        self._engine_request = engine
        self.engine = _resolve_engine(engine)  # the one in use: "compiled" or "numpy"
        self.reset()

    # ================================================================= state
    def reset(self) -> CLPC:
        """Forget all data: empty window, counter 0, no parameters. Returns ``self``."""
        self._n_in: int | None = None
        self._n_out: int | None = None
        self._names: tuple[tuple[str, ...], tuple[str, ...]] | None = None
        self._buf = np.empty((0, 0))  # decimated samples [u | y], from sample _buf_start
        self._buf_start = 0
        self._n_seen = 0  # decimated samples seen
        self._j_done = 0  # updates done
        self._last_theta: np.ndarray | None = None
        self._last_c: np.ndarray | None = None
        self._has_model: np.ndarray | None = None
        self._factor: int | None = None
        self._dec_zi: np.ndarray | None = None
        self._dec_phase = 0
        self._pending: list[Any] = []  # samples kept aside by step(): arrays or (u, y)
        self._empty: Trace | None = None
        self._layout: dict[str, Any] | None = None
        self._record_dt: float | None = None
        if not hasattr(self, "_pool"):
            self._pool: ThreadPoolExecutor | None = None
        return self

    def _time_step(self) -> float:
        """Seconds per (decimated) sample: sample_time, else the data's, else 1."""
        return self.sample_time or self._record_dt or self.data_sample_time or 1.0

    @property
    def counter(self) -> int:
        """Lag vectors since the last update (0 .. cluster_size - 1)."""
        rows = max(self._n_seen - self.structure.max_lag, 0)
        return rows - self._j_done * self.cluster_size

    @property
    def n_samples(self) -> int:
        """Samples seen (after decimation)."""
        return self._n_seen

    @property
    def theta(self) -> np.ndarray | None:
        """Last output parameters (unit norm), shape (p,) or (n_outputs, p); None before data."""
        if self._last_theta is None:
            return None
        out = self._last_theta.copy()
        out.setflags(write=False)
        return out[0] if out.shape[0] == 1 else out

    @property
    def window(self) -> np.ndarray:
        """The current window's lag vectors (read-only), shape (rows, p) or (E, rows, p)."""
        if self._n_in is None:
            return np.empty((0, self.structure.n_params()))
        self._flush_pending()
        rows_total = max(self._n_seen - self.structure.max_lag, 0)
        first = max(rows_total - self.window_size, 0)
        rows = self._lag_rows(self._buf[first - self._buf_start :])
        rows.setflags(write=False)
        return rows[0] if rows.shape[0] == 1 else rows

    # ================================================================= config helpers
    def _mode(self) -> str:
        assert self._n_in is not None and self._n_out is not None
        mode = self.mimo or default_mode(self._n_in, self._n_out)
        check_mode(mode, self._n_in, self._n_out)
        return mode

    def _n_blocks(self) -> int:
        assert self._n_in is not None
        return self._n_in if self._mode() == "miso" else 1

    def _p(self) -> int:
        return self.structure.n_params(self._n_blocks())

    def _min_rows(self) -> int:
        return self.min_rows if self.min_rows is not None else 2 * self._p()

    def _noise(self) -> np.ndarray | None:
        if self.noise_cov is not None:
            return self.noise_cov
        if self.noise_ratio is None:
            return None
        s = self.structure
        ratio = float(self.noise_ratio)
        if not np.isfinite(ratio) or ratio <= 0:
            raise ValueError(f"noise_ratio must be > 0; got {self.noise_ratio!r}.")
        return np.concatenate([np.ones(s.na + 1), np.full(self._n_blocks() * (s.nb + 1), ratio)])

    def _init_channels(self, n_in: int, n_out: int, names: Any = None) -> None:
        if self._n_in is None:
            self._n_in, self._n_out = n_in, n_out
            self._mode()  # validates
            self._buf = np.empty((0, n_in + n_out))
            p = self._p()
            self._last_theta = np.zeros((n_out, p))
            self._last_c = np.zeros(n_out)
            self._has_model = np.zeros(n_out, dtype=bool)
            if names is not None:
                self._names = names
        elif (n_in, n_out) != (self._n_in, self._n_out):
            raise DataError(
                f"the appraiser was fed {self._n_in} input(s) and {self._n_out} output(s); "
                f"this chunk has {n_in} and {n_out}. Call reset() to start a new record."
            )

    # ================================================================= decimation
    def _decimation_factor(self, data_dt: float | None) -> int:
        target = self.sample_time
        dt = data_dt if data_dt is not None else (self.data_sample_time or target)
        if target is None or dt is None:
            return 1
        ratio = target / dt
        factor = round(ratio)
        if factor < 1 or abs(ratio - factor) > 1e-9 * max(ratio, 1.0):
            raise DataError(
                f"sample_time={target:g} s must be an integer multiple of the data's sample "
                f"time {dt:g} s (ratio {ratio:g}); resample the data or choose sample_time "
                "accordingly."
            )
        return factor

    def _decimate(self, x: np.ndarray) -> np.ndarray:
        f = self._factor or 1
        if f == 1 or x.shape[0] == 0:
            return x
        sos = signal.butter(4, 0.8 / f, output="sos")
        if self._dec_zi is None:  # start at rest at the first sample (no offset transient)
            zi0 = signal.sosfilt_zi(sos)
            self._dec_zi = zi0[:, :, None] * x[0][None, None, :]
        filtered, self._dec_zi = signal.sosfilt(sos, x, axis=0, zi=self._dec_zi)
        first = (-self._dec_phase) % f
        kept = filtered[first::f]
        self._dec_phase = (self._dec_phase + x.shape[0]) % f
        return kept

    # ================================================================= streaming API
    def step(self, u_k: Any, y_k: Any) -> Trace:
        """Feed one sample; returns the update it produced (a trace of 0 or 1 rows).

        Parameters
        ----------
        u_k : float or array_like, shape (n_inputs,)
        y_k : float or array_like, shape (n_outputs,)
        """
        rows_after = self._n_seen + 1 - self._max_lag
        update = rows_after > 0 and rows_after % self.cluster_size == 0
        if (
            self._factor == 1
            and self._n_in == 1
            and self._n_out == 1
            and type(u_k) in _SCALAR_TYPES
            and type(y_k) in _SCALAR_TYPES
        ):  # single-channel scalars: plain floats, no arrays until the update
            u_f, y_f = float(u_k), float(y_k)
            if not (math.isfinite(u_f) and math.isfinite(y_f)):
                _check_finite(np.array([[u_f]]), "u", self._n_seen)
                _check_finite(np.array([[y_f]]), "y", self._n_seen)
            self._pending.append((u_f, y_f))
            self._n_seen += 1
            return self._consume_pending() if update else self._empty_trace()
        u = np.atleast_1d(np.asarray(u_k, dtype=np.float64))
        y = np.atleast_1d(np.asarray(y_k, dtype=np.float64))
        if (
            self._factor == 1
            and self._n_in is not None
            and u.shape == (self._n_in,)
            and y.shape == (self._n_out,)
            and not update
        ):  # fast path: no update completes; keep the sample aside (flushed by _consume)
            sample = np.concatenate([u, y])
            if not np.all(np.isfinite(sample)):
                _check_finite(u[None], "u", self._n_seen)
                _check_finite(y[None], "y", self._n_seen)
            self._pending.append(sample)
            self._n_seen += 1
            return self._empty_trace()
        return self.push(u[None, :], y[None, :])

    def push(self, u: Any, y: Any) -> Trace:
        """Feed a chunk of samples of any length.

        Parameters
        ----------
        u : array_like, shape (n,) or (n, n_inputs)
        y : array_like, shape (n,) or (n, n_outputs)

        Returns
        -------
        Trace
            The updates this chunk produced (possibly empty); the traces of consecutive
            pushes concatenated equal :meth:`run` on the whole record.
        """
        u2 = _as_columns(u, "u")
        y2 = _as_columns(y, "y")
        if u2.shape[0] != y2.shape[0]:
            raise DataError(
                f"u and y must have the same length; got len(u)={u2.shape[0]}, "
                f"len(y)={y2.shape[0]}."
            )
        for lo in range(0, u2.shape[0], 1 << 20):  # bounded temporaries
            _check_finite(u2[lo : lo + (1 << 20)], "u", self._n_seen + lo)
            _check_finite(y2[lo : lo + (1 << 20)], "y", self._n_seen + lo)
        self._init_channels(u2.shape[1], y2.shape[1])
        if self._factor is None:
            self._factor = self._decimation_factor(None)
        total = self._updates_after(u2.shape[0])
        # the parts are written into the final arrays (no concatenation at the end)
        out = Trace.allocate(self._empty_trace(), total) if total else self._empty_trace()
        done = 0
        for lo in range(0, u2.shape[0], self.chunk_samples):  # bounded working memory
            hi = lo + self.chunk_samples
            part = self._consume(self._decimate(np.hstack([u2[lo:hi], y2[lo:hi]])))
            if total:
                done = out.put(done, part)
        assert done == total, (done, total)
        return out

    def _updates_after(self, n_samples: int) -> int:
        """Updates that ``n_samples`` more (undecimated) samples will complete."""
        f = self._factor or 1
        first = (-self._dec_phase) % f  # the first of them that decimation keeps
        kept = 0 if first >= n_samples else (n_samples - 1 - first) // f + 1
        rows = max(self._n_seen + kept - self._max_lag, 0)
        return rows // self.cluster_size - self._j_done

    def run(self, u: Any, y: Any | None = None, dt: float | None = None) -> Trace:
        """Reset, then process a whole record (vectorised over windows).

        Parameters
        ----------
        u : IOData or array_like, shape (T,) or (T, n_inputs)
        y : array_like, shape (T,) or (T, n_outputs), optional
        dt : float, optional
            Sample time of the record [s] (default: the record's, else ``sample_time``).

        Returns
        -------
        Trace
            One row per update.
        """
        self.reset()
        if isinstance(u, np.ndarray) and isinstance(y, np.ndarray):
            # plain arrays: validated by push, without IOData's defensive copy of the record
            u_arr, y_arr = _as_columns(u, "u"), _as_columns(y, "y")
            data_dt = None if dt is None else _positive(dt, "dt")
            self._init_channels(u_arr.shape[1], y_arr.shape[1])
        else:
            data = as_iodata(u, y, dt)
            u_arr, y_arr = data.u, data.y
            given_dt = isinstance(u, IOData) or dt is not None
            data_dt = data.dt if given_dt else None  # arrays without dt: at sample_time
            self._init_channels(
                data.n_inputs, data.n_outputs, (data.input_names, data.output_names)
            )
        self._factor = self._decimation_factor(data_dt)
        if self.sample_time is None and data_dt is not None:
            self._record_dt = data_dt  # no decimation: the appraiser works at the data's rate
        return self.push(u_arr, y_arr)

    # ================================================================= engine
    def _lag_rows(self, buf: np.ndarray) -> np.ndarray:
        """Lag rows of every equation from decimated samples ``buf``: (E, n, p)."""
        assert self._n_in is not None and self._n_out is not None
        u, y = buf[:, : self._n_in], buf[:, self._n_in :]
        mode = self._mode()
        if buf.shape[0] <= self.structure.max_lag:
            return np.empty((self._n_out, 0, self._p()))
        if mode == "miso":
            mats = [miso_regressor(y[:, j], u, self.structure) for j in range(self._n_out)]
        else:
            mats = [
                miso_regressor(y[:, j], u[:, j : j + 1], self.structure) for j in range(self._n_out)
            ]
        return np.stack(mats)

    def _consume(self, new: np.ndarray) -> Trace:
        """Append decimated samples and compute the updates they complete."""
        if new.shape[0] == 0:
            return self._empty_trace()
        self._flush_pending()
        self._buf = np.vstack([self._buf, new]) if self._buf.size else new.copy()
        self._n_seen += new.shape[0]
        s, c, w = self.structure, self.cluster_size, self.window_size
        rows_total = max(self._n_seen - s.max_lag, 0)
        j_last = rows_total // c
        trace = self._empty_trace()
        if j_last > self._j_done:
            # absolute row index = _buf_start + i; the compiled engine builds rows itself
            rows = self._lag_rows(self._buf) if self.engine == "numpy" else None
            n_new = j_last - self._j_done
            n_batches = -(-n_new // _WINDOWS_PER_BATCH)
            if self.n_jobs > 1:  # equal shares for the threads
                n_batches = -(-n_batches // self.n_jobs) * self.n_jobs
            size = -(-n_new // n_batches)
            batches = [
                (j0, min(size, j_last + 1 - j0)) for j0 in range(self._j_done + 1, j_last + 1, size)
            ]
            # windows are independent: the batches are solved in parallel when asked; the
            # hold logic of the FSM output then runs in time order
            if self.n_jobs > 1 and len(batches) > 1:
                solved = list(
                    self._executor().map(lambda b: self._solve_windows(rows, *b), batches)
                )
            else:
                solved = [self._solve_windows(rows, *b) for b in batches]
            parts = [
                self._finish(res, j0, count)
                for res, (j0, count) in zip(solved, batches, strict=True)
            ]
            trace = parts[0] if len(parts) == 1 else Trace.concat(parts)
            self._j_done = j_last
        # keep only what the next window needs: rows from max(0, C (j+1) - W - C)
        keep_row = max(0, c * (self._j_done + 1) - w - c)
        drop = keep_row - self._buf_start
        if drop > 0:
            self._buf = self._buf[drop:].copy()
            self._buf_start = keep_row
        return trace

    def _consume_pending(self) -> Trace:
        """Compute the update the samples kept aside by :meth:`step` complete."""
        n = len(self._pending)
        self._n_seen -= n  # _consume counts them again
        block = np.array(self._pending, dtype=np.float64)
        self._pending = []
        return self._consume(block)

    def _flush_pending(self) -> None:
        """Move samples kept aside by the fast :meth:`step` path into the buffer."""
        if self._pending:
            block = np.array(self._pending, dtype=np.float64)
            self._buf = np.vstack([self._buf, block]) if self._buf.size else block
            self._pending = []

    def _executor(self) -> ThreadPoolExecutor:
        """A thread pool kept for the appraiser's lifetime (created on first use)."""
        if self._pool is None:
            self._pool = ThreadPoolExecutor(self.n_jobs)
        return self._pool

    def _solve_windows(self, rows: np.ndarray | None, j0: int, count: int) -> dict[str, np.ndarray]:
        """Solve windows ``j0 .. j0 + count - 1``: arrays of shape (count, E, ...).

        ``rows``: the buffer's lag rows (numpy engine; the compiled one reads the samples).
        """
        if rows is None:
            return self._solve_windows_compiled(j0, count)
        e = rows.shape[0]
        scat, mean, n_rows = window_scatter(
            rows, self._buf_start, j0, count, self.window_size, self.cluster_size
        )
        p = scat.shape[-1]
        res = solve_scatter(
            scat.reshape(-1, p, p),
            mean.reshape(-1, p),
            np.tile(n_rows, e),
            n_output_cols=self.structure.na + 1,
            blocks=structure_blocks(self.structure, self._n_blocks()),
            method=self.method,
            noise_cov=self._noise(),
            rule=self.rule,
        )
        out = {
            "theta_estimate": res.theta,
            "eigenvalues": res.eigenvalues,
            "c": res.c,
            "noise_variance": res.noise_variance,
            "separation": res.separation,
            "a0_weight": res.a0_weight,
            "n_null": res.n_null,
            "n_input_relations": res.n_input_relations,
            "degenerate": res.degenerate,
        }
        # (E * count, ...) -> (count, E, ...)
        for key, val in out.items():
            out[key] = np.swapaxes(val.reshape(e, count, *val.shape[1:]), 0, 1)
        out["n_rows_win"] = n_rows
        return out

    def _kernel_layout(self) -> dict[str, Any]:
        """Column maps and solve options of the compiled engine (fixed per record)."""
        if self._layout is not None:
            return self._layout
        from clpc.appraiser import kernel as wk  # imports numba: only when this engine is used

        assert self._n_in is not None and self._n_out is not None
        s, n_in, n_out = self.structure, self._n_in, self._n_out
        blocks = structure_blocks(s, self._n_blocks())
        p = self._p()
        col_channel = np.empty(p, dtype=np.int64)
        for ch, block in enumerate(blocks):
            col_channel[block] = ch
        # column a of equation e is buf[k - lag, chan] (buf columns: inputs, then outputs)
        chan = np.empty((n_out, p), dtype=np.int64)
        lag = np.empty((n_out, p), dtype=np.int64)
        for e in range(n_out):
            chan[e, : s.na + 1] = n_in + e
            lag[e, : s.na + 1] = np.arange(s.na + 1)
            inputs = range(n_in) if self._mode() == "miso" else [e]
            for i, inp in enumerate(inputs):
                cols = slice(s.na + 1 + i * (s.nb + 1), s.na + 1 + (i + 1) * (s.nb + 1))
                chan[e, cols] = inp
                lag[e, cols] = s.nk + np.arange(s.nb + 1)
        noise = self._noise()
        if noise is not None:
            mode, transform = wk.FIXED_TRANSFORM, fixed_transform(noise, p)
        elif self.method == "robust":
            mode, transform = wk.CHANNEL_SCALES, np.eye(p)
        else:
            mode, transform = wk.NO_TRANSFORM, np.eye(p)
        rule = self.rule
        ratio = -1.0 if rule.degeneracy_ratio is None else float(rule.degeneracy_ratio)
        self._layout = {
            "kernel": wk,
            "chan": chan,
            "lag": lag,
            "col_channel": col_channel,
            "n_channels": len(blocks),
            "mode": mode,
            "transform": np.ascontiguousarray(transform),
            "opts": np.array([rule.min_a0_weight, ratio, rule.zero_tol, rule.min_output_weight]),
        }
        return self._layout

    def _solve_windows_compiled(self, j0: int, count: int) -> dict[str, np.ndarray]:
        lay = self._kernel_layout()
        e, p = lay["chan"].shape
        out = {
            "theta_estimate": np.empty((count, e, p)),
            "eigenvalues": np.empty((count, e, p)),
            "c": np.empty((count, e)),
            "noise_variance": np.empty((count, e)),
            "separation": np.empty((count, e)),
            "a0_weight": np.empty((count, e)),
            "n_null": np.empty((count, e), dtype=np.int64),
            "n_input_relations": np.empty((count, e), dtype=np.int64),
            "degenerate": np.empty((count, e), dtype=bool),
            "n_rows_win": np.empty(count, dtype=np.int64),
        }
        lay["kernel"].solve_windows(
            self._buf,
            self._buf_start - self.structure.max_lag,
            lay["chan"],
            lay["lag"],
            j0,
            count,
            self.window_size,
            self.cluster_size,
            lay["col_channel"],
            lay["n_channels"],
            self.structure.na + 1,
            lay["mode"],
            lay["transform"],
            self.method == "robust",
            lay["opts"],
            *out.values(),
        )
        return out

    def _finish(self, res: dict[str, np.ndarray], j0: int, count: int) -> Trace:
        """Accept/hold logic of the FSM output, monic forms, stability, statistics."""
        arrays = (
            self._finish_compiled(res) if self.engine == "compiled" else (self._finish_numpy(res))
        )
        n_rows = arrays.pop("n_rows_win")
        not_enough = arrays.pop("not_enough")
        index = self.structure.max_lag + self.cluster_size * np.arange(j0, j0 + count) - 1
        return self._trace(index, index * self._time_step(), n_rows, not_enough, arrays)

    def _finish_compiled(self, res: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        assert self._last_theta is not None and self._last_c is not None
        assert self._has_model is not None
        s, rule = self.structure, self.rule
        count, e, p = res["theta_estimate"].shape
        n_inputs = self._n_in or 1
        out = {
            "theta": np.empty((count, e, p)),
            "c": np.empty((count, e)),
            "accepted": np.empty((count, e), dtype=bool),
            "has_model": np.empty((count, e), dtype=bool),
            "determined": np.empty((count, e), dtype=bool),
            "not_enough": np.empty(count, dtype=bool),
            "den": np.empty((count, e, s.na + 1)),
            "num": np.empty((count, e, n_inputs, s.nk + s.nb + 1)),
            "stable": np.empty((count, e), dtype=bool),
            "lambda_min": np.empty((count, e)),
            "lambda_max": np.empty((count, e)),
            "D": np.empty((count, e)),
            "eig_ratio": np.empty((count, e)),
            "J": np.empty((count, e)),
        }
        self._kernel_layout()["kernel"].finish_updates(
            res["theta_estimate"],
            res["c"],
            res["eigenvalues"],
            res["noise_variance"],
            res["separation"],
            res["a0_weight"],
            res["n_null"],
            res["n_input_relations"],
            res["degenerate"],
            res["n_rows_win"],
            self._min_rows(),
            self.gate,
            _MIN_A0_WEIGHT,
            rule.separation,
            s.na,
            s.nb,
            s.nk,
            self._mode() != "miso",
            self._last_theta,
            self._last_c,
            self._has_model,
            *out.values(),
        )
        for key in (
            "theta_estimate",
            "eigenvalues",
            "noise_variance",
            "separation",
            "a0_weight",
            "n_null",
            "n_input_relations",
            "degenerate",
            "n_rows_win",
        ):
            out[key] = res[key]
        return out

    def _finish_numpy(self, res: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        assert self._last_theta is not None and self._last_c is not None
        assert self._has_model is not None
        n_rows = res["n_rows_win"]
        count = n_rows.shape[0]
        info = solution_info(
            res["eigenvalues"],
            res["c"],
            res["noise_variance"],
            res["n_null"],
            res["n_input_relations"],
            res["separation"],
            res["degenerate"],
            n_rows[:, None],
            self.rule,
        )
        not_enough = n_rows < self._min_rows()
        est = res["theta_estimate"]
        a0_ok = res["a0_weight"] >= _MIN_A0_WEIGHT
        accepted = ~not_enough[:, None] & ~res["degenerate"] & a0_ok
        if self.gate:
            accepted &= info["determined"]
        # hold: the output is the last accepted estimate (carried across chunks)
        idx = np.where(accepted, np.arange(count)[:, None], -1)
        last = np.maximum.accumulate(idx, axis=0)  # (count, E)
        have = last >= 0
        e_idx = np.arange(est.shape[1])[None, :]
        theta = np.where(have[..., None], est[np.maximum(last, 0), e_idx], self._last_theta[None])
        c_out = np.where(have, res["c"][np.maximum(last, 0), e_idx], self._last_c[None])
        has_model = have | self._has_model[None, :]
        self._last_theta = theta[-1].copy()
        self._last_c = c_out[-1].copy()
        self._has_model = has_model[-1].copy()
        den, num, stable = self._monic(theta, has_model)
        arrays = {key: info[key] for key in _SOLVE_KEYS}
        arrays.update(
            theta_estimate=est,
            a0_weight=res["a0_weight"],
            theta=theta,
            c=c_out,
            accepted=accepted,
            has_model=has_model,
            den=den,
            num=num,
            stable=stable,
            n_rows_win=n_rows,
            not_enough=not_enough,
        )
        return arrays

    def _monic(
        self, theta: np.ndarray, has_model: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s = self.structure
        n, e, _ = theta.shape
        a0 = np.where(has_model, theta[:, :, 0], 1.0)
        den = theta[:, :, : s.na + 1] / a0[..., None]
        den[~has_model] = np.eye(1, s.na + 1)[0]
        b = theta[:, :, s.na + 1 :].reshape(n, e, -1, s.nb + 1)
        num = np.zeros((n, e, self._n_in or 1, s.nk + s.nb + 1))
        nb_blocks = b.shape[2]
        if self._mode() == "miso":
            num[:, :, :nb_blocks, s.nk :] = -b / a0[..., None, None]
        else:
            for j in range(e):
                num[:, j, j, s.nk :] = -b[:, j, 0] / a0[:, j, None]
        num[~has_model] = 0.0
        return den, num, has_model & schur_stable(den)

    def _trace(self, index, time, rows, not_enough, arrays) -> Trace:
        names = self._names or (
            tuple(f"u{i}" for i in range(self._n_in or 1)) if (self._n_in or 1) > 1 else ("u",),
            tuple(f"y{i}" for i in range(self._n_out or 1)) if (self._n_out or 1) > 1 else ("y",),
        )
        return Trace(
            index=np.asarray(index, dtype=np.int64),
            time=np.asarray(time, dtype=np.float64),
            rows=np.asarray(rows, dtype=np.int64),
            not_enough_data=np.asarray(not_enough, dtype=bool),
            arrays=arrays,
            structure=self.structure,
            n_inputs=self._n_in or 1,
            mode=self._mode() if self._n_in is not None else "siso",
            sample_time=self._time_step(),
            input_names=names[0],
            output_names=names[1],
            meta={"gate": self.gate, "method": self.method},
        )

    def _empty_trace(self) -> Trace:
        if self._empty is not None:
            return self._empty
        e = self._n_out or 1
        p = self._p() if self._n_in is not None else self.structure.n_params()
        s = self.structure
        shapes = {
            "theta": (p,),
            "theta_estimate": (p,),
            "den": (s.na + 1,),
            "num": (self._n_in or 1, s.nk + s.nb + 1),
            "eigenvalues": (p,),
        }
        ints = ("n_null", "n_input_relations")
        bools = ("degenerate", "determined", "accepted", "has_model", "stable")
        arrays = {}
        for key in PER_EQUATION:
            dtype = np.int64 if key in ints else (bool if key in bools else np.float64)
            arrays[key] = np.zeros((0, e, *shapes.get(key, ())), dtype=dtype)
        z = np.zeros(0)
        empty = self._trace(z, z, z, z.astype(bool), arrays)
        if self._n_in is not None:
            self._empty = empty
        return empty

    # ================================================================= persistence
    def config(self) -> dict[str, Any]:
        """Constructor arguments (JSON-safe)."""
        return {
            "parameters_size": self.parameters_size,
            "window_size": self.window_size,
            "cluster_size": self.cluster_size,
            "sample_time": self.sample_time,
            "na": self.structure.na,
            "nb": self.structure.nb,
            "nk": self.structure.nk,
            "method": self.method,
            "mimo": self.mimo,
            "noise_ratio": self.noise_ratio,
            "noise_cov": None if self.noise_cov is None else self.noise_cov.tolist(),
            "rule": asdict(self.rule),
            "gate": self.gate,
            "min_rows": self.min_rows,
            "data_sample_time": self.data_sample_time,
            "n_jobs": self.n_jobs,
            "chunk_samples": self.chunk_samples,
            "engine": self._engine_request,
        }

    def state_dict(self) -> dict[str, Any]:
        """The FSM state and configuration as a JSON-safe dict (floats round-trip exactly)."""

        def arr(x: np.ndarray | None) -> Any:
            return None if x is None else {"shape": list(x.shape), "data": x.ravel().tolist()}

        self._flush_pending()
        return {
            "format": "clpc-appraiser-state",
            "version": 1,
            "config": self.config(),
            "n_in": self._n_in,
            "n_out": self._n_out,
            "names": None if self._names is None else [list(n) for n in self._names],
            "buf": arr(self._buf),
            "buf_start": self._buf_start,
            "n_seen": self._n_seen,
            "j_done": self._j_done,
            "last_theta": arr(self._last_theta),
            "last_c": arr(self._last_c),
            "has_model": None if self._has_model is None else self._has_model.tolist(),
            "factor": self._factor,
            "dec_zi": arr(self._dec_zi),
            "dec_phase": self._dec_phase,
            "record_dt": self._record_dt,
        }

    @classmethod
    def from_state_dict(cls, state: dict[str, Any]) -> CLPC:
        """Rebuild an appraiser from :meth:`state_dict` output; it continues identically."""
        if state.get("format") != "clpc-appraiser-state" or state.get("version") != 1:
            raise ValueError("not a clpc appraiser state (format/version mismatch).")
        cfg = dict(state["config"])
        cfg.pop("parameters_size")
        rule = RobustRule(**cfg.pop("rule"))
        obj = cls(state["config"]["parameters_size"], rule=rule, **cfg)

        def arr(x: Any) -> np.ndarray | None:
            return None if x is None else np.asarray(x["data"], float).reshape(x["shape"])

        obj._n_in, obj._n_out = state["n_in"], state["n_out"]
        obj._names = None if state["names"] is None else tuple(tuple(n) for n in state["names"])
        obj._buf = arr(state["buf"])
        obj._buf_start = int(state["buf_start"])
        obj._n_seen = int(state["n_seen"])
        obj._j_done = int(state["j_done"])
        obj._last_theta = arr(state["last_theta"])
        obj._last_c = arr(state["last_c"])
        hm = state["has_model"]
        obj._has_model = None if hm is None else np.asarray(hm, dtype=bool)
        obj._factor = state["factor"]
        obj._dec_zi = arr(state["dec_zi"])
        obj._dec_phase = int(state["dec_phase"])
        obj._record_dt = state.get("record_dt")
        return obj

    def save(self, path: str) -> None:
        """Write :meth:`state_dict` as JSON to ``path``."""
        with open(path, "w", encoding="utf-8") as fh:
            json.dump(self.state_dict(), fh)

    @classmethod
    def load(cls, path: str) -> CLPC:
        """Read an appraiser saved with :meth:`save`."""
        with open(path, encoding="utf-8") as fh:
            return cls.from_state_dict(json.load(fh))

    def __repr__(self) -> str:
        return (
            f"CLPC(parameters_size={self.parameters_size}, window_size={self.window_size}, "
            f"cluster_size={self.cluster_size}, sample_time={self.sample_time}, "
            f"method={self.method!r}, samples_seen={self._n_seen}, updates={self._j_done})"
        )


def schur_stable(den: np.ndarray) -> np.ndarray:
    """Whether every root of ``den[..., 0] z^n + ... + den[..., n]`` lies inside the unit circle.

    The Schur-Cohn (Levinson) recursion, vectorised over the leading axes: with ``a`` the
    coefficients, for ``m = n .. 1`` the reflection coefficient ``k = a_m / a_0`` must satisfy
    ``|k| < 1`` and ``a_i <- (a_i - k a_{m-i}) / (1 - k^2)``. Costs ``O(n^2)`` per polynomial
    instead of an eigenvalue problem of the companion matrix.
    """
    a = np.array(den, dtype=np.float64, copy=True)
    ok = np.ones(a.shape[:-1], dtype=bool)
    for m in range(a.shape[-1] - 1, 0, -1):
        with np.errstate(divide="ignore", invalid="ignore"):
            k = a[..., m] / a[..., 0]
        ok &= np.abs(k) < 1.0
        k = np.where(ok, k, 0.0)
        rev = a[..., m::-1]
        a = (a[..., : m + 1] - k[..., None] * rev) / (1.0 - k * k)[..., None]
        a = a[..., :m]
    return ok


def _positive(value: Any, name: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a positive number of seconds; got {value!r}.") from None
    if not np.isfinite(v) or v <= 0:
        raise ValueError(f"{name} must be a positive number of seconds; got {value!r}.")
    return v


def _as_columns(x: Any, name: str) -> np.ndarray:
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise DataError(f"{name} must hold numbers; got {type(x).__name__}.") from None
    if arr.ndim == 0:
        arr = arr[None, None]
    elif arr.ndim == 1:
        arr = arr[:, None]
    elif arr.ndim != 2:
        raise DataError(f"{name} must be 1-D or 2-D; got shape {arr.shape}.")
    return arr


def _check_finite(arr: np.ndarray, name: str, offset: int) -> None:
    bad = ~np.isfinite(arr)
    if bad.any():
        row, col = np.argwhere(bad)[0]
        raise DataError(
            f"{name} channel {col} is not finite at sample {offset + row} (counting from the "
            "first sample fed); remove or interpolate missing samples."
        )
