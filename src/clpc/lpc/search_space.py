"""The structures :func:`clpc.identify` screens, and the ones a record is long enough for.

``order="auto"`` screens ``na`` in ``1..max_order`` and ``nb`` in ``0..max_order``
independently (clpc's ``nb``: ``nb + 1`` coefficients per input), ``nk="auto"`` the delays
``0..max_delay``; a given ``order`` fixes ``na = nb = order``, a given ``na`` or ``nb`` fixes
that one. A structure is kept when the shortest fitted part (before the first origin) has
:data:`ROWS_PER_PARAMETER` rows per coefficient and the shortest scored part (after the last
origin) :data:`SCORED_PER_PARAMETER` samples per coefficient after its lags, and when the
record's input excites the order it needs (``na + nb + 1``, :mod:`clpc.model.excitation`)
well: its lag covariance's singular-value ratio at that order at least
:data:`SEARCH_RTOL`. Models the input can hardly tell apart give the same held-out fit and
different plants; on the cascaded tanks (a smooth input, ratio 3e-5 at order 5) an OE
model with 6 numerator coefficients of +-1500 fitted the held-out origins and gave -2262 %
on the validation record. ``SEARCH_RTOL`` is stricter than the verdict's
:data:`~clpc.model.excitation.EXCITATION_RTOL` (1e-5, "not identifiable"), so a chosen
model is never one its own verdict calls unidentifiable (the smallest structure stays when
none qualifies, and its verdict then says so).
An automatic range is cut to what the record supports (the reason says so), a given
structure the record is too short for is an error.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.core.checks import check_int
from clpc.data import DataError, IOData
from clpc.lpc.screen import PARSIMONY, Screen
from clpc.model.excitation import excitation_ratios, needed_order
from clpc.model.structure import Structure

__all__ = [
    "ROWS_PER_PARAMETER",
    "SCORED_PER_PARAMETER",
    "SEARCH_RTOL",
    "SearchSpace",
    "excited_order",
    "search_space",
]

#: Fitted rows per coefficient a structure needs before the first origin.
ROWS_PER_PARAMETER = 4
#: Scored samples per coefficient a structure needs after the last origin (after its lags).
SCORED_PER_PARAMETER = 2
#: Singular-value ratio of the input's lag covariance the search asks at a structure's order.
SEARCH_RTOL = 1e-4


def excited_order(u: Any, max_order: int, experiments: Sequence[int] | None = None) -> int:
    """The largest order ``n <= max_order`` the input excites with ratio >= :data:`SEARCH_RTOL`.

    Parameters
    ----------
    u : array_like, shape (T,) or (T, m)
        The record's inputs (jointly).
    max_order : int
        Largest order checked.
    experiments : sequence of int, optional
        Samples of each experiment.

    Returns
    -------
    int
    """
    ratios = excitation_ratios(u, max_order, experiments)
    return int(np.argmin(np.r_[ratios, 0.0] >= SEARCH_RTOL))


@dataclass(frozen=True)
class SearchSpace:
    """The structures to screen and what was left out.

    Attributes
    ----------
    structures : list of Structure
        Every structure screened.
    ranges : str
        The ranges in words (``"na 1..10, nb 0..10, nk 0..5"``).
    note : str
        Structures left out because the record is too short (empty when none).
    """

    structures: list[Structure]
    ranges: str
    note: str = ""

    def describe(self, scr: Screen, short: list[Structure]) -> str:
        """The structure choice in words: the screen, its pick and the shortlist."""
        best = scr.best()
        s = scr.structures[best]
        top = scr.structures[int(scr.score.argmax())]
        text = (
            f"structures screened: {len(self.structures)} ({self.ranges}) by the held-out "
            f"free run of least squares; the fewest coefficients within {PARSIMONY:g} point "
            f"of the best ({_name(top)}: {scr.score.max():.1f} %) is {_name(s)} "
            f"({scr.score[best]:.1f} %); estimators fitted on {', '.join(map(_name, short))}"
        )
        return text + (f"; {self.note}" if self.note else "")


def _name(s: Structure) -> str:
    """``na=2 nb=1 nk=1``."""
    return f"na={s.na} nb={s.nb} nk={s.nk}"


def _values(given: Any, auto: range, name: str) -> list[int]:
    """``[given]`` or the automatic range."""
    if given is None or given == "auto":
        return list(auto)
    if isinstance(given, str):
        raise ValueError(f"{name} must be an int or 'auto'; got {given!r}.")
    return [check_int(given, name, auto.start)]


def search_space(
    folds: list[tuple[IOData, IOData]],
    given: tuple[Any, Any, Any, Any],
    limits: tuple[int, int],
    blocks: int,
    excited: int | None = None,
) -> SearchSpace:
    """The structures to screen (see the module).

    Parameters
    ----------
    folds : list of (IOData, IOData)
        The (fitted, scored) parts at the origins.
    given : tuple
        ``(order, na, nb, nk)`` as :func:`clpc.identify` takes them.
    limits : tuple of int
        ``(max_order, max_delay)``.
    blocks : int
        Input blocks per output equation (the inputs in ``"miso"`` mode, else 1).
    excited : int, optional
        The order the record's input excites (:func:`excited_order`); ``None``: not
        checked.

    Returns
    -------
    SearchSpace

    Raises
    ------
    DataError
        The record is too short for every structure (or for the one given).
    """
    order, na, nb, nk = given
    max_order = check_int(limits[0], "max_order", 1)
    max_delay = check_int(limits[1], "max_delay", 0)
    if order != "auto":
        order = _values(order, range(1, 2), "order")[0]
        na = order if na is None else na
        nb = order if nb is None else nb
    nas = _values(na, range(1, max_order + 1), "na")
    nbs = _values(nb, range(0, max_order + 1), "nb")
    nks = _values(nk, range(0, max_delay + 1), "nk")
    n_fit = min(f.n_samples for f, _ in folds)
    n_val = min(v.n_samples for _, v in folds)
    every = [Structure(a, b, d) for d in nks for a in nas for b in nbs]

    def fits(s: Structure) -> bool:
        p = s.na + blocks * (s.nb + 1) + 1
        return (
            n_fit - s.max_lag >= ROWS_PER_PARAMETER * p
            and n_val - s.max_lag >= SCORED_PER_PARAMETER * p
        )

    kept = [s for s in every if fits(s)]
    ranges = f"na {_span(nas)}, nb {_span(nbs)}, nk {_span(nks)}"
    if not kept:
        small = min(every, key=lambda s: (s.na + blocks * (s.nb + 1), s.max_lag))
        p = small.na + blocks * (small.nb + 1) + 1
        raise DataError(
            f"identify needs at least {ROWS_PER_PARAMETER * p + small.max_lag} samples before "
            f"the first origin and {SCORED_PER_PARAMETER * p + small.max_lag} after the last "
            f"for its smallest structure ({_name(small)}, {blocks} input block(s)); got "
            f"{n_fit} and {n_val}. Use a longer record, a lower order or delay, or a larger "
            "validation_fraction."
        )
    notes = []
    if len(kept) < len(every):
        notes.append(
            f"{len(every) - len(kept)} larger structures skipped: the record is too short "
            f"for them ({n_fit} samples before the first origin, {n_val} after the last; "
            f"{ROWS_PER_PARAMETER} rows per coefficient needed)"
        )
    if excited is not None:
        decided = [s for s in kept if needed_order(s) <= excited]
        if len(decided) < len(kept):
            smallest = min(kept, key=lambda s: (needed_order(s), s.max_lag))
            notes.append(
                f"{len(kept) - len(decided)} structures skipped: the input excites order "
                f"{excited} only (singular-value ratio >= {SEARCH_RTOL:g}) and they need "
                "more (na + nb + 1)"
            )
            kept = decided or [smallest]
    return SearchSpace(kept, ranges, "; ".join(notes))


def _span(values: list[int]) -> str:
    """``1..10`` or ``2``."""
    return f"{values[0]}..{values[-1]}" if len(values) > 1 else str(values[0])
