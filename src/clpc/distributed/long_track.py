"""A long record's trace written by the workers, and its summary from every update.

:func:`track_long` appraises a ``.npy`` or Parquet record piece by piece on a Dask cluster
(:mod:`clpc.distributed.long_record`). Each worker writes its piece's rows as one file of a
partitioned Parquet dataset ``OUT/trace/part-NNNNNN.parquet`` (the columns of
:func:`clpc.appraiser.tracefile.trace_columns`, in time order by file name; readable with
``pandas.read_parquet("OUT/trace")`` or ``pyarrow.dataset``) and sends back only the
per-update arrays the summary reads (about a third of a row). The client feeds them, piece
by piece in update order, to the :class:`clpc.appraiser.scanned.ScannedTrace` that plain
``clpc track`` uses, and lets them go: its memory does not grow with the record, and the
summary (:func:`clpc.report.trace_summary`: counts, convergence, findings, the
steady-state model), written to ``OUT/summary.json``, is ``clpc track``'s bit for bit.

The dataset is written into a hidden folder and renamed to ``OUT/trace`` when every piece
is complete: a failed or killed run leaves the previous dataset (or none), never a part.
Every worker must see ``OUT`` at the same path (one machine, or a shared file system).
"""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
import tempfile
import uuid
from collections import deque
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from clpc.appraiser import CLPC
from clpc.appraiser.decimation import Decimator
from clpc.appraiser.scanned import ScannedTrace
from clpc.appraiser.trace import Trace
from clpc.core.atomic import write_file
from clpc.data import DataError
from clpc.distributed.cluster import dask_client
from clpc.distributed.long_record import check_peaks, gather, plan_record
from clpc.distributed.part_file import WrittenPiece, write_piece
from clpc.distributed.piece_tasks import RecordPlan
from clpc.distributed.pieces import warmup
from clpc.distributed.schedule import run_pieces
from clpc.distributed.shared_rows import SharedRows
from clpc.distributed.shared_track import SharedPieces
from clpc.distributed.sources import NpySource, ParquetSource
from clpc.model import LinearModel
from clpc.report import steady_state, trace_summary
from clpc.workflows.track_report import REPORT_SAMPLES, Appraised

__all__ = ["SUMMARY_KEYS", "LongTrack", "track_long"]

#: the last updates the report's table shows (as ``clpc track``'s)
RECENT = 20
#: the per-update arrays that counts, convergence, findings and the steady-state model read
#: (the same as ``clpc track`` keeps for its summary)
SUMMARY_KEYS = (
    "theta",
    "D",
    "c",
    "accepted",
    "has_model",
    "trusted",
    "determined",
    "degenerate",
    "excited",
    "n_input_relations",
    "stable",
)


@dataclass(frozen=True)
class LongTrack:
    """The outcome of :func:`track_long`.

    Attributes
    ----------
    summary : dict
        :func:`clpc.report.trace_summary` of every update (as ``clpc track``'s).
    model : LinearModel or None
        The steady-state model (``None``: no update was accepted).
    model_source : str
        Where ``model`` comes from (see :func:`clpc.report.steady_state`).
    dataset : Path
        The folder of the trace's Parquet parts.
    parts : int
        Pieces (files of the dataset).
    in_place : int
        Of them, the pieces whose rows the workers wrote into the record's trace in shared
        memory, settled there by the client (:mod:`clpc.distributed.shared_track`); the
        others' rows were settled by their workers and what the report needs sent back.
    appraised : Appraised
        What a report is made of (:func:`clpc.workflows.track.write_report`).
    """

    summary: dict[str, Any]
    model: LinearModel | None
    model_source: str
    dataset: Path
    parts: int
    in_place: int
    appraised: Appraised

    def close(self) -> None:
        """Remove the summary's scratch file (the report is made of ``appraised``)."""
        whole = self.appraised.whole
        if isinstance(whole, ScannedTrace):
            whole.close()


