"""The readers' budget: how much a data file may decompress to, how long a line, how many columns.

A compressed file says nothing about its size once decompressed (10 MB of zeros fit in 10 kB
of gzip), and one line of a text file can be as long as the file. Every reader stops at the
first limit it meets with a one-line :class:`~clpc.data.DataError` naming the file, the limit
and the environment variable that raises it:

=========================  =======================  ==========================================
limit                      default                  environment variable
=========================  =======================  ==========================================
decompressed size          2 GiB                    ``CLPC_MAX_READ_BYTES`` (bytes)
                                                    (``.gz`` text, ``.npz`` members)
length of one text line    4 MiB                    ``CLPC_MAX_LINE_BYTES`` (bytes)
columns of a file          10,000                   ``CLPC_MAX_COLUMNS``
values held at once        1 GiB as float64         ``CLPC_MAX_LOAD_BYTES`` (bytes;
                                                    :func:`clpc.io.npz_members.max_load_bytes`)
=========================  =======================  ==========================================

The defaults hold any real log (a 1 kHz, 100-channel record of a day is about 2e8 text bytes
per hour). A variable is read when a file is opened, so it can be set for one run:
``CLPC_MAX_READ_BYTES=8589934592 clpc identify big.csv.gz ...``. Gzip is decompressed as a
stream, block by block, and the count is checked as it goes: a bomb is refused after the
limit's worth of output, never decompressed whole.
"""

from __future__ import annotations

import io
import os
from typing import Any

from clpc.data import DataError

__all__ = [
    "COLUMNS_ENV",
    "LINE_ENV",
    "MAX_COLUMNS",
    "MAX_LINE_BYTES",
    "MAX_READ_BYTES",
    "READ_ENV",
    "CountedReader",
    "check_columns",
    "limit",
    "line_too_long",
    "read_too_much",
    "stream_too_long",
]

#: default largest decompressed size of a ``.gz`` text file or of a ``.npz`` archive's members
MAX_READ_BYTES = 2 << 30
#: default largest length of one line of a text file (bytes)
MAX_LINE_BYTES = 4 << 20
#: default largest number of columns of a data file
MAX_COLUMNS = 10_000
#: environment variables overriding the defaults above
READ_ENV = "CLPC_MAX_READ_BYTES"
LINE_ENV = "CLPC_MAX_LINE_BYTES"
COLUMNS_ENV = "CLPC_MAX_COLUMNS"
_DEFAULTS = {READ_ENV: MAX_READ_BYTES, LINE_ENV: MAX_LINE_BYTES, COLUMNS_ENV: MAX_COLUMNS}


def limit(env: str) -> int:
    """The limit named by ``env``: its environment variable if set, else its default.

    Parameters
    ----------
    env : str
        :data:`READ_ENV`, :data:`LINE_ENV` or :data:`COLUMNS_ENV`.

    Raises
    ------
    DataError
        The variable is set but is not a positive integer.
    """
    text = os.environ.get(env, "").strip()
    if not text:
        return _DEFAULTS[env]
    if not text.isdigit() or int(text) <= 0:
        raise DataError(f"{env} must be a positive whole number; got {text!r}.")
    return int(text)


def read_too_much(source: str, budget: int | None = None) -> DataError:
    """The error for a file beyond the decompressed-size limit (``budget``, default its env)."""
    n = limit(READ_ENV) if budget is None else budget
    return DataError(
        f"{source} decompresses to more than the read limit of {_size(n)} (a compression "
        f"bomb or a very large record?); raise it with the environment variable "
        f"{READ_ENV}=<bytes> if the file is genuine."
    )


def stream_too_long(source: str, budget: int) -> DataError:
    """The error for a pipe or device that streams more than the read limit ``budget``."""
    return DataError(
        f"{source} streams more than the read limit of {_size(budget)} (it is copied to a "
        f"temporary file to be read); raise it with the environment variable "
        f"{READ_ENV}=<bytes> if the stream is genuine."
    )


def _size(n: int) -> str:
    """``n`` bytes for a message: ``"1,000 bytes"`` or ``"2.00 GiB"``."""
    return f"{n / 2**30:.2f} GiB" if n >= 2**30 else f"{n:,} bytes"


def line_too_long(source: str, line: int | str) -> DataError:
    """The error for a text line beyond the line-length limit."""
    n = limit(LINE_ENV)
    return DataError(
        f"{source} line {line} is longer than the line limit of {_size(n)} (is it a "
        f"delimited text file with line ends?); raise it with the environment variable "
        f"{LINE_ENV}=<bytes> if the line is genuine."
    )


def check_columns(n_columns: int, source: str) -> None:
    """Refuse a file with more than :func:`limit` (``COLUMNS_ENV``) columns.

    Parameters
    ----------
    n_columns : int
        The file's number of columns.
    source : str
        The file, for the message.

    Raises
    ------
    DataError
        Too many columns; the message names the variable that raises the limit.
    """
    n = limit(COLUMNS_ENV)
    if n_columns > n:
        raise DataError(
            f"{source} has {n_columns:,} columns, more than the column limit of {n:,}; check "
            f"the delimiter (or pass delimiter=), or raise the limit with the environment "
            f"variable {COLUMNS_ENV}=<count>."
        )


class CountedReader(io.RawIOBase):
    """A binary stream (e.g. a ``gzip.GzipFile``) that refuses to give more than a budget.

    Parameters
    ----------
    raw : binary file object
        The stream read from; closed with this one.
    source : str
        The file, for the message.
    budget : int, optional
        Bytes that may be read from the start (default: :func:`limit` of ``READ_ENV``).
    """

    def __init__(self, raw: io.BufferedIOBase, source: str, budget: int | None = None) -> None:
        super().__init__()
        self._raw = raw
        self._source = source
        self._budget = limit(READ_ENV) if budget is None else budget
        self._pos = 0

    def readable(self) -> bool:
        """True: a readable stream."""
        return True

    def seekable(self) -> bool:
        """True: seeking back to the start is supported."""
        return True

    def seek(self, offset: int, whence: int = 0) -> int:
        """Seek the underlying stream (in practice back to the start)."""
        self._pos = self._raw.seek(offset, whence)
        return self._pos

    def tell(self) -> int:
        """Bytes read from the start."""
        return self._pos

    def readinto(self, buffer: Any) -> int:
        """Fill ``buffer``; raises once more than the budget has been read."""
        view = memoryview(buffer)
        room = self._budget + 1 - self._pos
        data = self._raw.read(max(min(len(view), room), 1))
        n = len(data)
        view[:n] = data
        self._pos += n
        if self._pos > self._budget:
            raise read_too_much(self._source, self._budget)
        return n

    def close(self) -> None:
        """Close the underlying stream."""
        if not self.closed:
            self._raw.close()
        super().close()
