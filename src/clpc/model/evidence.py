"""Evidence on demand: what a fit's verdict cites, computed when first read, once.

A fit returns its estimate and what comes free with the solve (eigenvalues, ``D``, ``J``,
``c``, a least-squares covariance). The costlier evidence - the held-out fit of a refit on
part of the record, the residual tests, a block-jackknife covariance, the input's order of
persistent excitation - is computed only when a caller reads it: ``model.info["heldout"]``,
``model.info["residual_test"]``, ``model.info["covariance"]``,
``model.info["excitation_order"]`` (or :meth:`clpc.LinearModel.assess` for all of it). The
result is stored in the model's ``info``, so the second read costs nothing.

The model keeps a :class:`FitRecord`, the record it was fitted on and one function per kind
of evidence; :class:`FitInfo` is its ``info``, a ``dict`` whose missing evidence keys are
produced by those functions for that very model. A model made from another one with
``dataclasses.replace`` keeps the record and gets producers of its own, so its evidence
is computed for its own coefficients (entries computed for other coefficients are dropped,
to be computed again when read).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from clpc.model.display import squeeze_info

__all__ = ["EVIDENCE_KEYS", "FitInfo", "FitRecord"]

#: A producer: the model in, the ``info`` entries it computes out.
Producer = Callable[[Any], dict[str, Any]]

#: The ``info`` keys each kind of evidence fills (a producer may leave some out, e.g. a
#: jackknife that cannot run sets ``covariance_note`` only).
EVIDENCE_KEYS: dict[str, tuple[str, ...]] = {
    "assessment": ("heldout", "residual_test"),
    "covariance": ("covariance", "covariance_dof", "covariance_method", "covariance_note"),
    "excitation": (
        "excitation_order",
        "excitation_needed",
        "excitation_ratio",
        "excitation_threshold",
        "output_std",
        "input_std",
    ),
}


@dataclass(frozen=True)
class FitRecord:
    """The record a model was fitted on and how to compute its evidence.

    Parameters
    ----------
    data : IOData
        The record (kept by reference; no copy).
    producers : mapping of str to callable
        Kind of evidence (a key of :data:`EVIDENCE_KEYS`) to a function ``f(model) ->
        dict`` returning those ``info`` entries for ``model``.
    """

    data: Any
    producers: Mapping[str, Producer] = field(default_factory=dict)

    def with_producer(self, kind: str, producer: Producer) -> FitRecord:
        """A copy that also computes ``kind`` with ``producer``."""
        if kind not in EVIDENCE_KEYS:
            raise ValueError(f"kind must be one of {sorted(EVIDENCE_KEYS)}; got {kind!r}.")
        return FitRecord(self.data, {**self.producers, kind: producer})


class FitInfo(dict[str, Any]):
    """A model's ``info``: a ``dict`` whose evidence entries are computed on first read.

    Parameters
    ----------
    entries : mapping
        The statistics already known (a copy is stored).
    model : LinearModel
        The model the evidence is computed for.
    record : FitRecord
        The record and the producers.
    source : mapping, optional
        Where ``entries`` came from (default: ``entries``): a :class:`FitInfo` of other
        coefficients gives no evidence entries.

    Notes
    -----
    Reading a pending key (``info[key]``, ``info.get(key)``, ``key in info``) runs its
    producer once and stores every entry it returns. Iteration, ``len`` and copies see
    only the entries computed so far; :meth:`compute_all` computes the rest.
    """

    def __init__(
        self,
        entries: Mapping[str, Any],
        model: Any,
        record: FitRecord,
        source: Mapping[str, Any] | None = None,
    ) -> None:
        source = entries if source is None else source
        if isinstance(source, FitInfo) and not source.describes(model):
            # evidence of other coefficients: computed again, for these, when read
            stale = {key for kind in record.producers for key in EVIDENCE_KEYS[kind]}
            entries = {key: value for key, value in entries.items() if key not in stale}
        super().__init__(entries)
        self._model = model
        self._pending = {
            kind: producer
            for kind, producer in record.producers.items()
            if not any(key in entries for key in EVIDENCE_KEYS[kind])
        }

    def _kind_of(self, key: object) -> str | None:
        for kind in self._pending:
            if key in EVIDENCE_KEYS[kind]:
                return kind
        return None

    def _produce(self, kind: str) -> None:
        entries = self._pending[kind](self._model)  # a producer that raises stays pending
        del self._pending[kind]
        if self._model.n_outputs == 1:  # as the model's own statistics (LinearModel)
            entries = squeeze_info(entries)
        self.update(entries)

    def __missing__(self, key: str) -> Any:
        kind = self._kind_of(key)
        if kind is None:
            raise KeyError(key)
        self._produce(kind)
        return dict.__getitem__(self, key)

    def get(self, key: str, default: Any = None) -> Any:
        """``self[key]`` when present or computable, else ``default``."""
        try:
            return self[key]
        except KeyError:
            return default

    def __contains__(self, key: object) -> bool:
        if dict.__contains__(self, key):
            return True
        kind = self._kind_of(key)
        if kind is None:
            return False
        self._produce(kind)
        return dict.__contains__(self, key)

    def describes(self, model: Any) -> bool:
        """Whether these entries were computed for ``model``'s coefficients."""
        mine = self._model
        return mine is model or (
            mine.structure == model.structure
            and np.array_equal(mine.theta_matrix, model.theta_matrix)
            and np.array_equal(mine.c, model.c)
        )

    @property
    def pending(self) -> tuple[str, ...]:
        """The kinds of evidence not computed yet."""
        return tuple(self._pending)

    def compute_all(self, kinds: Iterable[str] | None = None) -> None:
        """Compute every pending kind of evidence (or only ``kinds``)."""
        for kind in list(self._pending if kinds is None else kinds):
            if kind in self._pending:
                self._produce(kind)

    def __reduce__(self) -> Any:
        """Pickle as a plain ``dict`` of the entries computed so far."""
        return (dict, (dict(self),))
