"""A long record's trace in the memory of one machine, its rows written in place by the workers.

:func:`clpc.distributed.run_long` returns the record's whole trace, about 300 bytes per
update, as :meth:`clpc.CLPC.run` does. Sent piece by piece, those rows cost the workers
their sending and the client receiving them, decoding them and copying them into the
record's trace, on the cores the workers need. So the client lays the record's trace
arrays out in one file of ``/dev/shm`` (a tmpfs: memory, not disk) and maps it
(:meth:`SharedRows.create`); a worker that sees the file, which only a process of the same
machine can, maps it too (:meth:`SharedRows.open`), reserves its piece's rows with
``posix_fallocate`` (so that a full tmpfs is refused there, not met by a write that would
kill the process; the workers do it in parallel, the client does not zero the whole file
first) and its kernel writes the piece's rows straight into it. The file is removed when
the record is done; the client's map, and so its trace, stays until the trace is let go.

Two extra arrays lie beside the trace's (``extra`` of :meth:`SharedRows.create`: for
``run_long``, each window's own ``c`` and its level): with them in the file, the client
itself settles a piece's first updates in its map once it knows the record's state before
the piece (:func:`clpc.distributed.piece_tasks.settle`), so nothing of the piece but its
few numbers is sent, and no finish task is needed.

A worker that does not see the file (another machine, or a container with its own
``/dev/shm``) solves into its own arrays and sends the rows, as it would without this.
So does a second run of a piece (Dask re-runs a solve whose worker died, perhaps after the
client heard from the first run and settled its rows): the first writer of a piece claims
its rows with a file created exclusively beside the trace (:meth:`SharedRows.open`), and
any later run of that piece solves into its own arrays, so rows the client may have
settled are never written again.
"""

from __future__ import annotations

import math
import mmap
import os
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from clpc.appraiser.trace import Trace

__all__ = ["SHM", "Mapped", "SharedRows"]

#: the tmpfs the shared trace is made in
SHM = Path("/dev/shm")
#: every array starts at a multiple of this many bytes
ALIGN = 64

#: one array of the trace: (shape, dtype string, byte offset in the file)
Slot = tuple[tuple[int, ...], str, int]


