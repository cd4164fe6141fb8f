"""A record or its arrays: what every function that takes measured ``u, y`` accepts.

``model.simulate(data)``, ``model.predict(data, k=5)``, ``clpc.residual_analysis(model,
data)``, ``clpc.kstep_fit(model, data)``: wherever ``u, y`` are asked for, an
:class:`~clpc.data.IOData` in the place of ``u`` stands for both.
"""

from __future__ import annotations

from typing import Any

from clpc.data.errors import DataError
from clpc.data.iodata import IOData

__all__ = ["signals"]


def signals(u: Any, y: Any = None, *, what: str, needs_y: bool = True) -> tuple[Any, Any]:
    """``(u, y)`` as given, or the arrays of a record of one experiment given as ``u``.

    Parameters
    ----------
    u : IOData or array_like, shape (T,) or (T, n_inputs)
        A record (its ``u`` and ``y``, shapes (T, n_inputs) and (T, n_outputs)), or the
        input samples.
    y : array_like, shape (T,) or (T, n_outputs), optional
        The output samples; required with array inputs when ``needs_y``, refused with a
        record.
    what : str
        The function asking (e.g. ``"predict"``), for messages.
    needs_y : bool
        Whether the function needs the outputs (``simulate`` does not).

    Returns
    -------
    u, y
        The arrays (``y`` is ``None`` when not given and not needed).

    Raises
    ------
    DataError
        A record and ``y`` both, ``y`` missing, or a record of several experiments (the
        caller runs them one by one, or refuses them).
    """
    if isinstance(u, IOData):
        if y is not None:
            raise DataError(
                f"{what}: pass either an IOData or u and y, not both; after an IOData give the "
                "other arguments by keyword (e.g. k=10)."
            )
        if u.n_experiments > 1:
            raise DataError(
                f"{what} takes one experiment; this record holds {u.n_experiments}: pass "
                "them one at a time (data.split())."
            )
        return u.u, u.y
    if y is None and needs_y:
        raise DataError(
            f"{what}: y is missing: pass the measured outputs y with the inputs u, or one "
            "IOData for both."
        )
    return u, y
