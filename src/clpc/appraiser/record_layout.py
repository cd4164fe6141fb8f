"""What a record's channels fix: the MIMO mode, the parameters, the kernel setup, trace labels.

:class:`RecordLayout` is a base class of :class:`~clpc.appraiser.state.AppraiserState`: the
channel counts and names, the data's sample time, and what follows from them once per record
- the MIMO mode, the parameters of one equation, the fewest rows of a usable window, the
kernel's setup (:func:`clpc.appraiser.kernel.record_setup`), the labels of the record's traces
and its empty trace - each made on first use and kept.
"""

from __future__ import annotations

from dataclasses import dataclass

from clpc.appraiser import kernel
from clpc.appraiser.settings import Settings
from clpc.appraiser.trace import Trace
from clpc.appraiser.trace_labels import TraceLabels
from clpc.model.structure import check_mode, default_mode

__all__ = ["RecordLayout"]


@dataclass(eq=False, slots=True)
class RecordLayout:
    """The layout of one record's channels (a base class of the appraiser's state).

    ``n_in``, ``n_out`` and ``names`` are ``None`` until the first data fix them;
    ``record_dt`` is the data's sample time [s] when the appraiser works at it. ``setup``,
    ``labels`` and ``empty`` are fixed per record once the channels are known (made on
    first use).
    """

    settings: Settings
    n_in: int | None = None
    n_out: int | None = None
    names: tuple[tuple[str, ...], tuple[str, ...]] | None = None
    record_dt: float | None = None
    setup: kernel.KernelSetup | None = None
    labels: TraceLabels | None = None
    empty: Trace | None = None

    def mode(self) -> str:
        """The MIMO mode in use (validated against the channel counts)."""
        assert self.n_in is not None and self.n_out is not None
        chosen = self.settings.mimo or default_mode(self.n_in, self.n_out)
        check_mode(chosen, self.n_in, self.n_out)
        return str(chosen)

    def n_blocks(self) -> int:
        """Input blocks of a lag vector (all inputs with ``miso``, else one)."""
        assert self.n_in is not None
        return self.n_in if self.mode() == "miso" else 1

    def n_params(self) -> int:
        """Parameters of one equation."""
        return self.settings.structure.n_params(self.n_blocks())

    def min_rows(self) -> int:
        """Fewest rows of a usable window (default ``2 p``)."""
        given = self.settings.min_rows
        return given if given is not None else 2 * self.n_params()

    def time_step(self) -> float:
        """Seconds per (decimated) sample: ``decimate_to``, else the data's, else 1."""
        s = self.settings
        return s.decimate_to or self.record_dt or s.dt or 1.0

    def kernel_setup(self) -> kernel.KernelSetup:
        """The kernel's plan and settings (fixed per record)."""
        if self.setup is None:
            assert self.n_in is not None and self.n_out is not None
            channels = (self.n_in, self.n_out, self.mode() == "miso")
            self.setup = kernel.record_setup(
                self.settings, channels, self.n_params(), self.min_rows()
            )
        return self.setup

    def trace_labels(self) -> TraceLabels:
        """What the traces of this record say besides the numbers."""
        if self.labels is not None:
            return self.labels
        channels = (self.n_in or 1, self.n_out or 1)
        mode = self.mode() if self.n_in is not None else "siso"
        labels = TraceLabels.of_record(self.settings, channels, self.names, mode, self.time_step())
        if self.n_in is not None:
            self.labels = labels
        return labels

    def empty_trace(self) -> Trace:
        """A trace without updates, shaped for the record's channels (cached once known)."""
        if self.empty is not None:
            return self.empty
        p = self.n_params() if self.n_in is not None else self.settings.structure.n_params()
        empty = self.trace_labels().empty(self.n_out or 1, p)
        if self.n_in is not None:
            self.empty = empty
        return empty
