"""Where a report's figures are drawn: one after the other here, or handed out at once.

A report's figures are independent of each other (each a function of the trace, the model
or the data, writing its own file), so a caller with spare processes can draw them at the
same time. :class:`Drawing` takes each figure's call; without ``submit`` it draws it at
once in this process, with ``submit`` (``submit(function, *args, **kwargs)`` returning a
future with ``result()``: :meth:`concurrent.futures.Executor.submit`, or
:class:`clpc.distributed.cluster_submit.ClusterSubmit` for a Dask cluster's workers) it
hands it over; :meth:`Drawing.wait` returns when every figure is written (and raises the
first figure's error), so the report page is written after its figures, as before.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["Drawing"]


class Drawing:
    """The figures of one report: drawn here at once, or submitted and awaited together.

    Parameters
    ----------
    submit : callable, optional
        ``submit(function, *args, **kwargs) -> future``; ``None`` draws in this process.
    """

    def __init__(self, submit: Callable[..., Any] | None = None) -> None:
        self.submit = submit
        self.pending: list[Any] = []

    def __call__(self, function: Callable[..., Any], *args: Any, **kwargs: Any) -> None:
        """Draw a figure: ``function(*args, **kwargs)``, here or where ``submit`` runs it."""
        if self.submit is None:
            function(*args, **kwargs)
        else:
            self.pending.append(self.submit(function, *args, **kwargs))

    def wait(self) -> None:
        """Until every submitted figure is drawn; a figure's error is raised here."""
        pending, self.pending = self.pending, []
        for future in pending:
            future.result()
