"""The scheduling variable ``psi(n)`` of a multi-model: which signal selects the local model.

Specifications (``MultiModel(schedule=...)``):

* ``"y"`` (default): the previous output ``y(n-1)``;
* ``"u"``: the current input ``u(n)`` (first input);
* an int ``j >= 1``: column ``j`` of the lag vector ``z_n`` (``y(n-j)`` for ``j <= na``, then
  the input lags in the order of :func:`clpc.lpc.regressors.miso_regressor`); column 0 is
  ``y(n)`` itself, which is not known when ``y(n)`` is predicted;
* a callable ``f(u, y_prev) -> psi``: ``u`` of shape (T, n_inputs) holds ``u(n)``,
  ``y_prev`` (shape (T,)) holds ``y(n-1)``; it must work elementwise on arrays. A free run
  with a callable is a Python loop (slow for long records) and cannot be saved to JSON.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.model.structure import Structure

__all__ = ["Schedule", "parse_schedule"]


@dataclass(frozen=True)
class Schedule:
    """A parsed scheduling variable: ``code = (kind, channel, lag)`` or a callable.

    ``kind`` 0: ``y(n - lag)``; 1: ``u_channel(n - lag)``; 2: ``func(u(n), y(n-1))``.
    """

    spec: Any
    kind: int
    channel: int
    lag: int
    label: str
    func: Callable[..., Any] | None = None

    @property
    def code(self) -> tuple[int, int, int]:
        """``(kind, channel, lag)`` for the compiled free run."""
        return self.kind, self.channel, self.lag

    def values(self, u: np.ndarray, y: np.ndarray) -> np.ndarray:
        """``psi(n)`` for every sample, shape (T,); NaN where it does not exist yet."""
        psi = np.full(y.shape[0], np.nan)
        if self.kind == 2:
            assert self.func is not None
            out = np.asarray(self.func(u[1:], y[:-1]), dtype=np.float64).reshape(-1)
            if out.shape[0] != y.shape[0] - 1:
                raise ValueError(
                    f"the schedule callable must return one value per sample; got "
                    f"{out.shape[0]} for {y.shape[0] - 1} samples."
                )
            psi[1:] = out
        elif self.kind == 0:
            psi[self.lag :] = y[: y.shape[0] - self.lag]
        else:
            psi[self.lag :] = u[: u.shape[0] - self.lag, self.channel]
        return psi


def parse_schedule(spec: Any, structure: Structure, n_inputs: int) -> Schedule:
    """Check and parse a schedule specification (see the module); raise ValueError if bad."""
    if callable(spec):
        return Schedule(spec, 2, 0, 1, getattr(spec, "__name__", "callable"), spec)
    if spec == "y":
        return Schedule(spec, 0, 0, 1, "y(n-1)")
    if spec == "u":
        return Schedule(spec, 1, 0, 0, "u(n)")
    if isinstance(spec, (int, np.integer)) and not isinstance(spec, bool):
        j = int(spec)
        na1, nb1 = structure.na + 1, structure.nb + 1
        if 1 <= j <= structure.na:
            return Schedule(j, 0, 0, j, f"y(n-{j})")
        if na1 <= j < na1 + n_inputs * nb1:
            c, lag = divmod(j - na1, nb1)
            lag += structure.nk
            return Schedule(j, 1, c, lag, f"u{c}(n-{lag})" if n_inputs > 1 else f"u(n-{lag})")
    last = structure.na + (structure.nb + 1) * n_inputs
    raise ValueError(
        f"schedule must be 'y' (y(n-1)), 'u' (u(n)), a lag-vector column 1..{last} or a "
        f"callable f(u, y_prev); got {spec!r}."
    )
