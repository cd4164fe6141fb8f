"""An output folder that holds one complete run's files, or the previous run's untouched.

:class:`OutputFolder` is how ``clpc track --out DIR`` and ``clpc identify --report DIR``
write their folder:

1. **Lock.** ``DIR/.clpc.lock`` is locked (``fcntl.flock``; the lock ends with the process,
   even on ``kill -9``). A second run into the same folder is refused with one line.
2. **Stage.** The run writes into a fresh hidden folder ``DIR/.clpc-run-<token>/``;
   ``DIR`` keeps the previous run's files meanwhile. Leftovers of killed runs (staging
   folders, temporary files) are removed first.
3. **Commit.** When every file is complete: the previous run's record
   (``DIR/.clpc-run.json``) and report are removed first, then its other files (stale
   figures), then the new files are renamed in, the report last, and the record written.
   A folder whose record exists holds exactly the files it lists, all complete.

Any error (or a kill) before the commit leaves ``DIR`` as it was. No file is written
through a symbolic link: a link at a target name is refused with its name.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from pathlib import Path
from types import TracebackType

from clpc.core.atomic import TMP_PREFIX, OutputError, check_not_link, fsync_folder, write_file

try:  # POSIX
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

__all__ = ["LOCK_NAME", "RECORD_NAME", "OutputFolder"]

LOCK_NAME = ".clpc.lock"
RECORD_NAME = ".clpc-run.json"
_STAGE_PREFIX = ".clpc-run-"
#: what earlier clpc versions wrote into an output folder: removed when there is no record
#: but a report or a trace shows that clpc wrote the folder
_LEGACY = (
    "report.html",
    "trace.csv",
    "trace.parquet",
    "trace.png",
    "fit.png",
    "data.png",
    "step.png",
    "bode.png",
    "pz.png",
    "residuals.png",
)


class OutputFolder:
    """A locked output folder written as one transaction (see the module's description).

    Parameters
    ----------
    folder : str or os.PathLike
        The output folder (created with its parents).
    option : str
        The option that named it, for messages (e.g. ``"--out"``).
    marker : str
        The file that says a run is complete (moved in last, removed first).

    Examples
    --------
    >>> with OutputFolder("run1") as out:  # doctest: +SKIP
    ...     (out.staging / "trace.csv").write_text("...")
    ...     out.commit()
    """

    def __init__(
        self, folder: str | os.PathLike[str], option: str = "--out", marker: str = "report.html"
    ) -> None:
        self.folder = Path(os.fspath(folder))
        self.option = option
        self.marker = marker
        self._lock_fd: int | None = None
        self._staging: Path | None = None
        self.files: list[Path] = []

    @property
    def staging(self) -> Path:
        """Where the run writes its files (a hidden folder inside :attr:`folder`)."""
        if self._staging is None:
            raise RuntimeError("the output folder is not open; use it in a `with` block.")
        return self._staging

    def final(self, path: str | os.PathLike[str]) -> Path:
        """The place in :attr:`folder` of a path in :attr:`staging` (others unchanged).

        Parameters
        ----------
        path : str or os.PathLike
            A file.

        Returns
        -------
        Path
        """
        p = Path(os.fspath(path))
        if self._staging is not None and p.parent == self._staging:
            return self.folder / p.name
        return p

    def __enter__(self) -> OutputFolder:
        where = self.folder
        try:
            where.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OutputError(where, exc, f"choose another folder with {self.option}") from exc
        if not where.is_dir():
            raise OutputError(where, "it is not a folder", f"choose a folder with {self.option}")
        self._lock()
        try:
            self._remove_leftovers()
            for name in self._previous():
                check_not_link(where / name)
            self._staging = Path(tempfile.mkdtemp(prefix=_STAGE_PREFIX, dir=where))
        except BaseException as exc:
            self._unlock()
            if isinstance(exc, OSError) and not isinstance(exc, OutputError):
                raise OutputError(where, exc, f"choose another folder with {self.option}") from exc
            raise
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        moved: OutputError | None = None
        if isinstance(exc, OutputError):  # named by its final place, not the staged one
            moved = exc.moved(self.final(exc.path))
        elif isinstance(exc, OSError) and isinstance(exc.filename, str):
            if Path(exc.filename).parent == self._staging:
                moved = OutputError(self.final(exc.filename), exc)
        try:
            if self._staging is not None:
                shutil.rmtree(self._staging, ignore_errors=True)
                self._staging = None
        finally:
            self._unlock()
        if moved is not None:
            raise moved from exc

    def commit(self) -> list[Path]:
        """Move the staged files into the folder, replacing the previous run's files.

        Returns
        -------
        list of Path
            The files now in the folder (the marker last when there is one).

        Raises
        ------
        OutputError
            A target name is a symbolic link, or a rename failed.
        """
        staged = sorted(p.name for p in self.staging.iterdir())
        staged.sort(key=lambda n: n == self.marker)  # the marker last
        for name in staged:
            check_not_link(self.folder / name)
        previous = self._previous()
        for name in (RECORD_NAME, self.marker, *previous):
            if name not in staged or name in (RECORD_NAME, self.marker):
                self._remove(self.folder / name)
        fsync_folder(self.folder)
        for name in staged:
            try:
                os.replace(self.staging / name, self.folder / name)
            except OSError as exc:
                raise OutputError(self.folder / name, exc) from exc
        fsync_folder(self.folder)
        write_file(self.folder / RECORD_NAME, json.dumps({"complete": True, "files": staged}))
        self.files = [self.folder / n for n in staged]
        return self.files

    def _previous(self) -> list[str]:
        """The previous run's files (from its record; the names clpc writes without one)."""
        record = self.folder / RECORD_NAME
        with contextlib.suppress(OSError, ValueError, TypeError, AttributeError):
            if record.is_file() and not record.is_symlink():
                files = json.loads(record.read_text(encoding="utf-8")).get("files", [])
                return [
                    f
                    for f in files
                    if isinstance(f, str) and f == Path(f).name and not f.startswith(".clpc")
                ]
        looks_like_clpc = any((self.folder / n).is_file() for n in _LEGACY[:3])
        return list(_LEGACY) if looks_like_clpc else []

    def _remove(self, path: Path) -> None:
        """Remove a file (or a link, never its target); a folder of that name is kept."""
        if path.is_symlink() or path.is_file():
            try:
                path.unlink()
            except FileNotFoundError:
                pass
            except OSError as exc:
                raise OutputError(path, exc, "remove it by hand or choose another folder") from exc

    def _remove_leftovers(self) -> None:
        """Staging folders and temporary files of runs that were killed (the lock is ours)."""
        for entry in self.folder.iterdir():
            if entry.is_symlink():
                continue
            if entry.name.startswith(_STAGE_PREFIX) and entry.is_dir():
                shutil.rmtree(entry, ignore_errors=True)
            elif entry.name.startswith(TMP_PREFIX) and entry.is_file():
                with contextlib.suppress(OSError):
                    entry.unlink()

    def _lock(self) -> None:
        path = self.folder / LOCK_NAME
        flags = os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0)
        try:
            fd = os.open(path, flags, 0o666)
        except OSError as exc:
            raise OutputError(path, exc, f"choose another folder with {self.option}") from exc
        if fcntl is not None:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                os.close(fd)
                raise OutputError(
                    self.folder,
                    f"another clpc run is writing into this folder (it holds '{path}')",
                    f"wait for it to finish or choose another folder with {self.option}",
                ) from None
        self._lock_fd = fd

    def _unlock(self) -> None:
        fd, self._lock_fd = self._lock_fd, None
        if fd is not None:
            os.close(fd)  # closing the descriptor releases the flock
