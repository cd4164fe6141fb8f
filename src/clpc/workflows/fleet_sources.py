"""The records of a fleet from what a user names: files, globs, folders, partitioned datasets.

* a file: one record, named by the file's name without its data extension;
* a glob (``logs/*.parquet``): every matching file, sorted;
* a folder of data files: each file with a supported extension (not recursive);
* a partitioned Parquet dataset: a folder whose sub-folders are partitions ``key=value``
  (``axis=A1/part.parquet``, as ``pandas.DataFrame.to_parquet(partition_cols=[...])``
  writes it), one record per partition, named ``key=value``; a partition must hold one data
  file;
* in Python, :class:`clpc.IOData` objects (named ``record-<k>``) or a mapping name -> file or
  IOData.

Names are unique: files of the same name in different folders are named ``parent-name``.
"""

from __future__ import annotations

import glob
import os
import re
from collections import Counter
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from clpc.data import IOData
from clpc.io.formats import SUPPORTED
from clpc.workflows.common import SettingsError
from clpc.workflows.fleet_settings import RecordSource

__all__ = ["expand_sources", "record_name"]

_PARTITION = re.compile(r"^[^=/\\]+=[^/\\]*$")
_GLOB = re.compile(r"[*?\[]")


def _is_data(path: Path) -> bool:
    return path.is_file() and path.name.lower().endswith(SUPPORTED)


def record_name(path: str | os.PathLike[str]) -> str:
    """A file's name without its data extension (``m1.csv.gz`` -> ``m1``).

    Parameters
    ----------
    path : str or os.PathLike
        A data file.

    Returns
    -------
    str
    """
    name = Path(path).name
    for ext in sorted(SUPPORTED, key=len, reverse=True):
        if name.lower().endswith(ext):
            return name[: -len(ext)] or name
    return Path(name).stem or name


def _partition_file(part: Path) -> Path:
    files = sorted(p for p in part.iterdir() if _is_data(p))
    if len(files) != 1:
        shown = ", ".join(p.name for p in files) or "none"
        raise SettingsError(
            f"partition folder '{part}' holds {len(files)} data files ({shown}); a fleet "
            "takes one record per partition: write each partition as one file."
        )
    return files[0]


def _files_of(item: str) -> list[tuple[Path, str | None]]:
    """The data files an argument names, with a name for partitions (else ``None``)."""
    if _GLOB.search(item) and not Path(item).exists():
        matched = sorted(glob.glob(item))
        if not matched:
            raise SettingsError(f"no file matches {item!r}.")
        return [f for m in matched for f in _files_of(m)]
    path = Path(item)
    if path.is_file():
        return [(path, None)]
    if path.is_dir():
        subs = sorted(p for p in path.iterdir() if p.is_dir() and _PARTITION.match(p.name))
        if subs:
            return [(_partition_file(p), p.name) for p in subs]
        files = sorted(p for p in path.iterdir() if _is_data(p))
        if not files:
            raise SettingsError(
                f"folder '{path}' holds no data file (extensions: {', '.join(SUPPORTED)}) "
                "and no partition folders (key=value)."
            )
        return [(p, None) for p in files]
    raise SettingsError(f"no such file or folder: '{item}'.")


def _unique(entries: list[tuple[str, Path | None]]) -> list[str]:
    names = [n for n, _ in entries]
    counts = Counter(names)
    out = []
    for name, path in entries:
        if counts[name] > 1 and path is not None:
            name = f"{path.parent.name}-{name}"
        out.append(name)
    seen: Counter[str] = Counter()
    final = []
    for name in out:
        seen[name] += 1
        final.append(name if seen[name] == 1 else f"{name}-{seen[name]}")
    if len(set(final)) != len(final):
        raise SettingsError(f"two records get the same name; rename them: {final}")
    return final


def _safe(name: str) -> str:
    cleaned = re.sub(r"[/\\\x00]", "_", name).lstrip(".")
    return cleaned or "record"


def expand_sources(sources: Any) -> list[RecordSource]:
    """The records named by ``sources`` (see the module), in order.

    Parameters
    ----------
    sources : str, os.PathLike, IOData, mapping or iterable of these
        Files, globs, folders, partitioned datasets, IOData objects, or a mapping
        ``{name: file or IOData}``.

    Returns
    -------
    list of RecordSource
        At least one, with unique names.

    Raises
    ------
    SettingsError
        A path that does not exist, a glob that matches nothing, a folder without data, a
        partition with several files, or no record at all.
    """
    if isinstance(sources, Mapping):
        out = []
        for name, item in sources.items():
            if isinstance(item, IOData):
                out.append(RecordSource(_safe(str(name)), data=item))
            else:
                out.append(RecordSource(_safe(str(name)), file=os.fspath(item)))
        if not out:
            raise SettingsError("the fleet has no record.")
        return out
    items: Iterable[Any] = (
        [sources] if isinstance(sources, (str, os.PathLike, IOData)) else list(sources)
    )
    entries: list[tuple[str, Path | None, Any]] = []
    k = 0
    for item in items:
        if isinstance(item, IOData):
            entries.append((f"record-{k}", None, item))
            k += 1
            continue
        for path, part in _files_of(os.fspath(item)):
            entries.append((part or record_name(path), None if part else path, path))
    if not entries:
        raise SettingsError("the fleet has no record.")
    names = _unique([(n, p) for n, p, _ in entries])
    return [
        RecordSource(_safe(name), data=obj)
        if isinstance(obj, IOData)
        else RecordSource(_safe(name), file=str(obj))
        for name, (_, _, obj) in zip(names, entries, strict=True)
    ]