class _Views:
    """``empty(shape, dtype)`` for :meth:`Trace.allocate`: consecutive aligned views of a map.

    Without a map it only lays the arrays out (returning empty arrays); with ``expect`` it
    checks that the arrays asked for are those laid out.
    """

    def __init__(self, buf: mmap.mmap | None = None, expect: tuple[Slot, ...] = ()) -> None:
        self.buf, self.expect = buf, expect
        self.slots: list[Slot] = []
        self.size = 0

    def __call__(self, shape: tuple[int, ...], dtype: Any) -> np.ndarray:
        kind = np.dtype(dtype)
        count = math.prod(shape)
        slot = (tuple(int(n) for n in shape), kind.str, self.size)
        if self.expect and self.expect[len(self.slots)] != slot:
            raise ValueError(
                f"the shared trace's array {len(self.slots)} is {self.expect[len(self.slots)]}, "
                f"not {slot}: a trace of another appraiser."
            )
        self.slots.append(slot)
        self.size += -(-count * kind.itemsize // ALIGN) * ALIGN
        if self.buf is None:
            return np.empty((0, *shape[1:]), kind)
        return np.frombuffer(self.buf, kind, count=count, offset=slot[2]).reshape(shape)


class Mapped(NamedTuple):
    """A process's map of the shared file: the trace and the extra per-update arrays."""

    trace: Trace
    extra: list[np.ndarray]  #: (rows, ...) float64 each, as laid out by ``extra`` of create
    buf: mmap.mmap  #: the map itself


@dataclass(frozen=True)
class SharedRows:
    """Where a record's trace lies in a shared file (small and picklable).

    Parameters
    ----------
    path : str
        The file in :data:`SHM`.
    rows : int
        Updates of the record.
    slots : tuple
        ``(shape, dtype, offset)`` of every array, in the order :meth:`Trace.allocate`
        makes them, then the extra arrays.
    size : int
        Bytes of the file.
    """

    path: str
    rows: int
    slots: tuple[Slot, ...]
    size: int

    @classmethod
    def create(
        cls,
        like: Trace,
        rows: int,
        extra: tuple[tuple[int, ...], ...] = (),
        folder: Path | None = None,
    ) -> tuple[SharedRows, Mapped] | None:
        """Make the shared file of a trace of ``rows`` updates shaped like ``like``, and map it.

        ``extra``: the row shapes of float64 arrays laid out after the trace's (per-update
        numbers that are not trace columns). ``folder``: where (default :data:`SHM`). The
        file is sized but not filled: each writer reserves the rows it writes
        (:meth:`reserve`), in parallel.

        Returns
        -------
        (SharedRows, Mapped) or None
            The layout for the workers and the client's map of the file; ``None`` when
            ``folder`` is missing or has not twice the room (the rows are then sent).
        """
        plan = _Views()
        Trace.allocate(like, rows, empty=plan)
        for shape in extra:
            plan((rows, *shape), np.float64)
        where = SHM if folder is None else folder
        try:
            room = os.statvfs(where)
            if room.f_bavail * room.f_frsize < 2 * plan.size:
                return None
            path = where / f"clpc-trace-{uuid.uuid4().hex}"
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o600)
        except OSError:
            return None
        try:
            os.ftruncate(fd, plan.size)
            buf = mmap.mmap(fd, plan.size)
        except OSError:
            path.unlink(missing_ok=True)
            return None
        finally:
            os.close(fd)
        shared = cls(str(path), rows, tuple(plan.slots), plan.size)
        return shared, shared._mapped(like, buf)

    def _mapped(self, like: Trace, buf: mmap.mmap) -> Mapped:
        views = _Views(buf, self.slots)
        trace = Trace.allocate(like, self.rows, empty=views)
        extra = [views(shape, kind) for shape, kind, _ in self.slots[len(views.slots) :]]
        return Mapped(trace, extra, buf)

    def open(self, like: Trace, rows: tuple[int, int]) -> Mapped | None:
        """The shared file mapped in this process, rows ``rows`` reserved.

        ``like``: a trace of the record's appraiser; ``rows = (start, stop)``: the rows
        this process will write. The arrays are views of a map of the file, kept as long
        as they are. ``None``: this process does not see the file, or there is no room for
        the rows (a write to an unreserved page of a full tmpfs would kill the process),
        or the rows were claimed before: another run of the same piece (a re-run of its
        task) has written them, and the client may have settled them since.
        """
        try:
            fd = os.open(self.path, os.O_RDWR)
        except OSError:
            return None
        try:
            if os.fstat(fd).st_size != self.size or not self._claimed(fd, rows[0]):
                return None
            if not self._reserve(fd, rows):
                return None
            buf = mmap.mmap(fd, self.size)
        finally:
            os.close(fd)
        return self._mapped(like, buf)

    def read(self, like: Trace) -> Mapped | None:
        """The shared file mapped in this process for reading (no claim, nothing reserved).

        ``like``: a trace of the record's appraiser. The arrays are read-only views of a
        map of the file, kept as long as they are. ``None``: this process does not see the
        file (another machine, or another ``/dev/shm``).
        """
        try:
            fd = os.open(self.path, os.O_RDONLY)
        except OSError:
            return None
        try:
            if os.fstat(fd).st_size != self.size:
                return None
            buf = mmap.mmap(fd, self.size, prot=mmap.PROT_READ)
        finally:
            os.close(fd)
        return self._mapped(like, buf)

    def reserve(self, rows: tuple[int, int]) -> None:
        """Reserve rows ``rows = (start, stop)`` for writing through an existing map.

        Raises
        ------
        OSError
            No room left for them (the message names the file and the bytes).
        """
        fd = os.open(self.path, os.O_RDWR)
        try:
            if not self._reserve(fd, rows):
                raise OSError(
                    f"{self.path}: no room in its tmpfs for rows {rows[0]}-{rows[1]} of the "
                    "trace; free memory in /dev/shm (or run without the shared trace)."
                )
        finally:
            os.close(fd)

    def release(self, mapped: Mapped, rows: tuple[int, int]) -> None:
        """Give the memory of rows ``rows = (start, stop)`` back (their values become 0).

        Every page of the file that lies within those rows of an array is removed from the
        tmpfs (``madvise(MADV_REMOVE)`` through ``mapped``, this process's map); pages
        shared with the rows before or after are kept. Call it once nobody reads the rows
        any more (e.g. they are written elsewhere).
        """
        page = mmap.PAGESIZE
        for lo, hi in self._spans(rows):
            first, last = -(-lo // page) * page, hi // page * page
            if last > first:
                mapped.buf.madvise(mmap.MADV_REMOVE, first, last - first)

    def _spans(self, rows: tuple[int, int]) -> list[tuple[int, int]]:
        """The byte ranges ``[lo, hi)`` of rows ``rows`` in every array of the file."""
        out = []
        for shape, kind, offset in self.slots:
            per_row = math.prod(shape[1:]) * np.dtype(kind).itemsize
            out.append((offset + rows[0] * per_row, offset + rows[1] * per_row))
        return out

    def _reserve(self, fd: int, rows: tuple[int, int]) -> bool:
        """Allocate the pages of rows ``rows`` of every array (False: no room)."""
        try:
            for lo, hi in self._spans(rows):
                if hi > lo:
                    os.posix_fallocate(fd, lo, hi - lo)
        except OSError:
            return False
        return True

    def _claimed(self, fd: int, row: int) -> bool:
        """Claim the rows that start at ``row`` (a file created exclusively); False: taken.

        ``fd``: this process's descriptor of the file. A claim made after the file was
        removed (a late re-run of a piece) is taken back: :meth:`remove` unlinks the file
        before its claims, so no claim outlives the record.
        """
        name = f"{self.path}.rows-{row}"
        try:
            os.close(os.open(name, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
        except OSError:
            return False
        if os.fstat(fd).st_nlink == 0:  # the record is done: nothing to write into
            Path(name).unlink(missing_ok=True)
            return False
        return True

    def remove(self) -> None:
        """Remove the file and its claims (the maps stay valid until their arrays are let go)."""
        path = Path(self.path)
        path.unlink(missing_ok=True)  # first: a claim made from now on is taken back
        for claim in path.parent.glob(f"{path.name}.rows-*"):
            claim.unlink(missing_ok=True)
