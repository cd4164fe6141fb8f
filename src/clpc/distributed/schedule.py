"""How a long record's pieces are given to a Dask cluster (see :mod:`.long_record`).

:func:`run_pieces` gives each worker two solves at a time (:data:`SOLVING`: the one it
runs and the next, so it never waits for the client between pieces), the next piece to the
worker that ended one (a worker slowed by another job solves fewer). As a solve ends, the
worker tells the client the piece's few numbers (:func:`.piece_tasks.piece_info`) in a Dask
event (``Worker.log_event`` / ``Client.subscribe_topic``), because a ``piece_info`` task
would wait behind the worker's next solve; the task is still submitted, and taken when an
event is lost. The client carries the record's FSM state to each piece's start in time
order (:func:`.piece_tasks.next_state`) and sends the piece's finish, with that state, to
the worker that holds it (first in its queue). No task waits for another piece's. At most
:data:`AHEAD` pieces per worker are held, so a worker's memory is O(piece) whatever the
record's length; what the finishes return is taken in time order.
"""

from __future__ import annotations

import threading
import uuid
from collections import deque
from collections.abc import Callable
from typing import Any

import numpy as np

from clpc.distributed.cluster import require_distributed
from clpc.distributed.piece_tasks import (
    PieceInfo,
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
#: solves given to a worker at a time: the one it runs and the next, so it starts the next
#: as soon as one ends
SOLVING = 2
#: the Dask event topic (and a run's own suffix) on which workers tell a piece is solved
TOPIC = "clpc-piece-solved"


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
    local: Callable[[Piece, PieceInfo, Any, str | None], Any] | None = None,
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
    local : callable, optional
        ``local(piece, info, state, worker)``: the finish of a piece whose rows are in the
        shared trace (``info.shared``), done by the client itself in its map of it (no
        finish task); ``worker``: the address of the worker that solved it (``None``:
        unknown).

    Returns
    -------
    parts : list
        What ``finish`` returned for each piece, in time order (without ``sink``).
    peaks : ndarray, shape (2, channels)
        The maximum and the minimum of every raw channel of the record.
    """
    distributed = require_distributed()
    addresses = list(client.scheduler_info().get("workers", {})) or [None]
    n_workers = len(addresses)
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
    news = _News(f"{TOPIC}-{uuid.uuid4().hex}")
    free = deque(addresses * SOLVING)  # a worker once per solve it may be given
    solving: dict[int, tuple[Any, Any]] = {}  # piece number: (solved, info) futures
    solved: dict[int, tuple[Any, Any, Any]] = {}  # piece number: (future, PieceInfo, worker)
    finishing: deque[Any] = deque()  # in time order
    ending: list[Any] = []  # solves whose event was heard, their tasks maybe not yet ended
    state: Any = plan.initial()
    after = 0  # the piece whose finish is submitted next (the record's state is before it)
    client.subscribe_topic(news.topic, news.hear)
    try:
        while todo or solving or solved or finishing:
            while todo and free and len(solving) + len(solved) + len(finishing) < AHEAD * n_workers:
                piece, where = todo.popleft(), free.popleft()
                job = (news.topic, read(client, piece), plan, piece, shared)
                key = f"solve_piece-{uuid.uuid4().hex}"  # named as what it runs
                fut = client.submit(_solve_and_tell, *job, key=key, **_on(where))
                info = client.submit(piece_info, fut, pure=False)
                info.add_done_callback(news.wake_up)
                solving[piece.number] = (fut, info)
            for number in [k for k, (_, i) in solving.items() if k in news.heard or i.done()]:
                fut, info = solving.pop(number)
                heard = news.heard.pop(number, None)
                part, where = heard if heard is not None else (info.result(), None)
                free.append(where)  # that worker's next solve (None: any worker)
                solved[number] = (fut, part, where)
                peaks = np.stack([np.maximum(peaks[0], part.peaks[0]),
                                  np.minimum(peaks[1], part.peaks[1])])  # fmt: skip
            while after in solved:  # in time order: the record's state before each piece
                fut, part, where = solved.pop(after)
                if local is not None and part.shared:  # the rows are in the shared trace
                    finishing.append(_Done(local(pieces[after], part, state, where)))
                    ending.append(fut)  # released once its task has ended
                else:
                    finishing.append(_finish(client, fut, (plan, state, where), finish))
                    finishing[-1].add_done_callback(news.wake_up)
                state = next_state(state, part)
                after += 1
            ending = [f for f in ending if not f.done()]
            if finishing and finishing[0].done():
                take(finishing.popleft().result())
            elif solving or finishing:
                news.wait()
        distributed.wait(ending)  # every task of the record has ended
    finally:
        client.unsubscribe_topic(news.topic)
    return results, peaks


class _Done:
    """A finish done by the client: a future already done."""

    def __init__(self, value: Any) -> None:
        self.value = value

    def done(self) -> bool:
        return True

    def result(self) -> Any:
        return self.value


def _on(where: str | None) -> dict[str, Any]:
    """Submit keywords: prefer the worker ``where`` (another takes the task if it is lost)."""
    return {} if where is None else {"workers": [where], "allow_other_workers": True}


class _News:
    """What the client hears of solved pieces: the workers' events, and futures done."""

    def __init__(self, topic: str) -> None:
        self.topic = topic
        self.heard: dict[int, tuple[PieceInfo, str]] = {}  # piece number: (info, worker)
        self.event = threading.Event()

    def hear(self, event: tuple[float, dict[str, Any]]) -> None:
        """Handler of the topic's events (the client's event loop calls it)."""
        msg = event[1]
        self.heard[int(msg["piece"])] = (_unplain(msg["info"]), str(msg["worker"]))
        self.event.set()

    def wake_up(self, _: Any = None) -> None:
        """A future is done (its callback)."""
        self.event.set()

    def wait(self) -> None:
        """Until something is heard or a future is done."""
        self.event.wait()
        self.event.clear()


def _solve_and_tell(topic: str, *job: Any) -> Any:
    """:func:`.piece_tasks.solve_piece`, then tell the client the piece's few numbers at once.

    As a Dask event on ``topic`` (with this worker's address), sent as the solve ends: the
    worker's next solve may already be waiting, and the ``piece_info`` task (kept, in case
    the event is lost) runs only after it.
    """
    solved = solve_piece(*job)
    distributed = require_distributed()
    try:
        worker = distributed.get_worker()
    except ValueError:  # pragma: no cover - run outside a worker: the piece_info task tells
        return solved
    msg = {"piece": solved.piece.number, "worker": worker.address}
    worker.log_event(topic, {**msg, "info": _plain(piece_info(solved))})
    return solved


def _plain(info: PieceInfo) -> dict[str, Any]:
    """A piece's numbers as lists (an event is msgpack: float64 values round-trip exactly)."""
    theta, c, has_model = info.end
    return {
        "peaks": info.peaks.tolist(),
        "end": [theta.tolist(), c.tolist(), has_model.tolist()],
        "accepted": info.accepted.tolist(),
        "first": info.first.tolist(),
        "shared": bool(info.shared),
    }


def _unplain(msg: dict[str, Any]) -> PieceInfo:
    """:func:`_plain` undone (the same arrays, the same values)."""
    theta, c, has_model = msg["end"]
    end = (np.array(theta, dtype=np.float64), np.array(c, dtype=np.float64),
           np.array(has_model, dtype=bool))  # fmt: skip
    peaks = np.array(msg["peaks"], dtype=np.float64)
    first = np.array(msg["first"], dtype=np.int64)
    return PieceInfo(peaks, end, np.array(msg["accepted"], dtype=bool), first, msg["shared"])


def _finish(
    client: Any,
    solved: Any,
    job: tuple[RecordPlan, Any, str | None],
    finish: tuple[Callable[..., Any], tuple[Any, ...]],
) -> Any:
    """Submit a solved piece's finish on the worker that holds it, before its next solve.

    A preference: another worker takes it if that one is lost. So only the FSM state moves
    between processes.
    """
    plan, state, where = job
    if where is None:
        held = list(client.who_has(solved).get(solved.key, ()))
        where = held[0] if held else None
    kw = {"pure": False, "priority": 1, **_on(where)}
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
