"""How a long record's pieces are given to a Dask cluster (see :mod:`.long_record`).

:func:`run_pieces` keeps one piece's solve (:func:`.piece_tasks.solve_piece`) per worker
in flight, so that a worker's next task after a solve is that piece's few numbers
(:func:`.piece_tasks.piece_info`), not another solve that would hold them back until it
ends, and a worker that is free takes the next piece (a worker slowed by another job solves
fewer). As the pieces' numbers arrive, the client carries the record's FSM state to each
piece's start in time order (:func:`.piece_tasks.next_state`) and sends the piece's finish,
with that state, to the worker that holds it. No task waits for another piece's. At most
:data:`AHEAD` pieces per worker are held, so a worker's memory is O(piece) whatever the
record's length; what the finishes return is taken in time order.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from typing import Any

import numpy as np

from clpc.distributed.cluster import require_distributed
from clpc.distributed.piece_tasks import (
    RecordPlan,
    finish_piece,
    next_state,
    piece_info,
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

#: most decimated samples per piece by default (about 1 s of one core's solving; a
#: worker holds up to AHEAD of them: ~60 MB each with one input and one output)
PIECE_SAMPLES = 1 << 21
#: pieces per worker the default piece size aims at: a few, so that a worker slowed by
#: another job is helped by the others at the end
PIECES_PER_WORKER = 3
#: fewest decimated samples per piece by default, in windows (the overlap read twice, at
#: most ``W + max_lag``, stays below 2 % of a piece)
MIN_PIECE_WINDOWS = 64
#: pieces in flight per worker (submitted, not yet taken by the client)
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
    shared: Any = None,
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
        ``(function, args)``: the last task of a piece, ``function(solved, plan, state,
        *args)`` (default :func:`.piece_tasks.finish_piece`: the piece's trace).
    sink : callable, optional
        Called with what ``finish`` returned for each piece, in time order, as it arrives
        (then not kept: ``parts`` is empty).
    shared : SharedRows, optional
        The record's trace in shared memory, for the solves
        (:func:`.piece_tasks.solve_piece`).

    Returns
    -------
    parts : list
        What ``finish`` returned for each piece, in time order (without ``sink``).
    peaks : ndarray, shape (2, channels)
        The maximum and the minimum of every raw channel of the record.
    """
    distributed = require_distributed()
    n_workers = max(1, len(client.scheduler_info().get("workers", {})))
    size = piece_samples or default_piece_samples(plan, n_workers)
    pieces = plan.layout.pieces(plan.n_raw, size)
    if pieces:  # the last piece reads to the end (the whole record is checked)
        last = pieces[-1]
        pieces[-1] = last._replace(raw=(last.raw[0], plan.n_raw))
    read = _reader(record)
    peaks = np.array([[-np.inf], [np.inf]]) * np.ones(sum(plan.channels))
    results: list[Any] = []
    take = results.append if sink is None else sink
    todo = deque(pieces)
    solving: dict[int, tuple[Any, Any]] = {}  # piece number: (solved, info) futures
    solved: dict[int, tuple[Any, Any]] = {}  # piece number: (solved future, PieceInfo)
    finishing: deque[Any] = deque()  # in time order
    state: Any = plan.initial()
    after = 0  # the piece whose finish is submitted next (the record's state is before it)
    while todo or solving or solved or finishing:
        # one solve per worker at a time: the worker's next task after a solve is its
        # piece_info (not another solve), and a free worker takes the next piece; at most
        # AHEAD pieces per worker held
        while (
            todo
            and len(solving) < n_workers
            and len(solving) + len(solved) + len(finishing) < AHEAD * n_workers
        ):
            piece = todo.popleft()
            job = (read(client, piece), plan, piece, shared)
            fut = client.submit(solve_piece, *job, pure=False)
            solving[piece.number] = (fut, client.submit(piece_info, fut, pure=False))
        for number in [k for k, (_, info) in solving.items() if info.done()]:
            fut, info = solving.pop(number)
            part = info.result()  # raises the worker's error (e.g. a sample not finite)
            solved[number] = (fut, part)
            peaks = np.stack([np.maximum(peaks[0], part.peaks[0]),
                              np.minimum(peaks[1], part.peaks[1])])  # fmt: skip
        while after in solved:  # in time order: the record's state before each piece
            fut, part = solved.pop(after)
            finishing.append(_finish(client, fut, (plan, state), finish))
            state = next_state(state, part)
            after += 1
        if finishing and finishing[0].done():
            take(finishing.popleft().result())
        elif solving or finishing:
            waiting = [info for _, info in solving.values()]
            waiting += [finishing[0]] if finishing else []
            distributed.wait(waiting, return_when="FIRST_COMPLETED")
    return results, peaks


def _finish(
    client: Any,
    solved: Any,
    job: tuple[RecordPlan, Any],
    finish: tuple[Callable[..., Any], tuple[Any, ...]],
) -> Any:
    """Submit a solved piece's finish on the worker that holds it.

    A preference: another worker takes it if that one is lost. So only the FSM state moves
    between processes.
    """
    plan, state = job
    where = list(client.who_has(solved).get(solved.key, ()))
    kw: dict[str, Any] = {"pure": False}
    if where:
        kw.update(workers=where, allow_other_workers=True)
    return client.submit(finish[0], solved, plan, state, *finish[1], **kw)


def default_piece_samples(plan: RecordPlan, n_workers: int) -> int:
    """Decimated samples per piece by default.

    :data:`PIECES_PER_WORKER` pieces per worker (or more, of at most :data:`PIECE_SAMPLES`
    samples), of equal numbers of updates; at least :data:`MIN_PIECE_WINDOWS` windows.
    """
    lay = plan.layout
    updates = lay.updates(plan.n_raw)
    count = max(PIECES_PER_WORKER * n_workers, -(-updates * lay.cluster // PIECE_SAMPLES))
    per = -(-updates // count)
    return max(per * lay.cluster, MIN_PIECE_WINDOWS * lay.window)
