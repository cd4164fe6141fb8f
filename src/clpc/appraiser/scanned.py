"""A trace known from its parts: what its summary needs, gathered in one pass.

``clpc track`` appraises a record chunk by chunk and writes every update to a file; keeping
the updates in memory for the summary would make a long record fail for memory.
:class:`ScannedTrace` is fed the same parts and answers what the summary asks of a trace
(:func:`clpc.report.trace_summary`, :func:`clpc.report.steady_state`): the counts, the
findings (:class:`clpc.model.trace_findings.Findings`), the convergence and the
steady-state model (:class:`clpc.appraiser.trace_scan.ScanState`), the last updates for
the report's table. Its memory does not grow with the record: the rows after the
convergence point go to a scratch file for the variations' second pass.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from clpc.appraiser.convergence import (
    Convergence,
    convergence_of,
    model_of,
    no_steady_state,
    normalised,
)
from clpc.appraiser.trace import Trace
from clpc.appraiser.trace_scan import RowSpill, ScanState
from clpc.model import LinearModel
from clpc.model.trace_findings import Findings

__all__ = ["RECENT", "ScannedTrace"]

RECENT = 20  #: updates kept for the report's table of the last updates


class ScannedTrace:
    """The summary's view of a trace fed in parts, in time order (bounded memory).

    Parameters
    ----------
    spill_folder : Path, optional
        Where the scratch file of the rows after the convergence point is made (e.g.
        :func:`tempfile.gettempdir`); ``None`` keeps them in memory.

    Attributes
    ----------
    counts : dict of str to int
        ``updates``, ``accepted``, ``determined``, ``not_enough_data`` (every equation) and
        ``lacking`` (updates with an input-only relation in some equation).
    findings : Findings
        The plain-language findings so far.
    last : Trace or None
        The last :data:`RECENT` updates.
    D_last : ndarray or None
        ``D`` of the last update, shape (n_equations,).
    """

    def __init__(self, spill_folder: Path | None = None) -> None:
        self.state = ScanState(0.02, 0.1, 5, RowSpill(spill_folder))  # Trace.convergence's
        self.findings = Findings()
        self.counts = dict.fromkeys(
            ("updates", "accepted", "determined", "not_enough_data", "lacking"), 0
        )
        self.last: Trace | None = None
        self.D_last: np.ndarray | None = None
        self._labels: Trace | None = None
        self._conv: Convergence | None = None

    @classmethod
    def of(cls, trace: Trace) -> ScannedTrace:
        """A whole in-memory trace, scanned at once (rows after convergence kept in memory)."""
        scanned = cls()
        scanned.add(trace)
        return scanned

    def add(self, part: Trace) -> None:
        """Feed the next updates."""
        if not len(part):
            return
        a = part.arrays
        self.state.add(part)
        self.findings.add(part)
        c = self.counts
        c["updates"] += len(part)
        c["accepted"] += int(a["accepted"].all(axis=1).sum())
        c["determined"] += int(a["determined"].all(axis=1).sum())
        c["not_enough_data"] += int(np.sum(part.not_enough_data))
        c["lacking"] += int((a["n_input_relations"] > 0).any(axis=1).sum())
        self.D_last = a["D"][-1].copy()
        if self._labels is None:  # copies (an index array): the part's memory is let go
            self._labels = part.take(np.arange(len(part) - 1, len(part)))
        recent = (
            part if self.last is None or len(part) >= RECENT else Trace.concat([self.last, part])
        )
        self.last = recent.take(np.arange(max(len(recent) - RECENT, 0), len(recent)))
        self._conv = None

    def __len__(self) -> int:
        return self.counts["updates"]

    def __getattr__(self, name: str) -> Any:
        """The trace's labels: structure, n_inputs, mode, sample_time, names, meta."""
        if name in ("structure", "n_inputs", "mode", "sample_time", "input_names",
                    "output_names", "meta", "n_equations"):  # fmt: skip
            labels = self.__dict__.get("_labels")
            if labels is None:
                raise ValueError("nothing scanned yet: no trace labels")
            return getattr(labels, name)
        raise AttributeError(name)

    def convergence(self) -> Convergence:
        """:meth:`clpc.Trace.convergence` with its default tolerances, over every part."""
        if self._conv is None:
            self._conv = convergence_of(self.state)
        return self._conv

    def steady_state_model(
        self, convergence: Convergence | None = None, *, allow_unconverged: bool = False
    ) -> LinearModel:
        """:meth:`clpc.Trace.steady_state_model` over every part (no window-level warning).

        ``convergence`` must be :meth:`convergence`'s (the sums start at its update).
        """
        conv = self.convergence() if convergence is None else convergence
        st = self.state
        if conv.converged:
            theta, c, used = normalised(st.mean("theta")), st.mean("c"), st.used
            return model_of(self, theta, c, conv, used, None)
        row = st.last_usable if st.n_usable else st.last_model
        if allow_unconverged and row is not None:
            return model_of(self, normalised(row[0]), row[1], conv, 1, None)
        raise no_steady_state(st.n_usable or st.n_model, len(self), conv)

    def close(self) -> None:
        """Remove the scratch file."""
        self.state.spill.close()
