"""Identifiability: what a record cannot decide about a fitted model, in numbers and words.

Two findings, each with its number and its threshold, lead a fit's verdict when they fail
(:func:`clpc.model.verdict.fit_verdict`, :func:`identifiability`):

* **Excitation** (:mod:`clpc.model.excitation`): the record's input is persistently
  exciting of a lower order than the structure needs (``na + nb + 1``); the order is
  measured once per fit and kept in ``info["excitation_order"]`` (evidence on demand).
* **The DC gain** (:mod:`clpc.model.gain`): a gain whose standard deviation exceeds its
  size (and a share of the record's scale), or any gain of an input that does not excite
  the order: the data do not decide it.

:func:`assess_gain` and :func:`gain_uncertainty` are re-exported from
:mod:`clpc.model.gain`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from clpc.model.errors import ModelError
from clpc.model.excitation import EXCITATION_RTOL, needed_order, stored_excitation
from clpc.model.gain import (
    GAIN_SCALE_FRACTION,
    GAIN_SIGMAS,
    GainAssessment,
    assess_gain,
    gain_uncertainty,
)

__all__ = [
    "GAIN_SCALE_FRACTION",
    "GAIN_SIGMAS",
    "GainAssessment",
    "Identifiability",
    "assess_gain",
    "gain_uncertainty",
    "identifiability",
]


@dataclass(frozen=True)
class Identifiability:
    """What the record decides about one output's equation.

    Attributes
    ----------
    output : str
        The output's name.
    excitation_order : int or None
        The input's order of persistent excitation, up to ``needed_order``
        (``info["excitation_order"]``; ``None``: the model keeps no record).
    needed_order : int
        ``na + nb + 1`` (:func:`clpc.model.excitation.needed_order`).
    excitation_ratio : float or None
        Singular-value ratio of the input's ``needed_order``-lag covariance.
    threshold : float
        The ratio's threshold (:data:`clpc.model.excitation.EXCITATION_RTOL`).
    gains : tuple of GainAssessment
        This output's DC gains.
    """

    output: str
    excitation_order: int | None
    needed_order: int
    excitation_ratio: float | None
    threshold: float
    gains: tuple[GainAssessment, ...]

    @property
    def excited(self) -> bool | None:
        """The input is PE of the needed order (``None``: not measured)."""
        order = self.excitation_order
        return None if order is None else order >= self.needed_order

    @property
    def identifiable(self) -> bool | None:
        """``False`` when a finding fails, ``None`` when nothing could be judged, else ``True``.

        Judged: the excitation (the model keeps its record) or a gain's sigma.
        """
        if self.excited is False or any(g.determined is False for g in self.gains):
            return False
        judged = self.excited is not None or any(g.determined for g in self.gains)
        return True if judged else None

    def messages(self, structure: Any) -> list[str]:
        """The findings, each with its number and threshold; empty when identifiable.

        Parameters
        ----------
        structure : Structure
            The model's orders (named in the excitation finding).

        Returns
        -------
        list of str
            A headline (``"NOT identifiable from this record: ..."``), then one line per
            finding.
        """
        if self.identifiable is not False:
            return []
        heads, lines = [], []
        if self.excited is False:
            n, o = self.needed_order, self.excitation_order
            heads.append(f"input persistently exciting of order {o} only, needs {n}")
            lines.append(
                f"input not persistently exciting of order {n} (na + nb + 1 = {structure.na} "
                f"+ {structure.nb} + 1): it excites order {o}; its {n}-lag covariance has "
                f"singular-value ratio {self.excitation_ratio:.2g} < {self.threshold:g} - "
                "lower the order or excite more frequencies"
            )
        for g in self.gains:
            if g.determined is False:
                heads.append(f"DC gain {g.input} -> {g.output} undetermined ({g.value})")
                lines.append(g.finding())
        return ["NOT identifiable from this record: " + "; ".join(heads), *lines]


def identifiability(model: Any, output: int = 0) -> Identifiability:
    """The identifiability findings of one output's equation (excitation, DC gains).

    Parameters
    ----------
    model : LinearModel
        A fitted model: the excitation is read from ``info["excitation_order"]`` (computed
        from the record a clpc fit keeps), the gains' sigma from ``info["covariance"]``.
    output : int
        Output index (default 0).

    Returns
    -------
    Identifiability
    """
    info = model.info
    try:
        gains = tuple(g for g in assess_gain(model) if g.output_index == output)
    except ModelError:  # no monic form (a0 about 0): the verdict says so by its stability
        gains = ()
    pe = stored_excitation(info, output)
    if pe is None:
        return Identifiability(
            model.output_names[output], None, needed_order(model.structure), None,
            EXCITATION_RTOL, gains,
        )  # fmt: skip
    return Identifiability(model.output_names[output], pe[0], pe[1], pe[2], pe[3], gains)
