"""The arrays of a ``.npz`` archive read without loading them: headers first, rows in chunks.

A ``.npz`` file is a zip archive of ``.npy`` files, often compressed: its size on disk says
nothing about its size in memory (4.6 MB of zeros can hold 2e8 values, 1.6 GB as float64).
:func:`npz_members` reads only each member's header (dtype and shape); :func:`member_rows`
then decompresses one block of rows at a time, so memory stays bounded by the chunk. A
2-D member stored in Fortran order has its rows scattered over the member: it is loaded
whole, and only when it fits :func:`max_load_bytes`. Before any data is read, the members'
sizes (from their headers and the zip directory) are checked against the read limit
(``CLPC_MAX_READ_BYTES``, :mod:`clpc.io.budget`) and their columns against the column limit.
"""

from __future__ import annotations

import math
import os
import zipfile
import zlib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO

import numpy as np

from clpc.data import DataError
from clpc.io.budget import READ_ENV, check_columns, limit, read_too_much

__all__ = ["LIMIT_ENV", "Member", "check_load", "max_load_bytes", "member_rows", "npz_members"]

#: environment variable overriding the default of :func:`max_load_bytes` (a number of bytes)
LIMIT_ENV = "CLPC_MAX_LOAD_BYTES"
_DEFAULT_LIMIT = 1 << 30  # 1 GiB: 1.3e8 float64 values


def max_load_bytes() -> int:
    """The most a reader loads into memory at once: ``$CLPC_MAX_LOAD_BYTES`` or 1 GiB.

    Raises
    ------
    DataError
        ``CLPC_MAX_LOAD_BYTES`` is set but is not a positive integer.
    """
    text = os.environ.get(LIMIT_ENV, "").strip()
    if not text:
        return _DEFAULT_LIMIT
    if not text.isdigit() or int(text) <= 0:
        raise DataError(f"{LIMIT_ENV} must be a positive number of bytes; got {text!r}.")
    return int(text)


def check_load(n_values: int, source: str, what: str) -> None:
    """Refuse to load ``n_values`` float64 values above :func:`max_load_bytes`.

    Parameters
    ----------
    n_values : int
        Values that would be held in memory at once (as float64).
    source : str
        The file, for the message.
    what : str
        What would be loaded, e.g. ``"the selected columns"``.
    """
    limit = max_load_bytes()
    need = 8 * n_values
    if need > limit:
        raise DataError(
            f"{source}: {what} hold {n_values:,} values ({need / 2**30:.2f} GiB as float64), "
            f"more than the load limit of {limit / 2**30:.2f} GiB; read the file in chunks "
            f"(clpc.io.iter_table_chunks, clpc track), select fewer columns, or raise the "
            f"limit with the environment variable {LIMIT_ENV}=<bytes>."
        )


@dataclass(frozen=True)
class Member:
    """One array of an archive, as its ``.npy`` header describes it."""

    key: str
    zip_name: str
    dtype: np.dtype
    shape: tuple[int, ...]
    fortran: bool

    @property
    def size(self) -> int:
        """Number of values."""
        return math.prod(self.shape)


def _header(fh: IO[bytes]) -> tuple[tuple[int, ...], bool, np.dtype]:
    version = np.lib.format.read_magic(fh)
    if version == (1, 0):
        return np.lib.format.read_array_header_1_0(fh)
    return np.lib.format.read_array_header_2_0(fh)


def npz_members(path: Path, source: str) -> list[Member]:
    """The arrays of a ``.npz`` file (key, dtype, shape), without reading their data.

    Raises
    ------
    DataError
        Not a zip archive, a member that is not a ``.npy`` array, an object (pickled)
        array, members that decompress beyond the read limit or hold more columns than
        the column limit (:mod:`clpc.io.budget`).
    """
    out = []
    budget = limit(READ_ENV)
    try:
        with zipfile.ZipFile(path) as zf:
            infos = zf.infolist()
            if sum(info.file_size for info in infos) > budget:
                raise read_too_much(source, budget)
            for name in (info.filename for info in infos):
                with zf.open(name) as fh:
                    shape, fortran, dtype = _header(fh)
                if dtype.hasobject:
                    raise DataError(
                        f"{source} array {name!r} holds Python objects (pickled); save numeric "
                        "arrays with numpy.savez."
                    )
                key = name[:-4] if name.endswith(".npy") else name
                out.append(Member(key, name, dtype, tuple(shape), bool(fortran)))
    except (ValueError, OSError, EOFError, zipfile.BadZipFile, zlib.error) as exc:
        if isinstance(exc, DataError):
            raise
        raise DataError(f"{source} is not a valid .npz file ({exc}).") from None
    if sum(m.size * m.dtype.itemsize for m in out) > budget:
        raise read_too_much(source, budget)
    check_columns(max([len(out), *(math.prod(m.shape[1:]) for m in out)]), source)
    return out


def load_member(path: Path, member: Member, source: str) -> np.ndarray:
    """The whole array of a (small) member, after :func:`check_load`."""
    check_load(member.size, source, f"array {member.key!r}")
    with zipfile.ZipFile(path) as zf, zf.open(member.zip_name) as fh:
        return np.lib.format.read_array(fh, allow_pickle=False)


def _read_exact(fh: IO[bytes], n: int, source: str, key: str) -> bytes:
    data = fh.read(n)
    if len(data) != n:
        raise DataError(f"{source} array {key!r} is truncated; save the file again.")
    return data


def member_rows(
    path: Path, members: list[Member], chunk_rows: int, source: str
) -> Iterator[list[np.ndarray]]:
    """Blocks of ``chunk_rows`` rows of equally long members (1-D, or one C-order 2-D).

    Yields
    ------
    list of ndarray
        One array per member: shape (rows,) for 1-D members, (rows, n_columns) for 2-D.
    """
    n_rows = members[0].shape[0]
    try:
        with zipfile.ZipFile(path) as zf:
            handles = [zf.open(m.zip_name) for m in members]
            try:
                for fh in handles:
                    _header(fh)
                for start in range(0, n_rows, chunk_rows):
                    rows = min(chunk_rows, n_rows - start)
                    block = []
                    for m, fh in zip(members, handles, strict=True):
                        width = math.prod(m.shape[1:])
                        raw = _read_exact(fh, rows * width * m.dtype.itemsize, source, m.key)
                        arr = np.frombuffer(raw, dtype=m.dtype)
                        block.append(arr.reshape((rows, *m.shape[1:])))
                    yield block
            finally:
                for fh in handles:
                    fh.close()
    except (OSError, EOFError, zipfile.BadZipFile, zlib.error) as exc:
        raise DataError(f"{source} is not a valid .npz file ({exc}).") from None