def track_long(
    appraiser: CLPC,
    source: NpySource | ParquetSource,
    out: str | os.PathLike[str],
    *,
    dt: float | None = None,
    client: Any = None,
    scheduler: str | None = None,
    workers: int | None = None,
    piece_samples: int | None = None,
    figure_updates: int = 20_000,
) -> LongTrack:
    """Appraise a record file on a Dask cluster; the workers write the trace as a dataset.

    Parameters
    ----------
    appraiser : CLPC
        The appraiser's settings (it is reset).
    source : NpySource or ParquetSource
        The record (:func:`clpc.distributed.open_source`).
    out : path
        Folder for ``trace/`` and ``summary.json`` (created).
    dt : float, optional
        The data's sample time [s] (default the appraiser's ``dt``).
    client, scheduler, workers
        Where to run (:func:`clpc.distributed.dask_client`).
    piece_samples : int, optional
        Decimated samples per piece (default
        :func:`clpc.distributed.schedule.default_piece_samples`).
    figure_updates : int
        The report's figures show at most about twice this many updates (as ``clpc track``).

    Returns
    -------
    LongTrack
        Call its :meth:`LongTrack.close` when done with its report (it removes the
        summary's scratch file).

    Raises
    ------
    clpc.DataError
        A record without a single update, a sample that is not finite, channels of
        hopeless scales.
    """
    appraiser.reset()
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    channels = (len(source.inputs), len(source.outputs))
    plan = plan_record(appraiser, channels, source.length(), dt, source.names(), levels=False)
    total = plan.layout.updates(plan.n_raw)
    if total == 0:
        raise DataError(
            f"{source.path}: {plan.n_raw} sample(s) give no cluster update with "
            f"window_size={appraiser.window_size}, cluster_size={appraiser.cluster_size}; use "
            "a longer record (or track it on one machine)."
        )
    staging = folder / f".trace-{uuid.uuid4().hex}"
    stride = thinning_stride(total, figure_updates)
    thinning = (SUMMARY_KEYS, (stride, RECENT))
    finish = (write_piece, (str(staging.resolve()), *thinning))
    taken = _Taken(ScannedTrace(Path(tempfile.gettempdir())))
    # the trace in shared memory, each window's own c beside it (None: the rows are sent)
    made = SharedRows.create(plan.state().empty_trace(), total, ((channels[1],),))
    try:
        with dask_client(client, scheduler, workers) as dask:
            tail = dask.submit(tail_samples, source, plan, REPORT_SAMPLES, pure=False)
            in_place, settled = None, 0
            if made is not None:
                in_place = SharedPieces(dask, plan, made, finish[1][0], thinning, taken.add)
            _, peaks = run_pieces(
                dask, plan, source, piece_samples, finish,
                sink=taken.add if in_place is None else in_place.take,
                shared=None if made is None else made[0],
                local=None if in_place is None else in_place.finish,
            )  # fmt: skip
            if in_place is not None:
                in_place.wait()
                settled = in_place.pieces
            tail = tail.result()
        check_peaks(appraiser, peaks, channels[0])
        summary = trace_summary(taken.whole)
        _replace(staging, folder / "trace")
        write_file(folder / "summary.json", json.dumps(summary, indent=1))
        model, model_source = steady_state(taken.whole)
    except BaseException:
        taken.whole.close()
        raise
    finally:
        shutil.rmtree(staging, ignore_errors=True)
        if made is not None:
            made[0].remove()
    figures = gather(taken.figures)
    figures = dataclasses.replace(
        figures, meta=dict(figures.meta, thinned_stride=stride, updates_total=total)
    )
    last = gather(list(taken.last))
    recent = last.take(np.arange(max(len(last) - RECENT, 0), len(last)))
    n_kept = plan.layout.kept(plan.n_raw)
    done = Appraised(appraiser.config(), n_kept, figures, taken.whole, recent, tail)
    parts = (taken.parts, settled)
    return LongTrack(summary, model, model_source, folder / "trace", *parts, done)


class _Taken:
    """What the client keeps of the written pieces, taken in time order (bounded memory)."""

    def __init__(self, whole: ScannedTrace) -> None:
        self.whole = whole  # every update's summary arrays, scanned and let go
        self.figures: list[Trace] = []  # every stride-th update: ~2 figure_updates in all
        self.last: deque[Trace] = deque(maxlen=2)  # the last RECENT updates are in these
        self.parts = 0

    def add(self, part: WrittenPiece) -> None:
        self.whole.add(part.summary)
        if len(part.figures):
            self.figures.append(part.figures)
        self.last.append(part.last)
        self.parts += 1


def thinning_stride(updates: int, figure_updates: int) -> int:
    """The stride :class:`clpc.appraiser.thinned.ThinnedTrace` ends with for ``updates``.

    The smallest power of two ``s`` with ``ceil(updates / s) <= 2 * figure_updates``.
    """
    stride = 1
    while -(-updates // stride) > 2 * figure_updates:
        stride *= 2
    return stride


def tail_samples(source: NpySource | ParquetSource, plan: RecordPlan, n: int) -> np.ndarray:
    """The record's last ``n`` samples at the appraiser's rate, ``[inputs | outputs]``.

    Read on a worker; with decimation the filter starts :func:`.pieces.warmup` samples
    before (the values agree with ``clpc track``'s to rounding).
    """
    lay = plan.layout
    first = max(0, lay.kept(plan.n_raw) - n)
    lo = max(0, first * lay.factor - warmup(lay.factor))
    raw = source.read(lo, plan.n_raw)
    kept = Decimator(lay.factor)(raw) if lay.factor > 1 else raw
    return np.array(kept[first - lo // lay.factor :], dtype=np.float64)


def _replace(new: Path, target: Path) -> None:
    """Rename the folder ``new`` to ``target``, removing a previous ``target`` folder."""
    if target.is_symlink() or (target.exists() and not target.is_dir()):
        raise DataError(f"{target} exists and is not a trace folder; remove it or pick --out.")
    old = target.with_name(f".{target.name}-old-{uuid.uuid4().hex}")
    if target.exists():
        target.rename(old)
    new.rename(target)
    shutil.rmtree(old, ignore_errors=True)
