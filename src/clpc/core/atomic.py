"""Files written whole or not at all: a temporary name beside the target, renamed at the end.

Every file clpc writes (traces, figures, reports, models, appraiser states, tables) goes
through :func:`atomic_file` or :func:`atomic_path`: the content is written to a hidden file
``.clpc-tmp-<token>-<name>`` in the target's folder, flushed to the disk (``fsync``) and
renamed over the target (``os.replace``, atomic on POSIX and Windows). A process killed
while writing leaves the previous file whole (and, at worst, a hidden temporary file that the
next :class:`clpc.core.output_folder.OutputFolder` run removes). The temporary file is
created with the mode a plain ``open`` gives (``0o666`` less the umask, read without
changing it), or the mode of the file it replaces. A target that is a symbolic link is
refused: clpc never writes through a link. A write error (a full disk, a read-only folder)
is raised as :class:`OutputError`, one line naming the file, and leaves no partial file.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

__all__ = [
    "TMP_PREFIX",
    "OutputError",
    "atomic_file",
    "atomic_path",
    "check_not_link",
    "fsync_folder",
    "write_file",
]

#: the name prefix of every temporary file (a later run may remove leftovers)
TMP_PREFIX = ".clpc-tmp-"


class OutputError(OSError):
    """A file could not be written; the message names it and says how to fix it.

    Parameters
    ----------
    path : str or os.PathLike
        The file (as the user named it, not its temporary name).
    reason : str or OSError
        What went wrong (an ``OSError`` is shown as its ``strerror``).
    hint : str
        How to fix it.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        reason: str | BaseException,
        hint: str = "free some space or choose another place to write to",
    ) -> None:
        if isinstance(reason, OSError) and reason.strerror:
            reason = reason.strerror
        self.path = Path(os.fspath(path))
        self.reason = " ".join(str(reason).split()) or type(reason).__name__
        self.hint = hint
        super().__init__(f"cannot write '{self.path}': {self.reason}; {hint}.")

    def moved(self, path: str | os.PathLike[str]) -> OutputError:
        """The same error about another path (a staged file's final name)."""
        return OutputError(path, self.reason, self.hint)


def check_not_link(path: str | os.PathLike[str]) -> None:
    """Refuse a target that is a symbolic link (clpc never writes through one).

    Parameters
    ----------
    path : str or os.PathLike
        The file about to be written.

    Raises
    ------
    OutputError
        ``path`` is a symbolic link.
    """
    if os.path.islink(path):
        raise OutputError(
            path,
            f"it is a symbolic link (to '{os.readlink(path)}')",
            "clpc does not write through links; remove the link or choose another name",
        )


def _temporary(target: Path) -> Path:
    return target.with_name(f"{TMP_PREFIX}{secrets.token_hex(4)}-{target.name}")


def _mode_of(target: Path) -> int | None:
    """The permission bits of an existing regular file at ``target`` (kept on replace)."""
    try:
        st = os.lstat(target)
    except OSError:
        return None
    return stat.S_IMODE(st.st_mode) if stat.S_ISREG(st.st_mode) else None


def fsync_folder(folder: str | os.PathLike[str]) -> None:
    """Flush a folder's entries (a rename in it) to the disk; nothing where unsupported.

    Parameters
    ----------
    folder : str or os.PathLike
        The folder.
    """
    with contextlib.suppress(OSError, AttributeError):
        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _commit(tmp: Path, target: Path, mode: int | None) -> None:
    check_not_link(target)  # planted while the file was written
    if mode is not None:
        os.chmod(tmp, mode)
    os.replace(tmp, target)
    fsync_folder(target.parent)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """A temporary path to write with any writer; renamed over ``path`` when it succeeds.

    The temporary name ends with ``path``'s own name, so writers that choose the format
    by the extension (``.csv.gz``, ``.npy``, ``.parquet``) behave the same.

    Parameters
    ----------
    path : str or os.PathLike
        The target file.

    Yields
    ------
    Path
        Where to write; it is flushed to the disk and renamed over ``path`` at the end.

    Raises
    ------
    OutputError
        ``path`` is a symbolic link, or writing failed (nothing is left behind).
    """
    target = Path(os.fspath(path))
    check_not_link(target)
    mode = _mode_of(target)
    tmp = _temporary(target)
    try:
        yield tmp
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        _commit(tmp, target, mode)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise OutputError(target, exc) from exc
        raise


@contextlib.contextmanager
def atomic_file(path: str | os.PathLike[str], binary: bool = False) -> Iterator[IO[Any]]:
    """An open file that replaces ``path`` when the ``with`` block ends without an error.

    Parameters
    ----------
    path : str or os.PathLike
        The target file.
    binary : bool
        Bytes (``True``) or UTF-8 text with Unix line ends (``False``).

    Yields
    ------
    file object
        The temporary file, created with ``O_EXCL | O_NOFOLLOW`` and mode ``0o666`` (the
        umask applies as for ``open``; an existing target's mode is kept).

    Raises
    ------
    OutputError
        ``path`` is a symbolic link, or writing failed (nothing is left behind).
    """
    target = Path(os.fspath(path))
    check_not_link(target)
    mode = _mode_of(target)
    tmp = _temporary(target)
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0)
    flags |= getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(tmp, flags, 0o666)
    except OSError as exc:
        raise OutputError(target, exc) from exc
    try:
        kwargs: dict[str, Any] = {} if binary else {"encoding": "utf-8", "newline": "\n"}
        with os.fdopen(fd, "wb" if binary else "w", **kwargs) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        _commit(tmp, target, mode)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise OutputError(target, exc) from exc
        raise


def write_file(path: str | os.PathLike[str], content: str | bytes) -> None:
    """Write ``content`` to ``path`` atomically (see :func:`atomic_file`).

    Parameters
    ----------
    path : str or os.PathLike
        The target file.
    content : str or bytes
        Text (written as UTF-8) or bytes.

    Raises
    ------
    OutputError
        ``path`` is a symbolic link, or writing failed (nothing is left behind).
    """
    with atomic_file(path, binary=isinstance(content, bytes)) as fh:
        fh.write(content)
