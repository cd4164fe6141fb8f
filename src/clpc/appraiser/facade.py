"""CLPC: the paper's appraiser (section V), a finite-state machine over time windows.

Semantics (``docs/clpc.md`` says the same):

* Samples are numbered ``k = 0, 1, 2, ...`` (after decimation to ``decimate_to``). The lag
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
  windows (nothing varies, a constant channel) are flagged ``degenerate``; with the guard (the
  default) only a *trusted* window's estimate is accepted: enough rows, an output excited
  above its quantization, a solution the data determine (see :mod:`clpc.core.rules`). An
  update that is not accepted holds the last accepted parameters; parameters are never NaN
  (zeros, with ``has_model=False``, until a first estimate is accepted).
* ``decimate_to``: data sampled (``dt``) faster by an integer factor are low-pass filtered
  (causal 4th-order Butterworth at 0.8 of the new Nyquist frequency, filter state carried
  across chunks) and every factor-th sample is kept (samples ``0, f, 2f, ...``). The former
  ``sample_time`` named either ``dt`` or ``decimate_to`` depending on the data; it still works
  and warns (``DeprecationWarning``) whenever it had to pick.

The state (the last window of samples, the counter, the last parameters, the filter state) is
the paper's FSM state; :meth:`CLPC.state_dict` / :meth:`CLPC.from_state_dict` serialise it.
"""

from __future__ import annotations

import logging
import math
import warnings
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np

from clpc.appraiser import fsm
from clpc.appraiser import state as state_io
from clpc.appraiser.buffer import SampleBuffer
from clpc.appraiser.decimation import Decimator, decimation_factor
from clpc.appraiser.inputs import SCALAR_TYPES, as_columns, check_finite, check_noise_cov
from clpc.appraiser.spread import attach_levels
from clpc.appraiser.trace import Trace
from clpc.appraiser.updates import KernelSetup, TraceLabels
from clpc.core.checks import (
    check_bool,
    check_choice,
    check_int,
    check_positive,
    resolve_order,
    same_setting,
)
from clpc.core.rules import SCALINGS, RobustRule
from clpc.data import DataError, IOData, as_iodata
from clpc.data.samples import check_spread
from clpc.model.structure import Structure

__all__ = ["CLPC"]

_LOG = logging.getLogger("clpc.appraiser")


