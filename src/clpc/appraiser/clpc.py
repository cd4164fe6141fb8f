"""CLPC: the paper's appraiser (section V), a finite-state machine over time windows.

Semantics (lag vectors, growing then sliding windows, accept-or-hold, guard, decimation):
``docs/clpc.md``. Settings: :class:`clpc.appraiser.settings.Settings` (read-only). The FSM
state: :class:`clpc.appraiser.state.AppraiserState`, one per record, fed by
:mod:`clpc.appraiser.feeding`, saved by :mod:`clpc.appraiser.saved_state` (its file:
:mod:`clpc.appraiser.state_file`, ``save`` and ``load``); records not in memory go to the
runners of :mod:`clpc.appraiser.runners`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np

from clpc.appraiser.feeding import feed_chunk, feed_record, feed_sample
from clpc.appraiser.inputs import SCALAR_TYPES, as_chunk
from clpc.appraiser.runners import register_runner, runner_for
from clpc.appraiser.saved_state import restored, saved_form
from clpc.appraiser.settings import Settings, SettingsProperties
from clpc.appraiser.state import AppraiserState
from clpc.appraiser.state_file import StateFile
from clpc.appraiser.trace import Trace
from clpc.core.rules import RobustRule

__all__ = ["CLPC", "register_runner"]


class CLPC(SettingsProperties, StateFile):
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
        Samples processed at a time by :meth:`run` and :meth:`push`: bounds their working
        memory (a few copies of a chunk, 8 bytes per sample and channel); larger chunks
        mean fewer hand-overs between the ``n_jobs`` threads.

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
        chunk_samples: int = 524288,
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
        if s.plain_siso and type(u_k) in SCALAR_TYPES and type(y_k) in SCALAR_TYPES:
            return s.keep_scalar(u_k, y_k)  # the common case, one call less
        return feed_sample(s, u_k, y_k, self._map)

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
        chunk = as_chunk(u, y, self._state.n_seen)
        return feed_chunk(self._state, chunk, self._map, progress)

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
        runner = runner_for(u, y)
        if runner is not None:
            return runner(self, u, y, dt)
        return feed_record(self.reset()._state, (u, y, dt), self._map, progress)

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

    def __repr__(self) -> str:
        return (
            f"CLPC(order={self.order}, window_size={self.window_size}, "
            f"cluster_size={self.cluster_size}, dt={self.dt}, decimate_to={self.decimate_to}, "
            f"method={self.method!r}, scaling={self.scaling!r}, "
            f"samples_seen={self._state.n_seen}, updates={self._state.j_done})"
        )
