"""The data lines of a text file, as pyarrow's CSV reader is given them.

:class:`DataLines` reads the file from its first data line (gzip decompressed) in blocks
cut at line ends. A block with blank lines or ``#`` comments (a whole line, or the end of a
line without quotes) has them taken out, and records the file line of each line taken out,
so that :meth:`DataLines.lines_of` gives every data row its line in the file; the fields of
a whitespace-delimited file are joined by tabs (pyarrow splits on one character). A block
without any of these (the usual case) is passed on as it is.
"""

from __future__ import annotations

import io
import re
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from clpc.io.budget import LINE_ENV, READ_ENV, limit, line_too_long, stream_too_long
from clpc.io.errors import show
from clpc.io.text_format import TextFormat, open_binary

__all__ = ["BLOCK_BYTES", "DataLines", "copy_stream"]

#: bytes handed to pyarrow at a time (and pyarrow's block size)
BLOCK_BYTES = 1 << 22
_BLANK_FIRST = re.compile(rb"[ \t\r]*\n")
_BLANK = re.compile(rb"\n[ \t\r]*\n")
_SPACE = np.frombuffer(b"\n\r \t", dtype=np.uint8)


class DataLines(io.RawIOBase):
    """The data lines of a text file as a binary stream, without blank and comment lines.

    Parameters
    ----------
    path : Path
        The text file (gzip-compressed when its name ends in ``.gz``).
    fmt : TextFormat
        Its layout; reading starts at ``fmt.data_line``.

    Attributes
    ----------
    dropped : list of int
        The 1-based file lines taken out so far (blank or comment lines), in order.
    """

    def __init__(self, path: Path, fmt: TextFormat) -> None:
        super().__init__()
        self._source = show(path)
        self.longest = limit(LINE_ENV)
        self._raw: Any = open_binary(path)
        head = self._raw.read(1 << 16)
        self._raw.seek(0)
        if b"\r" in head and b"\n" not in head:  # old Mac line ends: "\r" alone
            with self._raw:
                self._raw = io.BytesIO(self._raw.read().replace(b"\r", b"\n"))
        for _ in range(fmt.data_line - 1):
            self._raw.readline(self.longest + 1)
        self._whitespace = fmt.delimiter is None
        self._first = fmt.data_line == 1
        self._next_line = fmt.data_line
        self._pending = b""
        self._pos = 0
        self.dropped: list[int] = []

    def readable(self) -> bool:
        """True: a readable stream."""
        return True

    def peek(self) -> memoryview:
        """The cleaned bytes not read yet (empty at the end of the file)."""
        while self._pos >= len(self._pending) and self._fill():
            pass
        return memoryview(self._pending)[self._pos :]

    def _fill(self) -> bool:
        """Clean the next block into the pending bytes; False at the end of the file."""
        block = self._raw.read(BLOCK_BYTES)
        if not block:
            return False
        tail = self._raw.readline(self.longest + 1)
        block += tail
        if len(tail) > self.longest:
            raise line_too_long(self._source, self._next_line + block.count(b"\n"))
        self._check_lengths(block)
        if self._first:
            block, self._first = block.removeprefix(b"\xef\xbb\xbf"), False
        if not block.endswith(b"\n"):
            block += b"\n"
        self._pending, self._pos = self._clean(block), 0
        return True

    def _check_lengths(self, block: bytes) -> None:
        """Refuse a line of ``block`` longer than the line limit (``CLPC_MAX_LINE_BYTES``)."""
        if len(block) <= self.longest:
            return
        ends = np.flatnonzero(np.frombuffer(block, dtype=np.uint8) == 10)
        starts = np.concatenate([[-1], ends])
        lengths = np.diff(np.concatenate([starts, [len(block)]])) - 1
        if lengths.max() > self.longest:
            line = self._next_line + int(np.argmax(lengths > self.longest))
            raise line_too_long(self._source, line)

    def close(self) -> None:
        """Close the file."""
        self._raw.close()
        super().close()

    def read(self, size: int | None = -1) -> bytes:
        """Up to ``size`` cleaned bytes (all of them when ``size`` is negative or None)."""
        if size is None or size < 0:
            return b"".join(self.blocks())
        part = self.peek()[:size]
        self._pos += len(part)
        return bytes(part)

    def blocks(self) -> Iterator[bytes]:
        """The rest of the cleaned bytes, a block of whole lines at a time."""
        while len(part := self.peek()):
            self._pos = len(self._pending)
            yield bytes(part)

    def readinto(self, buffer: Any) -> int:
        """Fill ``buffer`` with the next cleaned bytes; 0 at the end."""
        part = self.peek()[: len(buffer)]
        buffer[: len(part)] = part
        self._pos += len(part)
        return len(part)

    def _clean(self, block: bytes) -> bytes:
        """``block`` (whole lines) without blank and comment lines, whitespace as tabs."""
        if not self._whitespace and b"#" not in block:
            # where each line starts: a blank line starts with a line end or white space
            buf = np.frombuffer(block, dtype=np.uint8)
            ends = np.flatnonzero(buf == 10)
            starts = np.concatenate([buf[:1], buf[ends[:-1] + 1]])
            if not np.isin(starts, _SPACE).any() or not (
                _BLANK_FIRST.match(block) or _BLANK.search(block)
            ):
                self._next_line += ends.size
                return block
        lines = block.split(b"\n")[:-1]
        out = []
        for k, line in enumerate(lines):
            bare = line.strip()
            if not bare or bare.startswith(b"#"):
                self.dropped.append(self._next_line + k)
                continue
            if b"#" in line and b'"' not in line:
                line = line[: line.index(b"#")]
            out.append(b"\t".join(line.split()) if self._whitespace else line)
        self._next_line += len(lines)
        return b"\n".join(out) + b"\n" if out else b""

    def lines_of(self, first_row: int, n: int, data_line: int) -> np.ndarray:
        """The 1-based file lines of data rows ``first_row .. first_row + n - 1``."""
        rows = np.arange(first_row, first_row + n, dtype=np.int64)
        if not self.dropped:
            return rows + data_line
        # the k-th line taken out comes after (dropped[k] - data_line - k) data rows
        after = np.asarray(self.dropped, dtype=np.int64) - data_line - np.arange(len(self.dropped))
        return rows + data_line + np.searchsorted(after, rows, side="right")


def copy_stream(path: Path) -> tuple[tempfile.TemporaryDirectory[str], Path]:
    """A named pipe or device copied to a temporary file, read once (nothing lost).

    The layout is sniffed from the first lines and the data read from the start again:
    a stream cannot be read twice, so it is copied to disk first (not into memory), at most
    ``CLPC_MAX_READ_BYTES`` of it (:mod:`clpc.io.budget`): an endless device
    (``/dev/zero``) or a runaway pipe is refused with a ``DataError``, the copy removed.
    """
    budget = limit(READ_ENV)
    folder = tempfile.TemporaryDirectory(prefix="clpc-")
    copy = Path(folder.name) / path.name
    copied = 0
    with open(path, "rb") as src, open(copy, "wb") as dst:
        while block := src.read(min(BLOCK_BYTES, budget + 1 - copied)):
            copied += len(block)
            if copied > budget:
                folder.cleanup()
                raise stream_too_long(f"'{path}'", budget)
            dst.write(block)
    return folder, copy
