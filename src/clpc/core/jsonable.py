"""Numbers to JSON: the one converter that reports, summaries and files use."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

__all__ = ["jsonable"]


def jsonable(x: Any) -> Any:
    """Convert numpy values (recursively) to JSON-safe Python; non-finite floats -> None.

    Mappings become dicts with string keys, arrays and tuples lists, numpy scalars Python
    scalars, complex numbers ``[real, imag]``; anything else is returned as it is.

    Parameters
    ----------
    x : object
        The value (a number, array, mapping, sequence...).

    Returns
    -------
    object
        ``x`` with numpy types replaced, nested containers converted.
    """
    if isinstance(x, Mapping):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        v = float(x)
        return v if math.isfinite(v) else None
    if isinstance(x, complex):
        return [jsonable(x.real), jsonable(x.imag)]
    return x
