"""Several experiments in one record: their lengths checked, joined, split and sliced.

A record (:class:`~clpc.data.IOData`) may hold several experiments stacked along the sample
axis; ``experiments`` holds the samples of each, in order. :class:`Experiments` is a base
class of :class:`~clpc.data.IOData` that gives it :meth:`~Experiments.concat` and
:meth:`~Experiments.split`; estimators build their lag vectors inside each experiment.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol, Self, TypeVar

import numpy as np

from clpc.data.validation import DataError

__all__ = ["Experiments", "RecordLike", "RecordT", "check_experiments", "slice_experiments"]


def check_experiments(given: Sequence[int] | None, n: int) -> tuple[int, ...]:
    """The samples of each experiment of a record of ``n`` samples (default one experiment).

    Parameters
    ----------
    given : sequence of int, optional
        Samples of each experiment, in order; ``None`` or empty: one experiment of ``n``.
    n : int
        Samples in the record.

    Returns
    -------
    tuple of int

    Raises
    ------
    DataError
        A count below 1, or counts that do not sum to ``n``.
    """
    if given is None or len(given) == 0:
        return (n,)
    parts = tuple(int(k) for k in given)
    if any(k < 1 for k in parts) or sum(parts) != n:
        raise DataError(
            f"experiments must be positive sample counts summing to {n}; got {list(given)}."
        )
    return parts


def slice_experiments(experiments: Sequence[int], start: int, stop: int, step: int) -> list[int]:
    """The experiments' samples in the slice ``start:stop:step`` of their record.

    Parameters
    ----------
    experiments : sequence of int
        Samples of each experiment of the record.
    start, stop, step : int
        The slice, as :meth:`slice.indices` gives it.

    Returns
    -------
    list of int
        The samples of each experiment that falls inside the slice; empty for a record of one
        experiment (whatever length the slice has).

    Raises
    ------
    DataError
        A step other than 1 on a record of several experiments.
    """
    if len(experiments) <= 1:
        return []
    if step != 1:
        raise DataError("a record of several experiments can be sliced with step 1 only.")
    ends = np.cumsum(experiments)
    lo = np.clip(ends - np.asarray(experiments), start, max(stop, start))
    return [int(n) for n in np.clip(ends, start, max(stop, start)) - lo if n > 0]


class RecordLike(Protocol):
    """What the record's base classes use of it (:class:`Experiments`, ``Preprocessing``)."""

    @property
    def u(self) -> np.ndarray:
        """Inputs, shape (T, n_inputs)."""

    @property
    def y(self) -> np.ndarray:
        """Outputs, shape (T, n_outputs)."""

    @property
    def dt(self) -> float:
        """Sample time [s]."""

    @property
    def input_names(self) -> tuple[str, ...]:
        """Input channel names."""

    @property
    def output_names(self) -> tuple[str, ...]:
        """Output channel names."""

    @property
    def experiments(self) -> tuple[int, ...]:
        """Samples of each experiment, in order."""

    def _with(self, u: Any, y: Any, dt: float | None = None, experiments: Any = None) -> Self:
        """A new record with these samples and this record's names."""


#: a record of the base classes' methods (``IOData``)
RecordT = TypeVar("RecordT", bound=RecordLike)


class Experiments:
    """``concat`` and ``split`` of a record's experiments; a base class of ``IOData``."""

    @classmethod
    def concat(cls, records: Sequence[RecordT]) -> RecordT:
        """Several experiments as one record (their boundaries kept, see :meth:`split`).

        Parameters
        ----------
        records : sequence of IOData
            The experiments, in order; same sample time and same channel names.

        Returns
        -------
        IOData
            The samples stacked, with one entry of ``experiments`` per record's experiment.

        Raises
        ------
        DataError
            No record, or records with different sample times or channel names.
        """
        records = list(records)
        if not records or not all(isinstance(r, cls) for r in records):
            raise DataError("concat needs a non-empty sequence of IOData records.")
        first = records[0]
        for i, r in enumerate(records[1:], 1):
            if abs(r.dt - first.dt) > 1e-9 * first.dt:
                raise DataError(
                    f"experiment {i} has dt = {r.dt:g} s but experiment 0 has {first.dt:g} s; "
                    "resample them to one sample time first (IOData.resample)."
                )
            if (r.input_names, r.output_names) != (first.input_names, first.output_names):
                raise DataError(
                    f"experiment {i} has channels {list(r.input_names)} -> "
                    f"{list(r.output_names)} but experiment 0 has {list(first.input_names)} "
                    f"-> {list(first.output_names)}; give every experiment the same channels."
                )
        return first._with(
            np.concatenate([r.u for r in records]),
            np.concatenate([r.y for r in records]),
            experiments=[n for r in records for n in r.experiments],
        )

    def split(self: RecordT) -> list[RecordT]:
        """One record per experiment."""
        ends = np.cumsum(self.experiments)
        return [
            self._with(self.u[e - n : e], self.y[e - n : e], experiments=[n])
            for n, e in zip(self.experiments, ends, strict=True)
        ]

    @property
    def n_experiments(self: RecordLike) -> int:
        """Number of experiments in the record."""
        return len(self.experiments)
