"""How the traces of one record are made: the labels they carry and their empty arrays.

:class:`TraceLabels` is what a trace says about its appraiser besides the numbers (fixed per
record once its channels are known, :meth:`clpc.appraiser.state.AppraiserState.trace_labels`);
:func:`empty_arrays` the arrays of a trace without updates.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.appraiser.settings import Settings
from clpc.appraiser.trace import Trace
from clpc.appraiser.trace_table import PER_EQUATION
from clpc.model.structure import Structure

__all__ = ["TraceLabels", "empty_arrays"]


@dataclass(frozen=True)
class TraceLabels:
    """What a trace says about its appraiser besides the numbers."""

    structure: Structure
    n_inputs: int
    mode: str
    sample_time: float
    names: tuple[tuple[str, ...], tuple[str, ...]]
    meta: dict[str, Any]

    @classmethod
    def of_record(
        cls,
        settings: Settings,
        channels: tuple[int, int],
        names: tuple[tuple[str, ...], tuple[str, ...]] | None,
        mode: str,
        sample_time: float,
    ) -> TraceLabels:
        """The labels of a record's traces.

        Parameters
        ----------
        settings : Settings
            The appraiser's settings (structure; ``guard``, ``method``, ``scaling`` in ``meta``).
        channels : (int, int)
            Inputs and outputs.
        names : ((str, ...), (str, ...)) or None
            Channel names (``None``: ``u``, ``y`` or ``u0``, ``u1``, ... ``y0``, ...).
        mode : {"siso", "paired", "miso"}
            How outputs relate to inputs.
        sample_time : float
            The appraiser's sample time [s].
        """
        n_in, n_out = channels
        names = names or (
            tuple(f"u{i}" for i in range(n_in)) if n_in > 1 else ("u",),
            tuple(f"y{i}" for i in range(n_out)) if n_out > 1 else ("y",),
        )
        return cls(
            structure=settings.structure,
            n_inputs=n_in,
            mode=mode,
            sample_time=sample_time,
            names=names,
            meta={"guard": settings.guard, "method": settings.method, "scaling": settings.scaling},
        )

    def empty(self, n_equations: int, p: int) -> Trace:
        """A trace without updates: ``n_equations`` equations of ``p`` parameters."""
        z = np.zeros(0, dtype=np.int64)
        return self.trace(z, z, empty_arrays(n_equations, p, self.structure, self.n_inputs))

    def trace(self, index: np.ndarray, rows: np.ndarray, arrays: dict[str, np.ndarray]) -> Trace:
        """A trace of updates ending at samples ``index`` with ``rows`` lag vectors each."""
        index = np.asarray(index, dtype=np.int64)
        return Trace.of(
            {
                "index": index,
                "time": index * self.sample_time,
                "rows": np.asarray(rows, dtype=np.int64),
                "not_enough_data": arrays.pop("not_enough"),
                "arrays": arrays,
                "structure": self.structure,
                "n_inputs": self.n_inputs,
                "mode": self.mode,
                "sample_time": self.sample_time,
                "input_names": self.names[0],
                "output_names": self.names[1],
                "meta": dict(self.meta),
            }
        )


def empty_arrays(
    n_equations: int, p: int, structure: Structure, n_inputs: int
) -> dict[str, np.ndarray]:
    """Zero-row per-equation arrays of the right shapes and types (an empty trace)."""
    s = structure
    shapes = {
        "theta": (p,),
        "theta_estimate": (p,),
        "den": (s.na + 1,),
        "num": (n_inputs, s.nk + s.nb + 1),
        "eigenvalues": (p,),
    }
    ints = ("n_null", "n_input_relations")
    bools = ("degenerate", "determined", "excited", "trusted", "accepted", "has_model", "stable")
    arrays: dict[str, np.ndarray] = {}
    for key in PER_EQUATION:
        dtype = np.int64 if key in ints else (np.bool_ if key in bools else np.float64)
        arrays[key] = np.zeros((0, n_equations, *shapes.get(key, ())), dtype=dtype)
    arrays["not_enough"] = np.zeros(0, dtype=np.bool_)
    return arrays
