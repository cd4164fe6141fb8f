"""One record too long for one core: :meth:`clpc.CLPC.run` spread over a Dask cluster.

The record is cut into pieces of consecutive updates (:mod:`clpc.distributed.pieces`). Per
piece, a worker reads its samples (a memory-mapped ``.npy`` slice, Parquet row groups, or
a slice of a ``dask.array`` computed on the workers: no sample passes through the client)
and solves its windows; a cheap chain of tasks then runs the finite-state machine piece
after piece, each passing on the few numbers of its end state; last, each piece's trace
rows are built (returned, or written by the worker as one file of a Parquet dataset).
Pieces in flight are bounded (:data:`AHEAD` per worker), so memory stays O(piece).

The trace equals ``CLPC(...).run(u, y)`` bit for bit without decimation; with decimation
each piece starts its anti-alias filter a warm-up earlier (:func:`.pieces.warmup`) and the
numbers agree to rounding (``docs/distributed-long.md``).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from typing import Any

import numpy as np

from clpc.appraiser import CLPC
from clpc.appraiser.clpc import register_runner
from clpc.appraiser.trace import Trace
from clpc.data import DataError
from clpc.data.samples import check_spread
from clpc.distributed.cluster import dask_client, require_distributed
from clpc.distributed.piece_tasks import (
    RecordPlan,
    SolvedPiece,
    end_state,
    finish_piece,
    fsm_piece,
    solve_piece,
)
from clpc.distributed.pieces import Layout, Piece
from clpc.distributed.sources import NpySource, ParquetSource

__all__ = [
    "AHEAD",
    "PIECE_SAMPLES",
    "check_peaks",
    "default_piece_samples",
    "gather",
    "is_dask_array",
    "plan_record",
    "run_long",
    "run_pieces",
]

#: most decimated samples per piece by default (about 1 s of one core's solving)
PIECE_SAMPLES = 1 << 20
#: pieces per worker the default piece size aims at (so that the workers stay busy)
PIECES_PER_WORKER = 4
#: fewest decimated samples per piece by default, in windows (the overlap read twice, at
#: most ``W + max_lag``, stays below 2 % of a piece)
MIN_PIECE_WINDOWS = 64
#: pieces in flight per worker (solved, not yet finished)
AHEAD = 3

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
    """
    settings = appraiser.settings
    factor = settings.factor(dt)
    record_dt = dt if settings.decimate_to is None else None
    layout = Layout(settings.window_size, settings.cluster_size, settings.structure.max_lag, factor)
    return RecordPlan(settings, channels, names, record_dt, layout, n_raw)


def _reader(record: Any) -> Callable[[Any, Piece], Any]:
    """How a piece's raw samples reach its worker: ``reader(client, piece)``."""
    if isinstance(record, NpySource | ParquetSource):
        return lambda client, piece: record  # the worker reads the file itself
    u, y = record  # each sliced on its own: no rechunking to align their chunks

    def read(client: Any, piece: Piece) -> Any:
        lo, hi = piece.raw
        return tuple(client.compute([u[lo:hi], y[lo:hi]]))

    return read