class CLPC:
    """The Cluster LPC appraiser: streaming ``step``/``push`` and a vectorised ``run``.

    Parameters
    ----------
    parameters_size : int, optional
        The paper's name: size of ``a`` and of ``b``, ``N + 1`` (an alias of ``order``;
        Table 1 uses 3). Kept as the first positional argument: ``CLPC(3, 201, 12)``.
    window_size : int
        ``W``: lag vectors per LPC (Table 1: 201).
    cluster_size : int
        ``C``: lag vectors between updates (Table 1: 12). The paper's name
        ``data_cluster_dimension`` is accepted too.
    sample_time : float, optional
        Former name, ambiguous: the data's sample time for plain arrays without ``dt``, a
        decimation target when the data's ``dt`` is known. Still works as before, with a
        ``DeprecationWarning`` whenever one meaning was picked; pass ``dt`` or
        ``decimate_to`` instead.
    order : int, optional
        The model order ``N`` (``na = nb = N``); default 2 (the paper's Table 1).
    dt : float, optional
        Sample time of the data [s] given to :meth:`step`/:meth:`push`/:meth:`run` as plain
        arrays (a record's own ``dt`` is used by :meth:`run`; the two must agree).
    decimate_to : float, optional
        Sample time [s] the appraiser works at, an integer multiple of the data's: the
        data are low-pass filtered and decimated (Table 1: 0.01 on 1 ms data). Needs the
        data's sample time (``dt``, or a record with ``dt``).
    data_cluster_dimension : int, optional
        Alias of ``cluster_size``.
    na, nb, nk : int, optional
        Separate orders and input delay (override ``parameters_size``).
    method, scaling, noise_ratio, noise_cov, rule
        LPC options (see :class:`clpc.LPC`).
    mimo : {"siso", "paired", "miso"}, optional
        Multi-channel structure (default ``"siso"`` for 1x1 data, else ``"miso"``).
    guard : bool
        Accept an estimate only from a trusted window (default ``True``): one that holds
        ``trust_rows`` lag vectors, whose output varies by at least three quantization
        steps, and whose solution the data determine (:func:`clpc.core.rules.is_trusted`).
        ``False`` is the paper's appraiser: every computable estimate is accepted.
    trust_rows : int, optional
        Lag vectors a trusted window needs (default ``max(10 p, W / 2)``, at most ``W``).
    gate : bool, optional
        Former name of ``guard``.
    min_rows : int, optional
        Fewest rows for a usable estimate (default ``2 p``); smaller windows are not solved.
    data_sample_time : float, optional
        Former name of ``dt``.
    n_jobs : int
        Threads for the batched solves (windows are independent).
    chunk_samples : int
        Samples processed at a time by :meth:`push` (bounds memory).

    Notes
    -----
    The windows are solved by a numba-compiled kernel (:mod:`clpc.appraiser.kernel`,
    compiled on first use and cached on disk); with the environment variable
    ``NUMBA_DISABLE_JIT=1`` the same functions run uncompiled (slow; for debugging and
    coverage).
    """

    def __init__(
        self,
        parameters_size: int | None = None,
        window_size: int = 201,
        cluster_size: int | None = None,
        sample_time: float | None = None,
        *,
        order: int | None = None,
        dt: float | None = None,
        decimate_to: float | None = None,
        data_cluster_dimension: int | None = None,
        na: int | None = None,
        nb: int | None = None,
        nk: int = 0,
        method: str = "robust",
        scaling: str = "none",
        mimo: str | None = None,
        noise_ratio: float | None = None,
        noise_cov: Any = None,
        rule: RobustRule | None = None,
        guard: bool = True,
        trust_rows: int | None = None,
        gate: bool | None = None,
        min_rows: int | None = None,
        data_sample_time: float | None = None,
        n_jobs: int = 1,
        chunk_samples: int = 65536,
    ) -> None:
        if cluster_size is not None and data_cluster_dimension is not None:
            if cluster_size != data_cluster_dimension:
                raise ValueError(
                    "cluster_size and data_cluster_dimension are the same setting; got "
                    f"{cluster_size} and {data_cluster_dimension}. Pass one of them."
                )
        cluster = cluster_size if cluster_size is not None else data_cluster_dimension
        order = resolve_order(order, parameters_size)
        self.order = order
        self.parameters_size = order + 1
        self.window_size = check_int(window_size, "window_size", 2)
        self.cluster_size = check_int(12 if cluster is None else cluster, "cluster_size", 1)
        self.structure = Structure(order if na is None else na, order if nb is None else nb, nk)
        self._max_lag = self.structure.max_lag  # read on every step()
        self.method = check_choice(method, "method", ("robust", "paper"))
        self.scaling = check_choice(scaling, "scaling", SCALINGS)
        self.mimo = mimo
        self.noise_ratio = noise_ratio
        self.noise_cov = check_noise_cov(noise_cov)
        self.rule = rule or RobustRule()
        if gate is not None and gate != guard and not guard:
            raise ValueError(
                f"gate is the former name of guard; got guard={guard!r} and gate={gate!r}. "
                "Pass one of them."
            )
        self.guard = check_bool(guard if gate is None else gate, "guard")
        top = 2**31 - 1  # counts of rows: beyond this no window fits in memory anyway
        self.trust_rows = (
            None if trust_rows is None else check_int(trust_rows, "trust_rows", 1, top)
        )
        self.min_rows = None if min_rows is None else check_int(min_rows, "min_rows", 2, top)
        fsm.check_window(self, self.structure.n_params())  # one input: the fewest parameters
        if sample_time is not None and decimate_to is not None:
            raise ValueError(
                f"sample_time is the former, ambiguous name of decimate_to; got "
                f"sample_time={sample_time!r} and decimate_to={decimate_to!r}. Pass "
                "decimate_to (the rate to work at) and dt (the data's sample time)."
            )
        target = decimate_to if decimate_to is not None else sample_time
        #: the sample time the appraiser works at (internal name; see decimate_to)
        target_name = "sample_time" if decimate_to is None else "decimate_to"
        self.sample_time = None if target is None else _seconds(target, target_name)
        #: sample_time was given: its meaning is picked from the data (with a warning)
        self._legacy_sample_time = sample_time is not None
        data_dt = same_setting(dt, data_sample_time, "dt", "data_sample_time")
        self.data_sample_time = None if data_dt is None else _seconds(data_dt, "dt")
        self.n_jobs = check_int(n_jobs, "n_jobs", 1)
        self.chunk_samples = check_int(chunk_samples, "chunk_samples", 1024)
        self._pool: ThreadPoolExecutor | None = None
        self.reset()

    # ================================================================= state
    def reset(self) -> CLPC:
        """Forget all data: empty window, counter 0, no parameters. Returns ``self``."""
        self._n_in: int | None = None
        self._n_out: int | None = None
        self._names: tuple[tuple[str, ...], tuple[str, ...]] | None = None
        self._buffer: SampleBuffer | None = None
        self._n_seen = 0  # decimated samples seen (including the ones kept aside)
        self._j_done = 0  # updates done
        self._last_theta: np.ndarray | None = None
        self._last_c: np.ndarray | None = None
        self._has_model: np.ndarray | None = None
        self._decimator: Decimator | None = None
        self._record_dt: float | None = None
        self._setup: KernelSetup | None = None
        self._trace_labels: TraceLabels | None = None
        self._empty: Trace | None = None
        return self

    @property
    def decimate_to(self) -> float | None:
        """Sample time [s] the appraiser works at (``None``: the data's)."""
        return self.sample_time

    @property
    def dt(self) -> float | None:
        """The data's sample time [s] given to the constructor (``None``: from the data)."""
        return self.data_sample_time

    @property
    def gate(self) -> bool:
        """Former name of :attr:`guard`."""
        return self.guard

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
        if self._buffer is None:
            return np.empty((0, self.structure.n_params()))
        rows_total = max(self._n_seen - self.structure.max_lag, 0)
        first = max(rows_total - self.window_size, 0)
        rows = fsm.lag_rows(self, self._buffer.since(first))
        rows.setflags(write=False)
        return rows[0] if rows.shape[0] == 1 else rows

    # ================================================================= configuration
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
        plain = self._decimator is not None and self._decimator.factor == 1
        if plain and self._n_in == 1 and self._n_out == 1:
            if type(u_k) in SCALAR_TYPES and type(y_k) in SCALAR_TYPES:
                # single-channel scalars: plain floats, no arrays until the update
                u_f, y_f = float(u_k), float(y_k)
                if not (math.isfinite(u_f) and math.isfinite(y_f)):
                    check_finite(np.array([[u_f]]), "u", self._n_seen)
                    check_finite(np.array([[y_f]]), "y", self._n_seen)
                return self._keep_aside((u_f, y_f), update)
        u = as_columns(u_k, "u").ravel()
        y = as_columns(y_k, "y").ravel()
        if plain and u.shape == (self._n_in,) and y.shape == (self._n_out,) and not update:
            sample = np.concatenate([u, y])
            if not np.all(np.isfinite(sample)):
                check_finite(u[None], "u", self._n_seen)
                check_finite(y[None], "y", self._n_seen)
            return self._keep_aside(sample, False)
        return self.push(u[None, :], y[None, :])

    def _keep_aside(self, sample: Any, update: bool) -> Trace:
        """Keep one undecimated sample in the buffer's pending list (fast ``step``)."""
        assert self._buffer is not None
        self._buffer.pending.append(sample)
        self._n_seen += 1
        if not update:
            return fsm.empty_trace(self)
        block = self._buffer.take_pending()
        self._n_seen -= block.shape[0]  # _consume counts them
        return fsm.consume(self, block)

    def push(
        self, u: Any, y: Any, *, progress: Callable[[int, int, int], Any] | None = None
    ) -> Trace:
        """Feed a chunk of samples of any length.

        Parameters
        ----------
        u : array_like, shape (n,) or (n, n_inputs)
        y : array_like, shape (n,) or (n, n_outputs)
        progress : callable, optional
            Called as ``progress(samples_done, samples_total, updates_done)`` after each
            block of ``chunk_samples`` samples; the same is logged at ``DEBUG`` level on
            the ``clpc.appraiser`` logger.

        Returns
        -------
        Trace
            The updates this chunk produced (possibly empty); the traces of consecutive
            pushes concatenated equal :meth:`run` on the whole record.
        """
        u2 = as_columns(u, "u")
        y2 = as_columns(y, "y")
        if u2.shape[0] != y2.shape[0]:
            raise DataError(
                f"u and y must have the same length; got len(u)={u2.shape[0]}, "
                f"len(y)={y2.shape[0]}."
            )
        check_finite(u2, "u", self._n_seen)
        check_finite(y2, "y", self._n_seen)
        fsm.init_channels(self, u2.shape[1], y2.shape[1])
        if self._decimator is None:
            self._decimator = Decimator(self._factor_for(None))
        total = self._updates_after(u2.shape[0])
        # the parts are written into the final arrays (no concatenation at the end)
        out = Trace.allocate(fsm.empty_trace(self), total) if total else fsm.empty_trace(self)
        done = 0
        for lo in range(0, u2.shape[0], self.chunk_samples):  # bounded working memory
            hi = lo + self.chunk_samples
            part = fsm.consume(self, self._decimator(np.hstack([u2[lo:hi], y2[lo:hi]])))
            if total:
                done = out.put(done, part)
            finished = min(hi, u2.shape[0])
            _LOG.debug("CLPC: %d of %d samples, %d updates", finished, u2.shape[0], done)
            if progress is not None:
                progress(finished, u2.shape[0], done)
        assert done == total, (done, total)
        return out

    def _factor_for(self, data_dt: float | None) -> int:
        dt = data_dt if data_dt is not None else self.data_sample_time
        target = self.sample_time
        if dt is None and target is not None:
            if not self._legacy_sample_time:
                raise DataError(
                    f"decimate_to={target:g} s needs the data's sample time; pass dt= to CLPC "
                    "(or to run()), or give an IOData with its dt."
                )
            warnings.warn(
                f"CLPC(sample_time={target:g}) was taken as the data's sample time (the data "
                f"came without one); pass dt={target:g} instead (sample_time is ambiguous).",
                DeprecationWarning,
                stacklevel=4,
            )
            dt = target
        elif self._legacy_sample_time and target is not None and dt is not None:
            if not math.isclose(target, dt, rel_tol=1e-9):
                warnings.warn(
                    f"CLPC(sample_time={target:g}) was taken as the decimation target (the "
                    f"data's sample time is {dt:g} s); pass decimate_to={target:g} instead "
                    "(sample_time is ambiguous).",
                    DeprecationWarning,
                    stacklevel=4,
                )
        return decimation_factor(target, dt)

    def _updates_after(self, n_samples: int) -> int:
        """Updates that ``n_samples`` more (undecimated) samples will complete."""
        dec = self._decimator
        f = dec.factor if dec is not None else 1
        first = (-(dec.phase if dec is not None else 0)) % f  # the first one decimation keeps
        kept = 0 if first >= n_samples else (n_samples - 1 - first) // f + 1
        rows = max(self._n_seen + kept - self.structure.max_lag, 0)
        return rows // self.cluster_size - self._j_done

    def run(
        self,
        u: Any,
        y: Any | None = None,
        dt: float | None = None,
        *,
        progress: Callable[[int, int, int], Any] | None = None,
    ) -> Trace:
        """Reset, then process a whole record (vectorised over windows).

        Parameters
        ----------
        u : IOData or array_like, shape (T,) or (T, n_inputs)
        y : array_like, shape (T,) or (T, n_outputs), optional
        dt : float, optional
            Sample time of the record [s] (default: the record's, else the constructor's
            ``dt``).
        progress : callable, optional
            ``progress(samples_done, samples_total, updates_done)`` after each block of
            ``chunk_samples`` samples (see :meth:`push`; also logged at ``DEBUG`` level on
            the ``clpc.appraiser`` logger).

        Returns
        -------
        Trace
            One row per update.
        """
        self.reset()
        if isinstance(u, np.ndarray) and isinstance(y, np.ndarray):
            # plain arrays: validated by push, without IOData's defensive copy of the record
            u_arr = as_columns(u, "u", allow_empty=False)
            y_arr = as_columns(y, "y", allow_empty=False)
            data_dt = None if dt is None else _seconds(dt, "dt")
            fsm.init_channels(self, u_arr.shape[1], y_arr.shape[1])
        else:
            data = as_iodata(u, y, dt)
            if data.n_experiments > 1:
                raise DataError(
                    f"CLPC runs over one continuous record; this one holds "
                    f"{data.n_experiments} experiments, and its windows would reach across "
                    "their boundaries. Run each experiment on its own (IOData.split())."
                )
            u_arr, y_arr = data.u, data.y
            given_dt = isinstance(u, IOData) or dt is not None
            data_dt = data.dt if given_dt else None  # arrays without dt: at sample_time
            names = (data.input_names, data.output_names)
            fsm.init_channels(self, data.n_inputs, data.n_outputs, names)
        own = self.data_sample_time
        if data_dt is not None and own is not None and not math.isclose(data_dt, own, rel_tol=1e-9):
            raise DataError(
                f"the record's sample time is {data_dt:g} s but CLPC(dt={own:g}); they must "
                "agree (dt is the data's sample time; decimate_to is the rate to work at)."
            )
        if self.noise_cov is None and self.noise_ratio is None:
            check_spread(u_arr, y_arr, self.scaling)
        self._decimator = Decimator(self._factor_for(data_dt))
        if self.sample_time is None and data_dt is not None:
            self._record_dt = data_dt  # no decimation: the appraiser works at the data's rate
        trace = self.push(u_arr, y_arr, progress=progress)
        factor = self._decimator.factor if self._decimator is not None else 1
        attach_levels(trace, y_arr, factor)  # the windows' levels, for steady_state_model
        return trace

    def _executor(self) -> ThreadPoolExecutor:
        """A thread pool kept for the appraiser's lifetime (created on first use)."""
        if self._pool is None:
            self._pool = ThreadPoolExecutor(self.n_jobs)
        return self._pool

    # ================================================================= persistence
    def config(self) -> dict[str, Any]:
        """Constructor arguments (JSON-safe)."""
        return state_io.config_of(self)

    def state_dict(self) -> dict[str, Any]:
        """The FSM state and configuration as a JSON-safe dict (floats round-trip exactly)."""
        return state_io.snapshot(self)

    @classmethod
    def from_state_dict(cls, state: dict[str, Any]) -> CLPC:
        """Rebuild an appraiser from :meth:`state_dict` output; it continues identically."""
        return state_io.restore(cls, state)

    def save(self, path: str) -> None:
        """Write :meth:`state_dict` as JSON to ``path``."""
        state_io.save(self, path)

    @classmethod
    def load(cls, path: str) -> CLPC:
        """Read an appraiser saved with :meth:`save`."""
        return state_io.load(cls, path)

    def __repr__(self) -> str:
        return (
            f"CLPC(order={self.order}, window_size={self.window_size}, "
            f"cluster_size={self.cluster_size}, dt={self.data_sample_time}, "
            f"decimate_to={self.sample_time}, "
            f"method={self.method!r}, scaling={self.scaling!r}, "
            f"samples_seen={self._n_seen}, updates={self._j_done})"
        )


def _seconds(value: Any, name: str) -> float:
    return check_positive(value, name, "s")
