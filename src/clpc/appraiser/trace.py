"""The output of the appraiser: one row per cluster update, plus the convergence verdict.

Array keys and table layout: :mod:`clpc.appraiser.trace_table`; how the traces of one record
are made: :class:`~clpc.appraiser.trace_labels.TraceLabels`; what a trace concludes (``held``,
``convergence``, ``steady_state_model``): its base class
:class:`~clpc.appraiser.trace_verdict.TraceVerdict`.
"""

from __future__ import annotations

import operator
from collections.abc import Callable
from dataclasses import dataclass, field, fields, replace
from typing import Any

import numpy as np

from clpc.appraiser.convergence import MIN_TRUSTED_FRACTION, Convergence
from clpc.appraiser.trace_table import PER_EQUATION, SCALAR_KEYS, theta_labels, trace_frame
from clpc.appraiser.trace_verdict import TraceVerdict
from clpc.core.compact import compact_repr
from clpc.model.structure import Structure

__all__ = ["MIN_TRUSTED_FRACTION", "PER_EQUATION", "SCALAR_KEYS", "Convergence", "Trace"]


@compact_repr
@dataclass(frozen=True, eq=False)
class Trace(TraceVerdict):
    """Per-update record of a CLPC run (one row per cluster update).

    Arrays of every equation carry an equation axis 1; the properties of the same name
    drop it for single-output models (``theta`` is then (n_updates, p)).

    Attributes
    ----------
    index : ndarray of int, shape (n,)
        Sample index ``k`` of the newest sample in the window (after decimation).
    time : ndarray, shape (n,)
        ``index * sample_time`` [s].
    rows : ndarray of int, shape (n,)
        Lag vectors in the window.
    not_enough_data : ndarray of bool, shape (n,)
        Fewer rows than ``min_rows``: the estimate is not used.
    arrays : dict
        Per-equation arrays (see :data:`PER_EQUATION`): ``theta`` (held output, unit norm,
        paper convention), ``theta_estimate`` (this window's solution), ``den``/``num``
        (monic, ascending powers of ``z^-1``, of the held ``theta``), eigenvalues,
        ``lambda_min``, ``lambda_max``, ``D``, ``eig_ratio``, ``separation``,
        ``noise_variance``, ``J``, ``c``, ``n_null``, ``n_input_relations`` and flags
        ``degenerate``, ``determined``, ``accepted``, ``has_model``, ``stable``.
    structure : Structure
        Orders and delay of every window's model.
    n_inputs : int
        Inputs of the record.
    mode : {"siso", "paired", "miso"}
        How outputs relate to inputs.
    sample_time : float
        The appraiser's sample time [s] (after decimation).
    input_names, output_names : tuple of str
        Channel names.
    meta : dict
        The appraiser's settings and what it noticed (JSON-safe; written beside trace files).
    """

    index: np.ndarray
    time: np.ndarray
    rows: np.ndarray
    not_enough_data: np.ndarray
    arrays: dict[str, np.ndarray]
    structure: Structure
    n_inputs: int
    mode: str
    sample_time: float
    input_names: tuple[str, ...] = ("u",)
    output_names: tuple[str, ...] = ("y",)
    meta: dict[str, Any] = field(default_factory=dict)

    def __len__(self) -> int:
        lazy = self.__dict__.get("_view_of")  # a lazy_view: counted without slicing
        return lazy[2] - lazy[1] if lazy is not None else int(self.index.shape[0])

    @property
    def n_equations(self) -> int:
        """Number of equations (outputs)."""
        return int(self.arrays["theta"].shape[1])

    def __getattr__(self, name: str) -> np.ndarray:
        lazy = self.__dict__.get("_view_of")
        if lazy is not None:  # a lazy_view: a per-equation array sliced alone, else all
            block, start, stop = lazy
            source = block.__dict__["arrays"].get(name)
            if source is not None:
                value = source[start:stop]
                return value[:, 0] if value.shape[1] == 1 else value
            self._materialise()
            return getattr(self, name)
        arrays = self.__dict__.get("arrays")
        if arrays is not None and name in arrays:
            value = arrays[name]
            return value[:, 0] if value.shape[1] == 1 else value
        raise AttributeError(name)

    def _repr_html_(self) -> str:
        """Counts, convergence, findings and the steady-state model as HTML (Jupyter)."""
        from clpc.appraiser.display import trace_html

        return trace_html(self)

    # ----------------------------------------------------------------- building
    @classmethod
    def of(cls, values: dict[str, Any]) -> Trace:
        """A trace from every field's value, without the dataclass ``__init__``.

        The streaming path builds a trace per update; this is several times cheaper.

        Parameters
        ----------
        values : dict
            Every field's value by name (checked against the dataclass's fields).
        """
        if values.keys() != _FIELD_NAMES:
            raise TypeError(f"Trace.of needs exactly the fields {sorted(_FIELD_NAMES)}.")
        trace = object.__new__(cls)
        trace.__dict__.update(values)
        return trace

    @classmethod
    def concat(cls, traces: list[Trace], like: Trace | None = None) -> Trace:
        """Concatenate traces of the same appraiser in time order.

        Parameters
        ----------
        traces : list of Trace
            Parts in time order (``None`` entries are skipped).
        like : Trace, optional
            The trace whose settings (structure, names, ``meta``) the result takes; default
            the first part.

        Returns
        -------
        Trace

        Raises
        ------
        ValueError
            No trace to concatenate.
        """
        traces = [t for t in traces if t is not None]
        if not traces:
            raise ValueError("nothing to concatenate")
        first = traces[0] if like is None else like
        kw: dict[str, Any] = {
            f: np.concatenate([getattr(t, f) for t in traces]) for f in _ROW_FIELDS
        }
        arrays = {k: np.concatenate([t.arrays[k] for t in traces]) for k in first.arrays}
        return replace(first, **kw, arrays=arrays)

    @classmethod
    def allocate(cls, like: Trace, n: int, empty: Callable[..., np.ndarray] = np.empty) -> Trace:
        """An uninitialised trace of ``n`` rows shaped like ``like`` (fill it with :meth:`put`).

        Lets a long run write its parts into the final arrays instead of concatenating them
        at the end (which holds the parts and the result at once: twice the memory).

        Parameters
        ----------
        like : Trace
            A trace of the same appraiser (its settings, names and array shapes per row).
        n : int
            Rows to allocate.
        empty : callable
            ``empty(shape, dtype)`` makes each array, in a fixed order (e.g. views of a map).
        """
        kw: dict[str, Any] = {
            f: empty((n, *getattr(like, f).shape[1:]), getattr(like, f).dtype) for f in _ROW_FIELDS
        }
        arrays = {k: empty((n, *v.shape[1:]), v.dtype) for k, v in like.arrays.items()}
        return replace(like, **kw, arrays=arrays, meta=dict(like.meta))

    def view(self, start: int, stop: int) -> Trace:
        """Rows ``start .. stop - 1`` sharing this trace's memory (writing one writes both).

        Parameters
        ----------
        start, stop : int
            The rows, as in a slice.
        """
        rows = slice(start, stop)
        values = {f: getattr(self, f)[rows] for f in _ROW_FIELDS}
        values["arrays"] = {k: v[rows] for k, v in self.arrays.items()}
        for f in _FIELD_NAMES - values.keys():
            values[f] = getattr(self, f)
        return Trace.of(values)

    def lazy_view(self, start: int, stop: int) -> Trace:
        """:meth:`view`, its per-row arrays sliced on first use (``step``'s update).

        A view slices some 25 arrays (about 10 us); ``step`` returns its update as a view of
        a block of rows, and a caller that never reads it should not pay for the slicing.
        The labels (``structure``, names, ``meta`` - a copy) are set at once; a
        per-equation array read by name (``theta``, ``D``, ...) is sliced alone, at each
        read; any other field makes the view (:meth:`view`, the same arrays) and keeps it.

        Parameters
        ----------
        start, stop : int
            The rows, as in a slice.
        """
        trace = object.__new__(Trace)
        values = trace.__dict__
        values.update(zip(_LABEL_FIELDS, _labels_of(self.__dict__), strict=True))
        values["meta"] = dict(self.meta)
        values["_view_of"] = (self, start, stop)
        return trace

    def _materialise(self) -> None:
        """Slice the arrays of a :meth:`lazy_view` (idempotent)."""
        values = self.__dict__
        source = values.get("_view_of")
        if source is None:
            return
        block, start, stop = source
        of = block.__dict__
        for f in _ROW_FIELDS:  # as view() slices them, without a trace in between
            values[f] = of[f][start:stop]
        values["arrays"] = {k: v[start:stop] for k, v in of["arrays"].items()}
        values.pop("_view_of", None)

    def __getstate__(self) -> dict[str, Any]:
        """The fields for pickling (a :meth:`lazy_view` is sliced first: not its block)."""
        self._materialise()
        return self.__dict__

    def put(self, start: int, part: Trace) -> int:
        """Copy the rows of ``part`` into rows ``start ..``; returns the row after them.

        Parameters
        ----------
        start : int
            First row to write.
        part : Trace
            Rows of the same appraiser (from :meth:`CLPC.push`).

        Returns
        -------
        int
            ``start + len(part)``.
        """
        stop = start + len(part)
        for f in _ROW_FIELDS:
            getattr(self, f)[start:stop] = getattr(part, f)
        for key, value in self.arrays.items():
            value[start:stop] = part.arrays[key]
        return stop

    # ----------------------------------------------------------------- views
    def labels(self) -> list[str]:
        """Names of the entries of ``theta``: ``a0 .. a_na, b0 .. b_nb`` per input block."""
        return theta_labels(self)

    def to_frame(self) -> Any:
        """The trace as a pandas DataFrame (one row per update; needs pandas)."""
        return trace_frame(self)

    def take(self, rows: Any) -> Trace:
        """The updates ``rows`` as a trace of their own.

        Parameters
        ----------
        rows : ndarray of int or bool, or slice
            Which updates, as for indexing ``trace.index``.

        Returns
        -------
        Trace
            ``meta["window_level"]`` (one row per update) is taken along when it matches.
        """
        meta = dict(self.meta)
        levels = meta.get("window_level")
        if levels is not None and np.shape(levels)[0] == len(self):
            meta["window_level"] = np.asarray(levels)[rows]
        kw: dict[str, Any] = {f: getattr(self, f)[rows] for f in _ROW_FIELDS}
        return replace(self, **kw, arrays={k: v[rows] for k, v in self.arrays.items()}, meta=meta)


_FIELD_NAMES = {f.name for f in fields(Trace)}
#: the fields with one row per update besides ``arrays``
_ROW_FIELDS = ("index", "time", "rows", "not_enough_data")
#: the fields that are the same for every row (besides ``meta``, copied per trace)
_LABEL_FIELDS = tuple(sorted(_FIELD_NAMES - {*_ROW_FIELDS, "arrays", "meta"}))
_labels_of = operator.itemgetter(*_LABEL_FIELDS)
