"""The shipped records (``clpc datasets``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from clpc import datasets as _datasets
from clpc.core.compact import compact_repr

__all__ = ["DatasetEntry", "list_datasets"]


@compact_repr
@dataclass(frozen=True)
class DatasetEntry:
    """One shipped record (see :mod:`clpc.datasets`).

    Attributes
    ----------
    name, description : str
        Its key in :data:`clpc.datasets.DATASETS` and what it is.
    inputs, outputs : list of str
        Estimation columns.
    dt : float or None
        Sample time [s], when the source gives one.
    path : str
        The CSV file.
    validation_inputs, validation_outputs : list of str or None
        Validation columns, when the record has them.
    """

    name: str
    inputs: list[str]
    outputs: list[str]
    dt: float | None
    description: str
    path: str
    validation_inputs: list[str] | None = None
    validation_outputs: list[str] | None = None

    def to_dict(self) -> dict[str, Any]:
        """The entry as JSON fields (the validation columns only when there are some).

        Returns
        -------
        dict
            ``name``, ``inputs``, ``outputs``, ``dt``, ``description``, ``path`` [,
            ``validation_inputs``, ``validation_outputs``].
        """
        row: dict[str, Any] = {
            "name": self.name,
            "inputs": self.inputs,
            "outputs": self.outputs,
            "dt": self.dt,
            "description": self.description,
            "path": self.path,
        }
        if self.validation_inputs is not None:
            row["validation_inputs"] = self.validation_inputs
            row["validation_outputs"] = self.validation_outputs
        return row


def list_datasets() -> list[DatasetEntry]:
    """The real measured records shipped with clpc.

    Returns
    -------
    list of DatasetEntry
        One entry per record, in the order of :data:`clpc.datasets.DATASETS`.
    """
    entries = []
    for name, spec in _datasets.DATASETS.items():
        validation = spec.validation
        entries.append(
            DatasetEntry(
                name=name,
                inputs=list(spec.inputs),
                outputs=list(spec.outputs),
                dt=spec.dt,
                description=spec.description,
                path=str(_datasets.path(name)),
                validation_inputs=None if validation is None else list(validation[0]),
                validation_outputs=None if validation is None else list(validation[1]),
            )
        )
    return entries
