"""The appraiser's state file: its saved form as JSON, written atomically, read with a bound.

:func:`write_state` and :func:`read_state` write and read what
:func:`clpc.appraiser.saved_state.saved_form` returns; :class:`StateFile`, a base class of
:class:`clpc.CLPC`, gives it ``save`` and ``load`` over its ``state_dict`` and
``from_state_dict``.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any, Self

from clpc.appraiser.state_schema import MAX_STATE_BYTES, parse_json
from clpc.core.atomic import atomic_file

__all__ = ["StateFile", "read_state", "write_state"]


def write_state(path: str, saved: dict[str, Any]) -> None:
    """Write a saved state as JSON to ``path``, atomically (:func:`clpc.core.atomic.atomic_file`).

    Parameters
    ----------
    path : str
        Destination file (replaced if it exists; left as it was if writing fails).
    saved : dict
        What :func:`~clpc.appraiser.saved_state.saved_form` returned.
    """
    with atomic_file(path) as fh:
        json.dump(saved, fh)


def read_state(path: str) -> dict[str, Any]:
    """The saved state in the JSON file ``path`` (at most ``MAX_STATE_BYTES`` are read).

    Parameters
    ----------
    path : str
        A file written by :func:`write_state`.
    """
    with open(path, encoding="utf-8") as fh:
        text = fh.read(MAX_STATE_BYTES + 1)
    return parse_json(text)


class StateFile:
    """``save`` and ``load`` of an appraiser (its class gives the two methods below)."""

    if TYPE_CHECKING:

        def state_dict(self) -> dict[str, Any]:
            """The state as a JSON-safe dict (:func:`~clpc.appraiser.saved_state.saved_form`)."""

        @classmethod
        def from_state_dict(cls, state: dict[str, Any]) -> Self:
            """The appraiser that ``state`` (:meth:`state_dict`'s output) describes."""

    def save(self, path: str) -> None:
        """Write :meth:`state_dict` as JSON to ``path``, atomically.

        The state is written to a temporary file beside ``path`` and renamed over it, so a
        run killed while saving leaves the previous state file whole.

        Parameters
        ----------
        path : str
            Destination file (replaced if it exists).

        Raises
        ------
        clpc.core.atomic.OutputError
            ``path`` is a symbolic link, or writing failed (``path`` is left as it was).
        """
        write_state(path, self.state_dict())

    @classmethod
    def load(cls, path: str) -> Self:
        """Read an appraiser saved with :meth:`save`.

        Parameters
        ----------
        path : str
            A file written by :meth:`save`.

        Returns
        -------
        CLPC
            The appraiser, continuing where the saved one stopped.
        """
        return cls.from_state_dict(read_state(path))
