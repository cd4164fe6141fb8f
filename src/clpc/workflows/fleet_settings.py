"""What a fleet's records are tracked with, and where each record comes from.

:class:`FleetSettings` is ``clpc track``'s settings but the file (taken by
:func:`clpc.track_many` under ``clpc track``'s names); :class:`RecordSource` is one record:
a file a worker reads, or an :class:`IOData` sent along. :meth:`FleetSettings.key` hashes both,
so that a re-run can tell a finished record from one whose settings or data changed.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.core.jsonable import jsonable
from clpc.data import IOData
from clpc.workflows.common import AppraiserSettings, RecordSpec, SettingsError
from clpc.workflows.track import TraceFormat, TrackSettings

__all__ = ["FleetSettings", "RecordSource"]

_TRACK_KEYS = ("fmt", "chunk_rows", "figure_updates")


@dataclass(frozen=True)
class RecordSource:
    """Where one record of a fleet comes from.

    Parameters
    ----------
    name : str
        The record's name: its folder ``OUT/<name>/`` and its row in the fleet table.
    file : str, optional
        A data file, read by the worker.
    data : IOData, optional
        Samples held in memory (sent to the worker); exactly one of ``file`` and ``data``.
    """

    name: str
    file: str | None = None
    data: IOData | None = None

    def __post_init__(self) -> None:
        if (self.file is None) == (self.data is None):
            raise ValueError(f"record {self.name!r}: give exactly one of file and data.")

    def fingerprint(self) -> str:
        """What identifies the source's content: path, size and mtime, or a samples hash."""
        if self.data is not None:
            h = hashlib.sha256()
            for arr in (self.data.u, self.data.y):
                h.update(np.ascontiguousarray(arr, dtype=np.float64).tobytes())
            h.update(repr((self.data.dt, self.data.input_names, self.data.output_names)).encode())
            return f"data:{h.hexdigest()}"
        st = os.stat(str(self.file))
        return f"file:{os.path.abspath(str(self.file))}:{st.st_size}:{st.st_mtime_ns}"


@dataclass(frozen=True)
class FleetSettings:
    """What every record of a fleet is tracked with (``clpc track``'s settings but the file).

    Parameters
    ----------
    record : RecordSpec
        Columns and time base; its ``file`` is replaced by each record's.
    appraiser : AppraiserSettings
        The appraiser's settings.
    fmt : {"csv", "parquet"}
        Format of each record's trace file.
    chunk_rows : int
        Rows read at a time.
    figure_updates : int
        As for :class:`clpc.workflows.TrackSettings`.
    """

    record: RecordSpec
    appraiser: AppraiserSettings = dataclasses.field(default_factory=AppraiserSettings)
    fmt: TraceFormat = "csv"
    chunk_rows: int = 100_000
    figure_updates: int = 20_000

    def __post_init__(self) -> None:
        if self.record.resample:
            raise SettingsError(
                "track-many reads each record in chunks, as track does, and cannot resample "
                "it; resample the records first."
            )
        self.track_settings("<record>", "<out>")  # TrackSettings' own checks, once, here

    @classmethod
    def from_keywords(cls, **settings: Any) -> FleetSettings:
        """Settings from the keywords of :func:`clpc.track_many` (``clpc track``'s names).

        Parameters
        ----------
        **settings
            ``inputs``, ``outputs`` (a name or a sequence), ``dt``, ``time_col``,
            ``time_unit``, ``time_rtol``, ``skip_rows``; every field of
            :class:`AppraiserSettings`; ``fmt``, ``chunk_rows``, ``figure_updates``.

        Raises
        ------
        TypeError
            An unknown keyword (the message lists the known ones).
        """
        rec_keys = [f.name for f in dataclasses.fields(RecordSpec) if f.name not in ("file",)]
        app_keys = [f.name for f in dataclasses.fields(AppraiserSettings)]
        unknown = sorted(set(settings) - {*rec_keys, *app_keys, *_TRACK_KEYS})
        if unknown:
            known = ", ".join([*rec_keys, *app_keys, *_TRACK_KEYS])
            raise TypeError(f"unknown setting(s) {unknown}; known: {known}.")
        rec = {k: settings[k] for k in rec_keys if k in settings}
        for k in ("inputs", "outputs"):
            if k in rec:
                rec[k] = (rec[k],) if isinstance(rec[k], (str, int)) else tuple(rec[k])
                rec[k] = tuple(str(c) for c in rec[k])
        return cls(
            record=RecordSpec(file="", **rec),
            appraiser=AppraiserSettings(**{k: settings[k] for k in app_keys if k in settings}),
            **{k: settings[k] for k in _TRACK_KEYS if k in settings},
        )

    def track_settings(self, file: str, out_dir: str) -> TrackSettings:
        """The :class:`TrackSettings` of one record (what ``clpc track`` would be given)."""
        record = dataclasses.replace(self.record, file=file)
        return TrackSettings(
            record, out_dir, self.appraiser, self.fmt, self.chunk_rows, None, self.figure_updates
        )

    def key(self, source: RecordSource) -> str:
        """A hash of the settings and the source: equal keys give equal outputs."""
        text = json.dumps([jsonable(dataclasses.asdict(self)), source.fingerprint()])
        return hashlib.sha256(text.encode()).hexdigest()
