"""The file methods of :class:`clpc.MultiModel`: its JSON form, saved and loaded.

A base class of :class:`clpc.MultiModel`; the format is :mod:`clpc.multimodel.store`'s.
"""

from __future__ import annotations

from typing import Any, Self

from clpc.multimodel import store
from clpc.multimodel.fitting import Fitted

__all__ = ["ModelFiles"]


class ModelFiles:
    """``to_dict``, ``from_dict``, ``save`` and ``load`` of a multi-model."""

    _fitted: Fitted | None
    n_inputs: int
    dt: float

    def install_fit(self, fitted: Fitted, n_inputs: int, dt: float) -> Self:
        """Take a fit made elsewhere (a file read by :func:`clpc.multimodel.store.from_dict`).

        Parameters
        ----------
        fitted : Fitted
            Local models, centres, widths and diagnostics, already checked.
        n_inputs : int
            Inputs of the local models.
        dt : float
            Sample time [s].

        Returns
        -------
        MultiModel
            ``self``, fitted.
        """
        self.n_inputs, self.dt, self._fitted = int(n_inputs), float(dt), fitted
        return self

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe description (floats exact); see :mod:`clpc.multimodel.store`."""
        return store.to_dict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Self:
        """Rebuild a multi-model from :meth:`to_dict` output.

        Parameters
        ----------
        data : dict
            The description; its ``format`` and ``version`` are checked.

        Returns
        -------
        MultiModel
        """
        return store.from_dict(cls, data)

    def save(self, path: Any) -> None:
        """Write :meth:`to_dict` as JSON to ``path``.

        Parameters
        ----------
        path : str or path-like
            File to write (UTF-8; replaced if it exists).
        """
        store.save(self, path)

    @classmethod
    def load(cls, path: Any) -> Self:
        """Read a multi-model written by :meth:`save`.

        Parameters
        ----------
        path : str or path-like
            JSON file written by :meth:`save`.

        Returns
        -------
        MultiModel
        """
        return store.load(cls, path)
