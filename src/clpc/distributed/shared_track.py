""":func:`clpc.distributed.track_long`'s pieces in the record's trace in shared memory.

On the client's machine the workers solve their pieces straight into the record's trace in
a ``/dev/shm`` file (:mod:`.shared_rows`, as :func:`clpc.distributed.run_long` does). For
each such piece the client, once it knows the record's state before the piece:

1. settles the piece's first updates in its own map of the file (no rows are sent, no
   finish task: :func:`.piece_tasks.settle`);
2. gives a worker the writing of the piece's Parquet file, which that worker does from its
   own map of the file (:func:`.part_file.write_shared_piece`: only the piece's number
   goes to it); by preference the worker that solved the piece, ahead of its next solve;
3. takes what the summary and the report need straight from its map
   (:func:`.part_file.written`: the summary's arrays are scanned in place, the figures'
   updates and the last ones copied).

A piece solved by a worker that does not see the file (or a second run of a piece, see
:mod:`.shared_rows`) is settled and written by its worker, and what the report needs sent
back (:func:`.part_file.write_piece`), as without the shared trace. The client removes each
piece's rows from the file's memory once its Parquet file is written
(:meth:`.shared_rows.SharedRows.release`), so the file holds the pieces in flight, not the
record.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from clpc.distributed.part_file import WrittenPiece, write_shared_piece, written
from clpc.distributed.piece_tasks import FsmTuple, PieceInfo, RecordPlan, SolvedPiece, settle
from clpc.distributed.pieces import Piece
from clpc.distributed.shared_rows import Mapped, SharedRows

__all__ = ["SharedPieces"]


class SharedPieces:
    """The client's side of :func:`track_long`'s pieces in the shared trace.

    Parameters
    ----------
    client : distributed.Client
    plan : RecordPlan
    made : (SharedRows, Mapped)
        The shared file (its layout, with each window's own ``c`` as the one extra array)
        and the client's map of it (:meth:`.shared_rows.SharedRows.create`).
    folder : str
        The dataset's (staging) folder.
    keep, thin
        As for :func:`.part_file.written`.
    sink : callable
        Takes each piece's :class:`.part_file.WrittenPiece`, in time order (through
        :meth:`take`), and is done with its ``summary`` when it returns.
    """

    def __init__(
        self,
        client: Any,
        plan: RecordPlan,
        made: tuple[SharedRows, Mapped],
        folder: str,
        thinning: tuple[tuple[str, ...], tuple[int, int]],
        sink: Callable[[WrittenPiece], None],
    ) -> None:
        self.client, self.plan = client, plan
        self.shared, self.mapped = made
        self.folder, (self.keep, self.thin), self.sink = folder, thinning, sink
        self.writing: dict[int, tuple[Any, tuple[int, int]]] = {}  # piece: (write, rows)
        self.taken = 0  # pieces taken by the sink (they are numbered in time order)
        self.pieces = 0  # pieces settled and written in place

    def finish(
        self, piece: Piece, info: PieceInfo, state: FsmTuple, where: str | None
    ) -> WrittenPiece:
        """Settle a piece in place, have a worker write its file; what the report needs.

        ``state``: the record's FSM state before the piece; ``where``: the worker that
        solved it (``None``: unknown).
        """
        lo, hi = piece.j_lo - 1, piece.j_hi
        rows = self.mapped.trace.view(lo, hi)
        c = self.mapped.extra[0][lo:hi]
        settle(SolvedPiece(piece, rows, c, info.first, info.peaks, True), self.plan, state)
        kw: dict[str, Any] = {"pure": False, "priority": 1}
        if where is not None:  # a preference: another worker takes it if that one is lost
            kw.update(workers=[where], allow_other_workers=True)
        job = (self.shared, self.plan, piece, self.folder)
        self.writing[piece.number] = (self.client.submit(write_shared_piece, *job, **kw), (lo, hi))
        self.pieces += 1
        return written(rows, piece, self.keep, self.thin)

    def take(self, part: WrittenPiece) -> None:
        """The sink of :func:`.schedule.run_pieces`: ``sink(part)``, then free what is done."""
        self.sink(part)
        self.taken += 1
        self._release(wait=False)

    def wait(self) -> None:
        """Until every piece's file is written (a failed write raises its error)."""
        self._release(wait=True)

    def _release(self, wait: bool) -> None:
        """Free the file's memory of the pieces taken whose Parquet files are written."""
        for number, (write, rows) in list(self.writing.items()):
            if number < self.taken and (wait or write.done()):
                write.result()  # waits when asked to; a failed write raises here
                del self.writing[number]
                self.shared.release(self.mapped, rows)
        if wait and self.writing:  # pragma: no cover - every piece is taken before wait
            raise RuntimeError(f"pieces {sorted(self.writing)} were written but never taken")
