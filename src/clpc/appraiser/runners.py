"""Runners of records that are not arrays in memory, registered by the layers above.

:func:`register_runner` lets a higher layer (:mod:`clpc.distributed.long_record`, for a
``dask.array`` record) take over :meth:`clpc.CLPC.run` for the records it accepts;
:func:`runner_for` is the runner ``run`` hands a record to (the first that accepts it).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from clpc.appraiser.trace import Trace

__all__ = ["register_runner", "runner_for"]

#: ``(accepts(x), run(appraiser, u, y, dt))`` in the order they were registered
_RUNNERS: list[tuple[Callable[[Any], bool], Callable[..., Trace]]] = []


def register_runner(accepts: Callable[[Any], bool], run: Callable[..., Trace]) -> None:
    """Let :meth:`CLPC.run` hand records that ``accepts`` to ``run(appraiser, u, y, dt)``.

    Parameters
    ----------
    accepts : callable
        ``accepts(u_or_y)``: whether the runner takes this record.
    run : callable
        ``run(appraiser, u, y, dt)``, returning the :class:`Trace` ``run`` would return.
    """
    if (accepts, run) not in _RUNNERS:
        _RUNNERS.append((accepts, run))


def runner_for(u: Any, y: Any) -> Callable[..., Trace] | None:
    """The first registered runner that accepts ``u`` or ``y`` (``None``: an array record).

    Parameters
    ----------
    u, y : object
        What :meth:`CLPC.run` was given.
    """
    for accepts, run in _RUNNERS:
        if accepts(u) or accepts(y):
            return run
    return None
