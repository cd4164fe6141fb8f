"""``step``'s updates of one record: the packed kernel state and blocks of output rows.

:class:`StepUpdates` is the lean path of :meth:`clpc.CLPC.step` (issue 26): the record's
settings, carried state and block cache are packed once
(:func:`clpc.appraiser.step_kernel.pack_state`); the outputs of :data:`ROWS` updates are
allocated at once as a :class:`Trace` (a block); each update is one call of
:func:`clpc.appraiser.step_kernel.update_row` that writes its row of the block, and ``step``
returns that row as a :meth:`Trace.lazy_view`. Rows are never written twice: a returned
update stays as it was, and a block lives as long as a row of it is held.
"""

from __future__ import annotations

import numpy as np

from clpc.appraiser.blocks import BlockCache
from clpc.appraiser.kernel import FsmState, KernelSetup
from clpc.appraiser.step_kernel import ROWS, new_outputs, pack_state, state_views, update_row
from clpc.appraiser.trace import Trace
from clpc.appraiser.trace_labels import TraceLabels
from clpc.appraiser.trace_table import PER_EQUATION

__all__ = ["ROWS", "StepUpdates"]


class StepUpdates:
    """One update at a time, each written into a row of a block of :data:`ROWS` rows.

    Parameters
    ----------
    setup : KernelSetup
        The record's plan and settings.
    state : (FsmState, BlockCache)
        The carried FSM state and the block cache so far: copied into the packed state;
        :meth:`state` gives the arrays to use from then on (views of it).
    labels : TraceLabels
        What the record's traces say besides the numbers.
    rows : (int, int)
        ``(max_lag, cluster)``: update ``j`` ends at sample ``max_lag + cluster j - 1``.
    """

    def __init__(
        self,
        setup: KernelSetup,
        state: tuple[FsmState, BlockCache],
        labels: TraceLabels,
        rows: tuple[int, int],
    ) -> None:
        self._setup = setup
        self._packed = pack_state(setup, *state)
        self._labels = labels
        self._max_lag, self._cluster = rows
        #: the arguments of update_row after the row: the packed state, the block's arrays
        self._args: tuple[np.ndarray, ...] = ()
        self._block: Trace | None = None
        self._j0 = 0  #: the update of the block's row 0
        self._next = ROWS  #: the block's first row not written yet

    def state(self) -> tuple[FsmState, BlockCache]:
        """The carried FSM state and the block cache: views of the packed state."""
        return state_views(self._packed)

    def update(self, samples: np.ndarray, first_row: int, j: int) -> Trace:
        """Update ``j``: solved, written into its row, returned as a one-row trace.

        Parameters
        ----------
        samples : ndarray, shape (n, channels)
            The buffered samples (C-contiguous).
        first_row : int
            The absolute lag row of ``samples[0]`` (as for
            :func:`clpc.appraiser.kernel.solve_windows`).
        j : int
            The update (after the one before it; updates solved elsewhere may lie between).

        Returns
        -------
        Trace
            One row, a :meth:`Trace.lazy_view` of the block.
        """
        row = j - self._j0
        if not self._next <= row < ROWS:
            self._new_block(j)
            row = 0
        update_row(samples, first_row, j, row, *self._args)
        self._next = row + 1
        return self._block.lazy_view(row, row + 1)  # type: ignore[union-attr]

    def _new_block(self, j0: int) -> None:
        """A block for updates ``j0 .. j0 + ROWS - 1`` (their sample indices filled in)."""
        out, views = new_outputs(self._setup, self._packed[1])
        index = self._max_lag + self._cluster * np.arange(j0, j0 + ROWS, dtype=np.int64) - 1
        arrays = {key: views[key] for key in PER_EQUATION}
        arrays["not_enough"] = views["not_enough"]
        self._block = self._labels.trace(index, views["rows"], arrays)
        self._args, self._j0, self._next = (*self._packed, *out), j0, 0
