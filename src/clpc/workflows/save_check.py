"""Whether ``clpc track --save`` may save the model a trace settles on.

A steady-state model is refused when a pole lies beyond the unit circle by more than
:data:`clpc.core.polynomials.UNIT_CIRCLE_TOL` (an integrator within it is a model, a pole at
1.41 is not: a drive record's input-only windows once averaged to poles 1.41 and 1.03 for a
plant at ``0.97 +- 0.05j``). The refusal is one line with the numbers; the caller exits
non-zero and saves nothing.
"""

from __future__ import annotations

import numpy as np

from clpc.core.polynomials import UNIT_CIRCLE_TOL
from clpc.model import LinearModel

__all__ = ["save_refusal"]


def save_refusal(model: LinearModel, path: str) -> str | None:
    """Why ``model`` is not saved to ``path``, in one line; ``None`` when it may be.

    Parameters
    ----------
    model : LinearModel
        The steady-state model of a trace.
    path : str
        Where it was to be saved (named in the message).

    Returns
    -------
    str or None
        The refusal, naming the largest pole magnitude per output and the limit
        ``1 + UNIT_CIRCLE_TOL``; ``None`` when every pole is within it.
    """
    limit = 1.0 + UNIT_CIRCLE_TOL
    worst = []
    for j in range(model.n_outputs):
        poles = np.asarray(model.poles(j))
        size = float(np.max(np.abs(poles))) if poles.size else 0.0
        if not size <= limit:
            shown = ", ".join(f"{abs(p):.3g}" for p in poles)
            worst.append(f"{model.output_names[j]}: |poles| {shown}")
    if not worst:
        return None
    return (
        f"not saved to {path}: the steady-state model is unstable ({'; '.join(worst)}; "
        f"limit 1 + UNIT_CIRCLE_TOL = {limit:g}); the trace and the report were written - "
        "see the findings above, or fit the whole record with clpc identify."
    )
