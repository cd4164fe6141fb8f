"""The appraiser's state: the paper's FSM state and its transition.

:class:`AppraiserState` holds the FSM state - the samples the next windows need, the counters, the
last parameters, the decimation filter - and the transition (:meth:`AppraiserState.consume`:
new samples in, the updates they complete out). What the record's channels fix (the MIMO
mode, the parameters, the kernel setup, the trace labels) comes from its base class
:class:`~clpc.appraiser.record_layout.RecordLayout`. Its saved form is
:mod:`clpc.appraiser.saved_state` (:meth:`AppraiserState.resume` continues from it).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.appraiser import kernel
from clpc.appraiser.buffer import SampleBuffer
from clpc.appraiser.decimation import Decimator
from clpc.appraiser.inputs import check_finite
from clpc.appraiser.record_layout import RecordLayout
from clpc.appraiser.state_schema import FORMAT, VERSION, digest
from clpc.appraiser.step_block import StepUpdates
from clpc.appraiser.trace import Trace
from clpc.data import DataError
from clpc.lpc.regressors import miso_regressor

__all__ = ["FORMAT", "VERSION", "AppraiserState", "digest"]


@dataclass(eq=False, slots=True)
class AppraiserState(RecordLayout):
    """The FSM state of one record; a new one per record (:meth:`clpc.CLPC.reset`).

    ``n_seen`` counts decimated samples (those kept aside included), ``j_done`` updates;
    ``last_theta``, ``last_c``, ``has_model`` are the carried output (:class:`kernel.FsmState`).
    The channels, names, ``setup``, ``labels`` and ``empty`` are :class:`RecordLayout`'s.
    """

    max_lag: int = 0
    cluster: int = 1
    buffer: SampleBuffer | None = None
    n_seen: int = 0
    j_done: int = 0
    last_theta: np.ndarray | None = None
    last_c: np.ndarray | None = None
    has_model: np.ndarray | None = None
    decimator: Decimator | None = None
    plain: bool = False  #: no decimation: step keeps samples aside
    plain_siso: bool = False  #: and one input, one output: step's fastest path
    blocks: kernel.BlockCache | None = None  #: statistics of the newest blocks (derived)
    stepper: StepUpdates | None = None  #: step's updates (made on the first; derived)

    def __post_init__(self) -> None:
        self.max_lag = self.settings.structure.max_lag
        self.cluster = self.settings.cluster_size

    # ------------------------------------------------------------ the record's channels
    def set_decimator(self, decimator: Decimator) -> None:
        """Use ``decimator`` for the samples fed from now on."""
        self.decimator = decimator
        self.plain = decimator.factor == 1
        self.plain_siso = self.plain and (self.n_in, self.n_out) == (1, 1)

    def init_channels(self, n_in: int, n_out: int, names: Any = None) -> None:
        """Fix the record's channels on first data; later chunks must match them."""
        if self.n_in is None:
            self.n_in, self.n_out = n_in, n_out
            self.mode()  # validates
            p = self.n_params()
            self.settings.check_window(p)
            self.buffer = SampleBuffer(n_in + n_out)
            self.last_theta = np.zeros((n_out, p))
            self.last_c = np.zeros(n_out)
            self.has_model = np.zeros(n_out, dtype=bool)
            if names is not None:
                self.names = names
            self.plain_siso = self.plain and (n_in, n_out) == (1, 1)
        elif (n_in, n_out) != (self.n_in, self.n_out):
            raise DataError(
                f"the appraiser was fed {self.n_in} input(s) and {self.n_out} output(s); "
                f"this chunk has {n_in} and {n_out}. Call reset() to start a new record."
            )

    def resume(
        self,
        samples: tuple[np.ndarray, int],
        counts: tuple[int, int],
        model: tuple[np.ndarray, np.ndarray, np.ndarray],
        record_dt: float | None,
    ) -> None:
        """Continue from a saved point (:mod:`.saved_state`; every value checked by it).

        ``samples``: the kept decimated samples (n, n_in + n_out) and the absolute index of
        the first; ``counts``: ``n_seen``, ``j_done``; ``model``: ``last_theta`` (n_out, p),
        ``last_c`` (n_out,), ``has_model`` (n_out,); ``record_dt``: the data's sample time
        [s] when the appraiser works at it (else ``None``). The channels are set first.
        """
        assert self.buffer is not None
        data, start = samples
        if data.size:
            self.buffer.data = data
        self.buffer.start = start
        self.n_seen, self.j_done = counts
        self.last_theta, self.last_c, self.has_model = model
        self.stepper = None  # its packed state holds the former values
        if record_dt is not None:
            self.record_dt = record_dt

    # ------------------------------------------------------------ the transition
    def window(self) -> np.ndarray:
        """The current window's lag vectors, shape (E, rows, p)."""
        if self.buffer is None:
            return np.empty((1, 0, self.settings.structure.n_params()))
        assert self.n_in is not None and self.n_out is not None
        s = self.settings.structure
        rows_total = max(self.n_seen - self.max_lag, 0)
        buf = self.buffer.since(max(rows_total - self.settings.window_size, 0))
        if buf.shape[0] <= s.max_lag:
            return np.empty((self.n_out, 0, self.n_params()))
        u, y = buf[:, : self.n_in], buf[:, self.n_in :]
        miso = self.mode() == "miso"
        return np.stack(
            [miso_regressor(y[:, j], u if miso else u[:, j : j + 1], s) for j in range(self.n_out)]
        )

    def updates_after(self, n_samples: int) -> int:
        """Updates that ``n_samples`` more (undecimated) samples will complete."""
        dec = self.decimator
        f = dec.factor if dec is not None else 1
        first = (-(dec.phase if dec is not None else 0)) % f  # the first one decimation keeps
        kept = 0 if first >= n_samples else (n_samples - 1 - first) // f + 1
        return max(self.n_seen + kept - self.max_lag, 0) // self.cluster - self.j_done

    def keep_aside(self, sample: Any, update: bool) -> Trace:
        """Keep one undecimated sample aside (``step``); solve when it closes an update.

        ``sample``: its values (inputs, then outputs), floats; ``update``: it closes one.
        """
        buf = self.buffer
        assert buf is not None
        buf.pending.extend(sample)
        self.n_seen += 1
        if not update:
            return self.empty if self.empty is not None else self.empty_trace()
        return self._take_aside()

    def keep_scalar(self, u_k: float, y_k: float) -> Trace:
        """:meth:`keep_aside` of a sample of one input and one output (``step``'s fast path).

        Only for a record that keeps samples aside (:attr:`plain_siso`: its channels known,
        no decimation); ``u_k``, ``y_k`` real scalars (``float`` takes them).
        """
        u, y = float(u_k), float(y_k)
        if u - u != 0.0 or y - y != 0.0:  # inf or nan (inf - inf is nan)
            check_finite(np.array([[u]]), "u", self.n_seen)
            check_finite(np.array([[y]]), "y", self.n_seen)
        pending = self.buffer.pending  # type: ignore[union-attr]
        pending.append(u)
        pending.append(y)
        self.n_seen = n = self.n_seen + 1
        if n <= self.max_lag or (n - self.max_lag) % self.cluster:
            empty = self.empty
            return empty if empty is not None else self.empty_trace()
        return self._take_aside()

    def _take_aside(self) -> Trace:
        """The samples kept aside into the buffer, and the one update they close (``step``)."""
        trace = self._one_update()
        self._forget()
        return trace

    def consume(self, new: np.ndarray, mapper: Callable[..., Any] = map) -> Trace:
        """Append decimated samples and compute the updates they complete (a new trace).

        ``mapper`` is ``map`` or a thread pool's (``n_jobs > 1``: batches on threads).
        """
        if new.shape[0] == 0:
            return self.empty_trace()
        count = self._append(new)
        if count == 1:  # one update (step, small pushes): one kernel call, no batching
            trace = self._one_update()
        elif count > 1:
            trace = Trace.allocate(self.empty_trace(), count)
            self._solve_into(trace, mapper)
        else:
            trace = self.empty_trace()
        self._forget()
        return trace

    def consume_into(
        self, new: np.ndarray, mapper: Callable[..., Any], out: Trace, row: int
    ) -> int:
        """:meth:`consume`, writing the updates into rows ``row ..`` of ``out``; the next row.

        ``out`` comes from :meth:`Trace.allocate` with room for them: the kernel writes into
        its arrays directly (no copy of the updates).
        """
        if new.shape[0] == 0:
            return row
        count = self._append(new)
        if count > 0:
            self._solve_into(out.view(row, row + count), mapper)
        self._forget()
        return row + count

    def _append(self, new: np.ndarray) -> int:
        """Append decimated samples to the buffer; returns the updates they complete."""
        buf = self.buffer
        assert buf is not None
        buf.append(new)
        self.n_seen += new.shape[0]
        return max(self.n_seen - self.max_lag, 0) // self.cluster - self.j_done

    def _fsm_state(self) -> tuple[kernel.FsmState, kernel.BlockCache]:
        """The carried FSM state and the block cache (made on first use; never saved)."""
        assert self.last_theta is not None and self.last_c is not None
        assert self.has_model is not None
        if self.blocks is None:
            plan = self.kernel_setup().plan
            self.blocks = kernel.new_cache(plan.chan.shape, kernel.cache_blocks(plan))
        return kernel.FsmState(self.last_theta, self.last_c, self.has_model), self.blocks

    def _one_update(self) -> Trace:
        """The next update alone, as a new trace (``step``'s lean path, small pushes).

        The samples kept aside join the buffer, whose whole store goes to the kernel (no
        view made: :meth:`SampleBuffer.flushed`).
        """
        buf = self.buffer
        assert buf is not None
        store, first = buf.flushed()
        j = self.j_done + 1
        trace = (self.stepper or self._stepper()).update(store, first - self.max_lag, j)
        self.j_done = j
        return trace

    def _stepper(self) -> StepUpdates:
        """``step``'s updates; the carried state and the cache become views of its state."""
        stepper = StepUpdates(
            self.kernel_setup(),
            self._fsm_state(),
            self.trace_labels(),
            (self.max_lag, self.cluster),
        )
        (self.last_theta, self.last_c, self.has_model), self.blocks = stepper.state()
        self.stepper = stepper
        return stepper

    def _solve_into(self, part: Trace, mapper: Callable[..., Any]) -> None:
        """The next ``len(part)`` updates, written into ``part``'s arrays."""
        buf = self.buffer
        assert buf is not None
        j0, j_last = self.j_done + 1, self.j_done + len(part)
        kernel.solve_updates(
            self.kernel_setup(),
            (buf.data, buf.start - self.max_lag),
            (j0, j_last),
            self._fsm_state(),
            kernel.trace_outputs(part.arrays, part.rows, part.not_enough_data),
            (self.settings.n_jobs, mapper),
        )
        part.index[:] = self.max_lag + self.cluster * np.arange(j0, j_last + 1) - 1
        part.time[:] = part.index * part.sample_time
        self.j_done = j_last

    def _forget(self) -> None:
        """Keep only what the next window needs: rows from ``max(0, C (j+1) - W - C)``."""
        assert self.buffer is not None
        c = self.cluster
        self.buffer.drop_before(max(0, c * (self.j_done + 1) - self.settings.window_size - c))
