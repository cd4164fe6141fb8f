"""CLPC: the paper's appraiser (section V), a finite-state machine over time windows.

The semantics - samples and lag vectors, windows that grow then slide, an update every
``cluster_size`` lag vectors, accept-or-hold, the guard, decimation - are in ``docs/clpc.md``.
The settings are :class:`clpc.appraiser.settings.Settings` (checked, read-only); the FSM state
and its transition :class:`clpc.appraiser.state.AppraiserState`, one per record.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np

from clpc.appraiser.decimation import Decimator
from clpc.appraiser.inputs import (
    SCALAR_TYPES,
    as_chunk,
    as_columns,
    as_record,
    check_chunk,
    check_finite,
)
from clpc.appraiser.saved_state import read_state, restored, saved_form, write_state
from clpc.appraiser.settings import Settings
from clpc.appraiser.spread import attach_levels
from clpc.appraiser.state import AppraiserState
from clpc.appraiser.trace import Trace
from clpc.core.rules import RobustRule
from clpc.data.samples import check_spread

__all__ = ["CLPC", "register_runner"]

_LOG = logging.getLogger("clpc.appraiser")


#: runners of records that are not arrays in memory (e.g. a ``dask.array``), registered by
#: the layers above (:mod:`clpc.distributed.long_record`): ``(accepts(x), run(appraiser, u,
#: y, dt))``; :meth:`CLPC.run` hands a record to the first that accepts ``u`` or ``y``
_RUNNERS: list[tuple[Callable[[Any], bool], Callable[..., Trace]]] = []


def register_runner(accepts: Callable[[Any], bool], run: Callable[..., Trace]) -> None:
    """Let :meth:`CLPC.run` hand records that ``accepts`` to ``run(appraiser, u, y, dt)``.

    Parameters
    ----------
    accepts : callable
        ``accepts(u_or_y)``: whether the runner takes this record.
    run : callable
        ``run(appraiser, u, y, dt)``, returning the :class:`Trace` ``run`` would return.
    """
    if (accepts, run) not in _RUNNERS:
        _RUNNERS.append((accepts, run))


def _setting(name: str, doc: str) -> Any:
    return property(lambda self: getattr(self.settings, name), doc=doc)


class CLPC:
    """The Cluster LPC appraiser: streaming ``step``/``push`` and a vectorised ``run``.

    Every setting is named (keyword-only); ``docs/clpc.md`` maps the paper's names to them.

    Parameters
    ----------
    order : int
        The model order ``N`` (``na = nb = N``; the paper's ``parameters_size`` is ``N + 1``);
        default 2 (Table 1).
    window_size : int
        ``W``: lag vectors per LPC (Table 1: 201).
    cluster_size : int
        ``C``: lag vectors between updates (the paper's ``data_cluster_dimension``; 12).
    dt : float, optional
        Sample time of plain arrays [s] (a record's own ``dt`` must agree).
    decimate_to : float, optional
        Sample time [s] worked at, an integer multiple of the data's: the data are low-pass
        filtered and decimated (Table 1: 0.01 on 1 ms data). Needs the data's sample time.
    guard : bool
        Accept estimates of trusted windows only (default ``True``; see ``docs/clpc.md`` and
        :func:`clpc.core.rules.is_trusted`); ``False`` is the paper's appraiser.
    na, nb, nk : int, optional
        Separate orders and input delay (override ``order``).
    method, scaling, noise_ratio, noise_cov, rule
        LPC options (see :class:`clpc.LPC`).
    mimo : {"siso", "paired", "miso"}, optional
        Multi-channel structure (default ``"siso"`` for 1x1 data, else ``"miso"``).
    trust_rows : int, optional
        Lag vectors a trusted window needs (default ``max(10 p, W / 2)``, at most ``W``).
    min_rows : int, optional
        Fewest rows for a usable estimate (default ``2 p``); smaller windows are not solved.
    n_jobs : int
        Threads for the batched solves (windows are independent).
    chunk_samples : int
        Samples processed at a time by :meth:`push` (bounds memory).

    Notes
    -----
    The windows are solved by a numba-compiled kernel (:mod:`clpc.appraiser.kernel`, compiled
    on first use and cached on disk); with ``NUMBA_DISABLE_JIT=1`` the same functions run
    uncompiled (slow; for debugging and coverage).
    """

    def __init__(
        self,
        *,
        order: int = 2,
        window_size: int = 201,
        cluster_size: int = 12,
        dt: float | None = None,
        decimate_to: float | None = None,
        guard: bool = True,
        na: int | None = None,
        nb: int | None = None,
        nk: int = 0,
        method: str = "robust",
        scaling: str = "none",
        mimo: str | None = None,
        noise_ratio: float | None = None,
        noise_cov: Any = None,
        rule: RobustRule | None = None,
        trust_rows: int | None = None,
        min_rows: int | None = None,
        n_jobs: int = 1,
        chunk_samples: int = 65536,
    ) -> None:
        settings = Settings(
            order, window_size, cluster_size, dt, decimate_to, guard, na, nb, nk, method,
            scaling, mimo, noise_ratio, noise_cov, rule or RobustRule(), trust_rows, min_rows,
            n_jobs, chunk_samples,
        )  # fmt: skip
        self._start(settings)

    def _start(self, settings: Settings) -> None:
        self.settings = settings
        self._pool: ThreadPoolExecutor | None = None
        #: ``map`` of the batched solves: a thread pool's (created on first use) with n_jobs
        self._map: Callable[..., Iterable[Any]] = map if settings.n_jobs == 1 else self._threads
        self._state = AppraiserState(settings)

    order = _setting("order", "``N``: ``na = nb = N`` unless ``na``/``nb`` are given.")
    window_size = _setting("window_size", "``W``: lag vectors per LPC.")
    cluster_size = _setting("cluster_size", "``C``: lag vectors between updates.")
    dt = _setting("dt", "The data's sample time [s] given to the constructor (or ``None``).")
    decimate_to = _setting("decimate_to", "Sample time [s] worked at (``None``: the data's).")
    guard = _setting("guard", "Accept estimates of trusted windows only.")
    structure = _setting("structure", "The model structure (``na``, ``nb``, ``nk``).")
    method = _setting("method", "The LPC solve: ``'robust'`` or ``'paper'``.")
    scaling = _setting("scaling", "Channel scaling of the LPC solve.")
    mimo = _setting("mimo", "Multi-channel structure (``None``: from the data).")
    noise_ratio = _setting("noise_ratio", "Known noise ratio of the LPC solve (or ``None``).")
    noise_cov = _setting("noise_cov", "Known noise covariance of the lag vector (or ``None``).")
    rule = _setting("rule", "The thresholds of the robust solve.")
    trust_rows = _setting("trust_rows", "Lag vectors a trusted window needs (``None``: default).")
    min_rows = _setting("min_rows", "Fewest rows of a usable window (``None``: ``2 p``).")
    n_jobs = _setting("n_jobs", "Threads of the batched solves.")
    chunk_samples = _setting("chunk_samples", "Samples processed at a time by :meth:`push`.")

    # ================================================================= state
    def reset(self) -> CLPC:
        """Forget all data: empty window, counter 0, no parameters. Returns ``self``."""
        self._state = AppraiserState(self.settings)
        return self

    @property
    def counter(self) -> int:
        """Lag vectors since the last update (0 .. cluster_size - 1)."""
        s = self._state
        return max(s.n_seen - s.max_lag, 0) - s.j_done * s.cluster

    @property
    def n_samples(self) -> int:
        """Samples seen (after decimation)."""
        return self._state.n_seen

    @property
    def theta(self) -> np.ndarray | None:
        """Last output parameters (unit norm), shape (p,) or (n_outputs, p); None before data."""
        if self._state.last_theta is None:
            return None
        out = self._state.last_theta.copy()
        out.setflags(write=False)
        return out[0] if out.shape[0] == 1 else out

    @property
    def window(self) -> np.ndarray:
        """The current window's lag vectors (read-only), shape (rows, p) or (E, rows, p)."""
        rows = self._state.window()
        rows.setflags(write=False)
        return rows[0] if rows.shape[0] == 1 else rows

    # ================================================================= streaming API
    def step(self, u_k: Any, y_k: Any) -> Trace:
        """Feed one sample; returns the update it produced (a trace of 0 or 1 rows).

        Parameters
        ----------
        u_k : float or array_like, shape (n_inputs,)
            The input sample.
        y_k : float or array_like, shape (n_outputs,)
            The output sample at the same instant.

        Returns
        -------
        Trace
            One row when this sample closes a cluster (an update), else none.
        """
        s = self._state
        rows_after = s.n_seen + 1 - s.max_lag
        update = rows_after > 0 and rows_after % s.cluster == 0
        if s.plain_siso and type(u_k) in SCALAR_TYPES and type(y_k) in SCALAR_TYPES:
            # single-channel scalars: plain floats, no arrays until the update
            u_f, y_f = float(u_k), float(y_k)
            if not (math.isfinite(u_f) and math.isfinite(y_f)):
                check_finite(np.array([[u_f]]), "u", s.n_seen)
                check_finite(np.array([[y_f]]), "y", s.n_seen)
            return s.keep_aside((u_f, y_f), update, self._map)
        u = as_columns(u_k, "u").ravel()
        y = as_columns(y_k, "y").ravel()
        if s.plain and u.shape == (s.n_in,) and y.shape == (s.n_out,) and not update:
            sample = np.concatenate([u, y])
            if not np.all(np.isfinite(sample)):
                check_finite(u[None], "u", s.n_seen)
                check_finite(y[None], "y", s.n_seen)
            return s.keep_aside(sample, False, self._map)
        return self.push(u[None, :], y[None, :])

    def push(
        self, u: Any, y: Any, *, progress: Callable[[int, int, int], Any] | None = None
    ) -> Trace:
        """Feed a chunk of samples of any length.

        Parameters
        ----------
        u : array_like, shape (n,) or (n, n_inputs)
            Input samples.
        y : array_like, shape (n,) or (n, n_outputs)
            Output samples at the same instants.
        progress : callable, optional
            ``progress(samples_done, samples_total, updates_done)``, called after each block
            of ``chunk_samples`` samples (also logged at ``DEBUG`` on the ``clpc.appraiser``
            logger).

        Returns
        -------
        Trace
            The updates of this chunk (possibly none): consecutive pushes concatenated equal
            :meth:`run` on the whole record.
        """
        return self._feed(as_chunk(u, y, self._state.n_seen), progress)

    def _feed(
        self, chunk: tuple[np.ndarray, np.ndarray], progress: Callable[[int, int, int], Any] | None
    ) -> Trace:
        """:meth:`push` of a chunk already checked by :func:`as_chunk` (or :func:`check_chunk`)."""
        s = self._state
        u2, y2 = chunk
        n = u2.shape[0]
        s.init_channels(u2.shape[1], y2.shape[1])
        if s.decimator is None:
            s.set_decimator(Decimator(self.settings.factor(None)))
        decimator = s.decimator
        assert decimator is not None
        total = s.updates_after(n)
        # the kernel writes the updates straight into the final arrays (no copies)
        out = Trace.allocate(s.empty_trace(), total) if total else s.empty_trace()
        done, step = 0, self.settings.chunk_samples
        for lo in range(0, n, step):  # bounded working memory
            hi = lo + step
            block = decimator(np.hstack([u2[lo:hi], y2[lo:hi]]))
            if total:
                done = s.consume_into(block, self._map, out, done)
            else:
                s.consume(block, self._map)  # no update: the samples are only kept
            _LOG.debug("CLPC: %d of %d samples, %d updates", min(hi, n), n, done)
            if progress is not None:
                progress(min(hi, n), n, done)
        assert done == total, (done, total)
        return out

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
            The record, or its inputs.
        y : array_like, shape (T,) or (T, n_outputs), optional
            Outputs (when ``u`` is not an :class:`IOData`).
        dt : float, optional
            The record's sample time [s] (default: the record's, else the constructor's).
        progress : callable, optional
            As for :meth:`push`.

        Returns
        -------
        Trace
            One row per update.

        Notes
        -----
        A ``dask.array`` record is appraised piece by piece on a Dask cluster once
        :mod:`clpc.distributed` is imported (:func:`clpc.distributed.run_long`; the same
        trace).
        """
        for accepts, runner in _RUNNERS:
            if accepts(u) or accepts(y):
                return runner(self, u, y, dt)
        s = self.reset()._state
        u_arr, y_arr, data_dt, names = as_record(u, y, dt)
        s.init_channels(u_arr.shape[1], y_arr.shape[1], names)
        factor = self.settings.factor(data_dt)
        if self.noise_cov is None and self.noise_ratio is None:
            check_spread(u_arr, y_arr, self.scaling)
        s.set_decimator(Decimator(factor))
        if self.decimate_to is None and data_dt is not None:
            s.record_dt = data_dt  # no decimation: the appraiser works at the data's rate
        # as_record made them float columns (as push would): only length and finiteness left
        trace = self._feed(check_chunk(u_arr, y_arr, 0), progress)
        attach_levels(trace, y_arr, factor)  # the windows' levels (steady state)
        return trace

    def _threads(self, fn: Callable[..., Any], items: Iterable[Any]) -> Iterator[Any]:
        """``map`` on a thread pool kept for the appraiser's lifetime (made on first use)."""
        if self._pool is None:
            self._pool = ThreadPoolExecutor(self.n_jobs)
        return self._pool.map(fn, items)

    # ================================================================= persistence
    def config(self) -> dict[str, Any]:
        """Constructor arguments (JSON-safe)."""
        return self.settings.config()

    def state_dict(self) -> dict[str, Any]:
        """The FSM state and configuration as a JSON-safe dict (floats round-trip exactly)."""
        return saved_form(self.config(), self._state)

    @classmethod
    def from_state_dict(cls, state: dict[str, Any]) -> CLPC:
        """Rebuild an appraiser from :meth:`state_dict` output; it continues identically.

        Parameters
        ----------
        state : dict
            What :meth:`state_dict` returned (e.g. decoded from the JSON of :meth:`save`).

        Raises
        ------
        StateError
            A damaged or edited state: every field is checked first
            (:mod:`clpc.appraiser.state_schema`) and the error names the field.
        """
        fsm = restored(state)
        appraiser = cls.__new__(cls)
        appraiser._start(fsm.settings)
        appraiser._state = fsm
        return appraiser

    def save(self, path: str) -> None:
        """Write :meth:`state_dict` as JSON to ``path``, atomically.

        The state is written to a temporary file beside ``path`` and renamed over it, so a
        run killed while saving leaves the previous state file whole.

        Parameters
        ----------
        path : str
            Destination file (replaced if it exists).

        Raises
        ------
        clpc.core.atomic.OutputError
            ``path`` is a symbolic link, or writing failed (``path`` is left as it was).
        """
        write_state(path, self.state_dict())

    @classmethod
    def load(cls, path: str) -> CLPC:
        """Read an appraiser saved with :meth:`save`.

        Parameters
        ----------
        path : str
            A file written by :meth:`save`.

        Returns
        -------
        CLPC
            The appraiser, continuing where the saved one stopped.
        """
        return cls.from_state_dict(read_state(path))

    def __repr__(self) -> str:
        return (
            f"CLPC(order={self.order}, window_size={self.window_size}, "
            f"cluster_size={self.cluster_size}, dt={self.dt}, decimate_to={self.decimate_to}, "
            f"method={self.method!r}, scaling={self.scaling!r}, "
            f"samples_seen={self._state.n_seen}, updates={self._state.j_done})"
        )
