"""Samples into an appraiser's state: one sample (``step``), a chunk (``push``), a record (``run``).

The functions drive an :class:`~clpc.appraiser.state.AppraiserState` through its methods: they
check the samples (:mod:`clpc.appraiser.inputs`), decimate them chunk by chunk in bounded
working memory, and collect the updates they complete into one :class:`Trace` (the kernel
writes into its arrays). :class:`clpc.CLPC`'s ``step``, ``push`` and ``run`` are these.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from clpc.appraiser.decimation import Decimator
from clpc.appraiser.inputs import (
    as_chunk,
    as_columns,
    as_record,
    check_chunk,
    check_finite,
)
from clpc.appraiser.levels import attach_levels
from clpc.appraiser.state import AppraiserState
from clpc.appraiser.trace import Trace
from clpc.data.samples import check_spread

__all__ = ["feed_chunk", "feed_record", "feed_sample"]

_LOG = logging.getLogger("clpc.appraiser")

#: ``map`` of the batched solves: ``map`` or a thread pool's (``n_jobs > 1``)
Mapper = Callable[..., Iterable[Any]]
#: ``progress(samples_done, samples_total, updates_done)``
Progress = Callable[[int, int, int], Any]


def feed_sample(state: AppraiserState, u_k: Any, y_k: Any, mapper: Mapper) -> Trace:
    """One sample (:meth:`clpc.CLPC.step`); the update it produced (0 or 1 rows).

    Without decimation the sample is kept aside (plain floats) and the update it closes is
    solved alone; else the sample is fed as a chunk of one. (A scalar input and output of a
    single-channel record never come here: ``CLPC.step`` hands them to
    :meth:`AppraiserState.keep_scalar`.)

    Parameters
    ----------
    state : AppraiserState
        The record's state.
    u_k, y_k : float or array_like
        The input and output samples.
    mapper : callable
        ``map`` of the batched solves.
    """
    s = state
    rows_after = s.n_seen + 1 - s.max_lag
    update = rows_after > 0 and rows_after % s.cluster == 0
    u = as_columns(u_k, "u").ravel()
    y = as_columns(y_k, "y").ravel()
    if s.plain and u.shape == (s.n_in,) and y.shape == (s.n_out,):
        sample = np.concatenate([u, y])
        if not np.all(np.isfinite(sample)):
            check_finite(u[None], "u", s.n_seen)
            check_finite(y[None], "y", s.n_seen)
        return s.keep_aside(sample.tolist(), update)
    return feed_chunk(s, as_chunk(u[None, :], y[None, :], s.n_seen), mapper, None)


def feed_chunk(
    state: AppraiserState,
    chunk: tuple[np.ndarray, np.ndarray],
    mapper: Mapper,
    progress: Progress | None,
) -> Trace:
    """A chunk already checked by :func:`as_chunk` (or :func:`check_chunk`); its updates.

    Parameters
    ----------
    state : AppraiserState
        The record's state.
    chunk : (ndarray, ndarray)
        Inputs (n, n_inputs) and outputs (n, n_outputs), float columns.
    mapper : callable
        ``map`` of the batched solves.
    progress : callable or None
        Called after each block of ``chunk_samples`` samples (see :meth:`clpc.CLPC.push`).
    """
    s = state
    u2, y2 = chunk
    n = u2.shape[0]
    s.init_channels(u2.shape[1], y2.shape[1])
    if s.decimator is None:
        s.set_decimator(Decimator(s.settings.factor(None)))
    decimator = s.decimator
    assert decimator is not None
    total = s.updates_after(n)
    # the kernel writes the updates straight into the final arrays (no copies)
    out = Trace.allocate(s.empty_trace(), total) if total else s.empty_trace()
    done, step = 0, s.settings.chunk_samples
    n_in = u2.shape[1]
    rows = np.empty((min(step, n), n_in + y2.shape[1]))  # one chunk's [u | y], reused
    for lo in range(0, n, step):  # bounded working memory
        hi = min(lo + step, n)
        rows[: hi - lo, :n_in] = u2[lo:hi]
        rows[: hi - lo, n_in:] = y2[lo:hi]
        block = decimator(rows[: hi - lo])  # the buffer copies what it keeps
        if total:
            done = s.consume_into(block, mapper, out, done)
        else:
            s.consume(block, mapper)  # no update: the samples are only kept
        _LOG.debug("CLPC: %d of %d samples, %d updates", hi, n, done)
        if progress is not None:
            progress(hi, n, done)
    assert done == total, (done, total)
    return out


def feed_record(
    state: AppraiserState,
    record: tuple[Any, Any, float | None],
    mapper: Mapper,
    progress: Progress | None,
) -> Trace:
    """A whole record into a fresh state (:meth:`clpc.CLPC.run`); one row per update.

    Parameters
    ----------
    state : AppraiserState
        A state that has seen nothing.
    record : (IOData or array_like, array_like or None, float or None)
        ``u``, ``y`` and ``dt`` as :meth:`clpc.CLPC.run` takes them.
    mapper : callable
        ``map`` of the batched solves.
    progress : callable or None
        As for :func:`feed_chunk`.
    """
    s, settings = state, state.settings
    u, y, dt = record
    u_arr, y_arr, data_dt, names = as_record(u, y, dt)
    s.init_channels(u_arr.shape[1], y_arr.shape[1], names)
    factor = settings.factor(data_dt)
    if settings.noise_cov is None and settings.noise_ratio is None:
        check_spread(u_arr, y_arr, settings.scaling)
    s.set_decimator(Decimator(factor))
    if settings.decimate_to is None and data_dt is not None:
        s.record_dt = data_dt  # no decimation: the appraiser works at the data's rate
    # as_record made them float columns (as push would): only length and finiteness left
    trace = feed_chunk(s, check_chunk(u_arr, y_arr, 0), mapper, progress)
    attach_levels(trace, y_arr, factor)  # the windows' levels (steady state)
    return trace
