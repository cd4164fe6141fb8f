"""Real measured records shipped with clpc (see ``README.md`` beside this file).

>>> from clpc import datasets
>>> est, val = datasets.load("cascaded_tanks")
>>> est.n_samples, val.n_samples
(1024, 1024)
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from clpc.data import IOData
from clpc.io import Table, read_table

__all__ = ["DATASETS", "Dataset", "load", "names"]

_HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class Dataset:
    """Where a record lives and how its columns split into inputs and outputs.

    Attributes
    ----------
    file : str
        CSV file name, beside this module.
    inputs, outputs : tuple of str
        Column names of the inputs and outputs (of the estimation part).
    dt : float or None
        Sample time [s]; ``None`` when the source gives none (loaded with ``dt = 1``).
    description : str
        One line: the plant and what drives what.
    validation : (tuple of str, tuple of str) or None
        Input and output column names of a separate validation record, if the source
        splits it (default ``None``).
    """

    file: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    dt: float | None
    description: str
    validation: tuple[tuple[str, ...], tuple[str, ...]] | None = None


DATASETS: dict[str, Dataset] = {
    "robot_arm": Dataset(
        "daisy_robot_arm.csv",
        ("u",),
        ("y",),
        None,
        "flexible robot arm: reaction torque -> arm acceleration",
    ),
    "ballbeam": Dataset(
        "daisy_ballbeam.csv", ("u",), ("y",), 0.1, "ball and beam: beam angle -> ball position"
    ),
    "dryer": Dataset(
        "daisy_dryer.csv",
        ("u",),
        ("y",),
        0.08,
        "hair dryer: heater voltage -> outlet air temperature",
    ),
    "cd_player_arm": Dataset(
        "daisy_cd_player_arm.csv",
        ("u1", "u2"),
        ("y1", "y2"),
        None,
        "CD player arm (2x2): actuator forces -> tracking signals",
    ),
    "exchanger": Dataset(
        "daisy_exchanger.csv",
        ("q",),
        ("th",),
        1.0,
        "heat exchanger: liquid flow rate -> outlet temperature",
    ),
    "winding": Dataset(
        "daisy_winding.csv",
        ("u1_S1", "u2_S2", "u3_S3", "u4_I1set", "u5_I3set"),
        ("y1_T1", "y2_T3"),
        0.1,
        "winding process (5x2): reel speeds, currents -> web tensions",
    ),
    "industrial_dryer": Dataset(
        "daisy_industrial_dryer.csv",
        ("u1_fuel", "u2_fan", "u3_material"),
        ("y1_drybulb", "y2_wetbulb", "y3_moisture"),
        10.0,
        "industrial dryer (3x3)",
    ),
    "cascaded_tanks": Dataset(
        "cascaded_tanks.csv",
        ("uEst",),
        ("yEst",),
        4.0,
        "cascaded tanks with overflow: pump voltage -> lower tank level",
        validation=(("uVal",), ("yVal",)),
    ),
}


def names() -> list[str]:
    """Names of the shipped records.

    Returns
    -------
    list of str
        The keys of :data:`DATASETS`, e.g. ``"dryer"``.
    """
    return list(DATASETS)


def path(name: str) -> Path:
    """Path of the CSV file of record ``name``.

    Parameters
    ----------
    name : str
        One of :func:`names`.

    Returns
    -------
    Path
        The CSV file (a header line of column names, then one sample per line).

    Raises
    ------
    KeyError
        An unknown record name (the message lists the known ones).
    """
    return _HERE / _spec(name).file


def _spec(name: str) -> Dataset:
    if name not in DATASETS:
        raise KeyError(f"unknown dataset {name!r}; available: {', '.join(DATASETS)}.")
    return DATASETS[name]


def _block(table: Table, names: tuple[str, ...]) -> np.ndarray:
    """Columns ``names`` of ``table``, shape (n_samples, len(names))."""
    return table.data[:, [table.index(c) for c in names]]


def load(name: str) -> IOData | tuple[IOData, IOData]:
    """Load a shipped record as :class:`~clpc.IOData`.

    Parameters
    ----------
    name : str
        One of :func:`names`.

    Returns
    -------
    IOData or tuple of IOData
        ``u`` of shape (n_samples, n_inputs), ``y`` of shape (n_samples, n_outputs),
        ``dt`` in seconds; ``(estimation, validation)`` for records that come split
        (cascaded_tanks). Records with no sample time given get ``dt = 1`` (frequencies
        per sample).

    Raises
    ------
    KeyError
        An unknown record name (the message lists the known ones).
    """
    spec = _spec(name)
    table = read_table(_HERE / spec.file)

    def pick(ins: tuple[str, ...], outs: tuple[str, ...]) -> IOData:
        return IOData(_block(table, ins), _block(table, outs), spec.dt or 1.0, ins, outs)

    est = pick(spec.inputs, spec.outputs)
    if spec.validation is None:
        return est
    return est, pick(*spec.validation)