def run_pieces(
    client: Any,
    plan: RecordPlan,
    record: Any,
    piece_samples: int | None = None,
    out: tuple[str, tuple[str, ...]] | None = None,
) -> tuple[list[Trace], np.ndarray]:
    """Run every piece of a record on ``client``.

    Parameters
    ----------
    client : distributed.Client
    plan : RecordPlan
    record : source or (dask.array.Array, dask.array.Array)
        A file source, or inputs and outputs as 2-D dask arrays.
    piece_samples : int, optional
        Decimated samples per piece; default :func:`default_piece_samples`.
    out : (str, tuple of str), optional
        ``(folder, keys)``: the workers write each piece's rows to
        ``folder/part-NNNNNN.parquet`` and return only the arrays ``keys``.

    Returns
    -------
    parts : list of Trace
        The pieces' traces in time order (what :func:`.piece_tasks.finish_piece` returned).
    peaks : ndarray, shape (channels,)
        The largest magnitude of every raw channel of the record.
    """
    n_workers = max(1, len(client.scheduler_info().get("workers", {})))
    size = piece_samples or default_piece_samples(plan, n_workers)
    pieces = plan.layout.pieces(plan.n_raw, size)
    if pieces:  # the last piece reads to the end (the whole record is checked)
        last = pieces[-1]
        pieces[-1] = last._replace(raw=(last.raw[0], plan.n_raw))
    read = _reader(record)
    limit = AHEAD * n_workers
    state: Any = plan.initial()
    solving: deque[tuple[Piece, Any]] = deque()
    finishing: deque[tuple[Any, Any]] = deque()
    results: list[Trace] = []
    peaks = np.zeros(sum(plan.channels))
    todo = deque(pieces)
    while todo or solving or finishing:
        while todo and len(solving) + len(finishing) < limit:
            piece = todo.popleft()
            raw = read(client, piece)
            solving.append((piece, client.submit(solve_piece, raw, plan, piece, pure=False)))
        if solving:  # the oldest solved piece: its FSM pass and rows where it lies
            piece, solved = solving.popleft()
            state, done, peak = _chain(client, (plan, piece, solved), state, out)
            finishing.append((done, peak))
        if finishing and (finishing[0][0].done() or not solving):
            done, peak = finishing.popleft()
            results.append(done.result())
            peaks = np.maximum(peaks, peak.result())
    return results, peaks


def _chain(
    client: Any, job: tuple[RecordPlan, Piece, Any], state: Any, out: tuple[str, Any] | None
) -> tuple[Any, Any, Any]:
    """Submit a solved piece's FSM pass (after the previous piece's), rows and peaks.

    They run on the worker that holds the solved piece (a preference: another worker takes
    them if that one is lost), so only the few numbers of the FSM state move between
    workers. Returns the futures of the end state, the rows and the peaks.
    """
    plan, piece, solved = job
    distributed = require_distributed()
    distributed.wait(solved)
    if solved.status == "error":
        solved.result()  # raises the worker's error (e.g. a sample that is not finite)
    where = list(client.who_has(solved).get(solved.key, ()))
    kw: dict[str, Any] = {"pure": False}
    if where:
        kw.update(workers=where, allow_other_workers=True)
    outputs = client.submit(fsm_piece, solved, plan, state, **kw)
    path = None if out is None else f"{out[0]}/part-{piece.number:06d}.parquet"
    keep = None if out is None else out[1]
    done = client.submit(finish_piece, solved, outputs, plan, path, keep, **kw)
    return (
        client.submit(end_state, outputs, **kw),
        done,
        client.submit(_peaks, solved, **kw),
    )


def default_piece_samples(plan: RecordPlan, n_workers: int) -> int:
    """Decimated samples per piece by default.

    :data:`PIECES_PER_WORKER` pieces per worker, at most :data:`PIECE_SAMPLES` samples, at
    least :data:`MIN_PIECE_WINDOWS` windows.
    """
    share = plan.layout.kept(plan.n_raw) // (PIECES_PER_WORKER * n_workers)
    return max(min(share, PIECE_SAMPLES), MIN_PIECE_WINDOWS * plan.layout.window)


def _peaks(solved: SolvedPiece) -> np.ndarray:
    return solved.peaks


def gather(parts: list[Trace]) -> Trace:
    """The record's trace from its pieces' traces (window levels joined)."""
    total = sum(len(p) for p in parts)
    trace = Trace.allocate(parts[0], total)
    done = 0
    for part in parts:
        done = trace.put(done, part)
    levels = [p.meta["window_level"] for p in parts]
    trace.meta["window_level"] = np.concatenate(levels)
    return trace


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
        parts, peaks = run_pieces(dask, plan, record, piece_samples)
    check_peaks(appraiser, peaks, channels[0])
    return gather(parts)


def check_peaks(appraiser: CLPC, peaks: np.ndarray, n_in: int) -> None:
    """The whole record's scale check of :meth:`clpc.CLPC.run`, from the channels' peaks."""
    if appraiser.noise_cov is None and appraiser.noise_ratio is None:
        check_spread(peaks[None, :n_in], peaks[None, n_in:], appraiser.scaling)


register_runner(is_dask_array, run_long)
