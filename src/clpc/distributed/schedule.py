"""How a long record's pieces are given to a Dask cluster (see :mod:`.long_record`).

:func:`run_pieces` submits each piece's solve, then - in time order, on the worker that
holds the solved piece - its FSM pass (after the previous piece's), its finish and its
channel extremes. At most :data:`AHEAD` pieces per worker are in flight, so a worker's memory
is O(piece) whatever the record's length.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from typing import Any

import numpy as np

from clpc.distributed.cluster import require_distributed
from clpc.distributed.piece_tasks import (
    RecordPlan,
    SolvedPiece,
    end_state,
    finish_piece,
    fsm_piece,
    solve_piece,
)
from clpc.distributed.pieces import Piece
from clpc.distributed.sources import NpySource, ParquetSource

__all__ = [
    "AHEAD",
    "MIN_PIECE_WINDOWS",
    "PIECES_PER_WORKER",
    "PIECE_SAMPLES",
    "default_piece_samples",
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
    finish: tuple[Callable[..., Any], tuple[Any, ...]] = (finish_piece, ()),
    sink: Callable[[Any], None] | None = None,
) -> tuple[list[Any], np.ndarray]:
    """Run every piece of a record on ``client``.

    Parameters
    ----------
    client : distributed.Client
    plan : RecordPlan
    record : source or (dask.array.Array, dask.array.Array)
        A file source, or inputs and outputs as 2-D dask arrays.
    piece_samples : int, optional
        Decimated samples per piece; default :func:`default_piece_samples`.
    finish : (callable, tuple)
        ``(function, args)``: the last task of a piece, ``function(solved, outputs, plan,
        *args)`` (default :func:`.piece_tasks.finish_piece`: the piece's trace).

    sink : callable, optional
        Called with what ``finish`` returned for each piece, in time order, as it arrives
        (then not kept: ``parts`` is empty).

    Returns
    -------
    parts : list
        What ``finish`` returned for each piece, in time order (without ``sink``).
    peaks : ndarray, shape (2, channels)
        The maximum and the minimum of every raw channel of the record.
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
    results: list[Any] = []
    take = results.append if sink is None else sink
    peaks = np.array([[-np.inf], [np.inf]]) * np.ones(sum(plan.channels))
    todo = deque(pieces)
    while todo or solving or finishing:
        while todo and len(solving) + len(finishing) < limit:
            piece = todo.popleft()
            raw = read(client, piece)
            solving.append((piece, client.submit(solve_piece, raw, plan, piece, pure=False)))
        if solving:  # the oldest solved piece: its FSM pass and rows where it lies
            piece, solved = solving.popleft()
            state, done, peak = _chain(client, (plan, solved), state, finish)
            finishing.append((done, peak))
        if finishing and (finishing[0][0].done() or not solving):
            done, peak = finishing.popleft()
            take(done.result())
            part = peak.result()  # (2, channels): the piece's maxima and minima
            peaks = np.stack([np.maximum(peaks[0], part[0]), np.minimum(peaks[1], part[1])])
    return results, peaks


def _chain(
    client: Any,
    job: tuple[RecordPlan, Any],
    state: Any,
    finish: tuple[Callable[..., Any], tuple[Any, ...]],
) -> tuple[Any, Any, Any]:
    """Submit a solved piece's FSM pass (after the previous piece's), finish and peaks.

    They run on the worker that holds the solved piece (a preference: another worker takes
    them if that one is lost), so only the few numbers of the FSM state move between
    workers. Returns the futures of the end state, the finish and the peaks.
    """
    plan, solved = job
    distributed = require_distributed()
    distributed.wait(solved)
    if solved.status == "error":
        solved.result()  # raises the worker's error (e.g. a sample that is not finite)
    where = list(client.who_has(solved).get(solved.key, ()))
    kw: dict[str, Any] = {"pure": False}
    if where:
        kw.update(workers=where, allow_other_workers=True)
    outputs = client.submit(fsm_piece, solved, plan, state, **kw)
    done = client.submit(finish[0], solved, outputs, plan, *finish[1], **kw)
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
