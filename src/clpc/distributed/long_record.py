"""One record too long for one core: :meth:`clpc.CLPC.run` spread over a Dask cluster.

The record is cut into pieces of consecutive updates (:mod:`clpc.distributed.pieces`). Per
piece, a worker reads its samples (a memory-mapped ``.npy`` slice, Parquet row groups, or
a slice of a ``dask.array`` computed on the workers: no sample passes through the client),
solves its windows and runs the finite-state machine over them from "no model yet",
straight into the piece's trace rows; the client carries the FSM state from piece to piece
(a few numbers each), and the piece's first updates, up to each equation's first accepted
one, are run again from that state (:mod:`.piece_tasks`). On the client's machine the rows
lie in the record's trace in shared memory (:mod:`.shared_rows`): the workers write them
there and the client settles them in its map, so no rows are sent; a worker of another
machine settles its piece and returns the rows (or, in :mod:`.long_track`, writes them as
one file of a Parquet dataset). Pieces in flight are bounded (:mod:`.schedule`), so
memory stays O(piece).

The trace equals ``CLPC(...).run(u, y)`` bit for bit without decimation; with decimation
each piece starts its anti-alias filter a warm-up earlier (:func:`.pieces.warmup`) and the
numbers agree to rounding (``docs/distributed-long.md``).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from clpc.appraiser import CLPC
from clpc.appraiser.clpc import register_runner
from clpc.appraiser.trace import Trace
from clpc.data import DataError
from clpc.data.samples import check_ranges
from clpc.distributed.cluster import dask_client
from clpc.distributed.piece_tasks import FsmTuple, PieceInfo, RecordPlan, SolvedPiece, settle
from clpc.distributed.pieces import Layout, Piece
from clpc.distributed.schedule import run_pieces
from clpc.distributed.shared_rows import Mapped, SharedRows
from clpc.distributed.sources import NpySource, ParquetSource

__all__ = [
    "check_peaks",
    "gather",
    "is_dask_array",
    "plan_record",
    "run_long",
]

Source = NpySource | ParquetSource


def is_dask_array(x: Any) -> bool:
    """Whether ``x`` is a ``dask.array.Array`` (without importing dask)."""
    return type(x).__module__.startswith("dask.array") and hasattr(x, "chunks")


def _columns(x: Any, name: str) -> Any:
    """A dask array as a 2-D (samples, channels) dask array."""
    if x.ndim == 1:
        return x[:, None]
    if x.ndim != 2:
        raise DataError(f"{name} must be 1-D or 2-D (samples, channels); got shape {x.shape}.")
    return x


def plan_record(
    appraiser: CLPC,
    channels: tuple[int, int],
    n_raw: int,
    dt: float | None = None,
    names: tuple[tuple[str, ...], tuple[str, ...]] | None = None,
    levels: bool = True,
) -> RecordPlan:
    """The plan of a record of ``n_raw`` samples for ``appraiser`` (its settings, decimation).

    Parameters
    ----------
    appraiser : CLPC
    channels : (int, int)
        Inputs and outputs.
    n_raw : int
        Samples of the record (at the data's rate).
    dt : float, optional
        The data's sample time [s] (default the appraiser's ``dt``).
    names : ((str, ...), (str, ...)), optional
        Input and output names.
    levels : bool
        Compute the windows' mean output levels (``meta["window_level"]`` of the trace).
    """
    settings = appraiser.settings
    factor = settings.factor(dt)
    record_dt = dt if settings.decimate_to is None else None
    layout = Layout(settings.window_size, settings.cluster_size, settings.structure.max_lag, factor)
    return RecordPlan(settings, channels, names, record_dt, layout, n_raw, levels)


def gather(parts: list[Trace]) -> Trace:
    """The record's trace from its pieces' traces (window levels joined, when they have them)."""
    total = sum(len(p) for p in parts)
    trace = Trace.allocate(parts[0], total)
    done = 0
    for part in parts:
        done = trace.put(done, part)
    trace.meta.pop("window_level", None)
    if all("window_level" in p.meta for p in parts):
        trace.meta["window_level"] = np.concatenate([p.meta["window_level"] for p in parts])
    return trace


class _InPlace(NamedTuple):
    """A piece settled by the client in the shared trace."""

    start: int  #: its first row
    n_rows: int  #: its rows


class _Joined:
    """A record's trace filled piece by piece as the pieces arrive (one copy in memory).

    ``shared``: the record's trace in shared memory, which the workers of this machine
    write themselves, with each window's own ``c`` and level as extra arrays
    (:class:`.shared_rows.SharedRows` and the client's map of it); else the trace is made
    from the first piece sent.
    """

    def __init__(self, plan: RecordPlan, shared: tuple[SharedRows, Mapped] | None) -> None:
        self.plan = plan
        self.total = plan.layout.updates(plan.n_raw)
        self.shared: SharedRows | None = None
        self.mapped: Mapped | None = None
        self.trace: Trace | None = None
        if shared is not None:
            self.shared, self.mapped = shared
            self.trace = self.mapped.trace
        self.done = 0
        self.levels: list[np.ndarray] = []

    def settle(
        self, piece: Piece, info: PieceInfo, state: FsmTuple, worker: str | None = None
    ) -> _InPlace:
        """Finish a piece the workers wrote into the shared trace (in this process's map).

        ``worker``: the one that solved it (not needed: nothing is left to do there).
        """
        assert self.mapped is not None
        lo, hi = piece.j_lo - 1, piece.j_hi
        c = self.mapped.extra[0][lo:hi]
        here = SolvedPiece(piece, self.mapped.trace.view(lo, hi), c, info.first, info.peaks, True)
        settle(here, self.plan, state)
        return _InPlace(lo, hi - lo)

    def add(self, part: Trace | _InPlace) -> None:
        if isinstance(part, _InPlace):
            assert part.start == self.done, (part.start, self.done)
            self.done += part.n_rows
            return
        start, stop = self.done, self.done + len(part)
        if self.trace is None:
            self.trace = Trace.allocate(part, self.total)
        elif self.shared is not None:  # sent by a worker that does not see the file
            self.shared.reserve((start, stop))
        self.done = self.trace.put(start, part)
        if self.mapped is not None:
            self.mapped.extra[1][start:stop] = part.meta["window_level"]
        else:
            self.levels.append(part.meta["window_level"])

    def result(self) -> Trace:
        assert self.trace is not None and self.done == self.total, (self.done, self.total)
        if self.mapped is not None:
            self.trace.meta["window_level"] = self.mapped.extra[1]
        else:
            self.trace.meta["window_level"] = np.concatenate(self.levels)
        return self.trace


def _short_record(config: dict[str, Any], raw: Any, n_in: int, dt: float | None) -> Trace:
    """A record without a single update, read and appraised on a worker as it is."""
    if isinstance(raw, tuple):
        return CLPC(**config).run(np.asarray(raw[0]), np.asarray(raw[1]), dt)
    both = raw.read(0, raw.length())
    return CLPC(**config).run(both[:, :n_in], both[:, n_in:], dt)


def run_long(
    appraiser: CLPC,
    u: Any,
    y: Any = None,
    dt: float | None = None,
    *,
    client: Any = None,
    scheduler: str | None = None,
    workers: int | None = None,
    piece_samples: int | None = None,
) -> Trace:
    """:meth:`clpc.CLPC.run` over a record split into pieces on a Dask cluster.

    Parameters
    ----------
    appraiser : CLPC
        Its settings are used; it is reset (not advanced to the record's end).
    u : dask.array.Array or NpySource or ParquetSource
        The inputs, shape (T,) or (T, n_inputs) (with ``y``); or a file source
        (:func:`clpc.distributed.sources.open_source`) naming inputs and outputs.
    y : dask.array.Array, optional
        The outputs, shape (T,) or (T, n_outputs), with a dask ``u``.
    dt : float, optional
        The data's sample time [s] (default the appraiser's ``dt``).
    client, scheduler, workers
        Where to run (:func:`clpc.distributed.dask_client`): a client, a scheduler's
        address, or a local cluster of ``workers`` processes.
    piece_samples : int, optional
        Decimated samples per piece (each piece also reads up to ``W + max_lag`` before);
        default :func:`default_piece_samples`.

    Returns
    -------
    Trace
        Equal to ``appraiser.run(u, y, dt)`` (every array bit for bit without decimation;
        ``meta["window_level"]`` to rounding).

    Raises
    ------
    clpc.DataError
        A sample that is not finite (index in the record), channels of hopeless scales
        (:func:`clpc.data.samples.check_spread`), mismatched lengths.
    """
    appraiser.reset()
    if isinstance(u, NpySource | ParquetSource):
        record: Any = u
        channels = (len(u.inputs), len(u.outputs))
        n_raw, names = u.length(), u.names()
    else:
        import dask.array as da

        # one of them in memory: sliced by Dask like the other
        u, y = (x if is_dask_array(x) else da.from_array(np.asarray(x)) for x in (u, y))
        u2, y2 = _columns(u, "u"), _columns(y, "y")
        if u2.shape[0] != y2.shape[0]:
            raise DataError(
                f"u and y must have the same length; got len(u)={u2.shape[0]}, "
                f"len(y)={y2.shape[0]}."
            )
        record = (u2, y2)
        channels, n_raw, names = (u2.shape[1], y2.shape[1]), int(u2.shape[0]), None
    plan = plan_record(appraiser, channels, n_raw, dt, names)
    with dask_client(client, scheduler, workers) as dask:
        if plan.layout.updates(n_raw) == 0:  # no window: the record is small, run as it is
            raw = (
                record
                if isinstance(record, NpySource | ParquetSource)
                else (dask.compute(record[0]), dask.compute(record[1]))
            )
            config = appraiser.config()
            short = dask.submit(_short_record, config, raw, channels[0], dt, pure=False)
            return short.result()
        # the extra arrays: each window's own c and level, per output
        extra = ((channels[1],), (channels[1],))
        made = SharedRows.create(plan.state().empty_trace(), plan.layout.updates(n_raw), extra)
        shared = made[0] if made is not None else None
        joined = _Joined(plan, made)
        try:
            _, peaks = run_pieces(
                dask, plan, record, piece_samples, sink=joined.add, shared=shared,
                local=joined.settle,
            )  # fmt: skip
        finally:
            if shared is not None:
                shared.remove()
    check_peaks(appraiser, peaks, channels[0])
    return joined.result()


def check_peaks(appraiser: CLPC, peaks: np.ndarray, n_in: int) -> None:
    """The whole record's scale check of :meth:`clpc.CLPC.run`, from the channels' extremes.

    ``peaks`` (2, channels): each channel's maximum and minimum over every piece; their
    difference is the range :func:`clpc.data.samples.check_spread` computes on the whole.
    """
    if appraiser.noise_cov is None and appraiser.noise_ratio is None:
        check_ranges(peaks[0] - peaks[1], n_in, appraiser.scaling)


register_runner(is_dask_array, run_long)
