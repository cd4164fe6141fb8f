"""The model's structure: orders ``na``, ``nb``, input delay ``nk`` and the MIMO mode.

* ``na`` - output lags: ``y(n), y(n-1), ..., y(n-na)``  (``na + 1`` columns);
* ``nb`` - input lags after the delay: ``u(n-nk), ..., u(n-nk-nb)`` (``nb + 1`` columns);
* ``nk`` - input delay in samples (``nk = 0`` keeps ``b0``, the paper's choice).

The paper's order ``N`` is ``na = nb = N, nk = 0``; its ``parameters_size`` is ``N + 1``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from clpc.core.checks import check_int
from clpc.data import DataError

__all__ = [
    "MimoMode",
    "Structure",
    "check_mode",
    "column_labels",
    "default_mode",
    "input_blocks",
]

MimoMode = Literal["siso", "paired", "miso"]


@dataclass(frozen=True)
class Structure:
    """Orders and delay of a linear difference equation ``A(q) y + B(q) u = r``.

    Parameters
    ----------
    na : int
        Output order (>= 1): ``a0 .. a_na``.
    nb : int
        Input order (>= 0): ``b0 .. b_nb``.
    nk : int
        Input delay in samples (>= 0): ``b0`` multiplies ``u(n - nk)``.
    """

    na: int
    nb: int
    nk: int = 0

    def __post_init__(self) -> None:
        check_int(self.na, "na", 1)
        check_int(self.nb, "nb", 0)
        check_int(self.nk, "nk", 0)

    @classmethod
    def from_order(cls, order: int, nk: int = 0) -> Structure:
        """The paper's structure: ``na = nb = order``.

        Parameters
        ----------
        order : int
            The paper's order ``N`` (>= 1).
        nk : int
            Input delay in samples (>= 0, default 0).

        Returns
        -------
        Structure
        """
        order = check_int(order, "order", 1)
        return cls(order, order, nk)

    @classmethod
    def from_settings(
        cls, order: int, na: int | None = None, nb: int | None = None, nk: int = 0
    ) -> Structure:
        """``na = nb = order`` unless ``na``/``nb`` are given (estimator settings).

        Parameters
        ----------
        order : int
            Order used for whichever of ``na``, ``nb`` is not given.
        na : int, optional
            Output order (>= 1).
        nb : int, optional
            Input order (>= 0).
        nk : int
            Input delay in samples (>= 0, default 0).

        Returns
        -------
        Structure
        """
        if na is None and nb is None:
            return cls.from_order(order, nk)
        return cls(order if na is None else na, order if nb is None else nb, nk)

    @property
    def max_lag(self) -> int:
        """Largest lag used: the first sample index with a complete lag vector."""
        return max(self.na, self.nk + self.nb)

    def n_params(self, n_inputs: int = 1) -> int:
        """Length of ``theta = [a; b_1; ...; b_m]`` for ``n_inputs`` inputs.

        Parameters
        ----------
        n_inputs : int
            Number of input blocks ``m`` in one equation (default 1).

        Returns
        -------
        int
            ``na + 1 + n_inputs (nb + 1)``.
        """
        return self.na + 1 + n_inputs * (self.nb + 1)

    def n_rows(self, n_samples: int) -> int:
        """Number of lag vectors in a record of ``n_samples`` samples.

        Parameters
        ----------
        n_samples : int
            Samples in the record (one experiment).

        Returns
        -------
        int
            ``max(n_samples - max_lag, 0)``.
        """
        return max(n_samples - self.max_lag, 0)


def check_mode(mode: str, n_inputs: int, n_outputs: int) -> None:
    """Raise a clear error when ``mode`` does not fit the channel counts."""
    if mode not in ("siso", "paired", "miso"):
        raise ValueError(f"mimo mode must be 'siso', 'paired' or 'miso'; got {mode!r}.")
    if mode == "siso" and (n_inputs != 1 or n_outputs != 1):
        raise DataError(
            f"mode 'siso' needs one input and one output; got {n_inputs} input(s) and "
            f"{n_outputs} output(s). Use mimo='paired' or mimo='miso'."
        )
    if mode == "paired" and n_inputs != n_outputs:
        raise DataError(
            f"mode 'paired' (paper eqs. 35-38) needs as many inputs as outputs; got "
            f"{n_inputs} input(s) and {n_outputs} output(s). Use mimo='miso'."
        )


def default_mode(n_inputs: int, n_outputs: int) -> MimoMode:
    """``"siso"`` for one input and one output, otherwise ``"miso"``."""
    return "siso" if n_inputs == 1 and n_outputs == 1 else "miso"


def input_blocks(mode: str, n_inputs: int) -> int:
    """Input blocks of one lag vector: every input for ``"miso"``, one otherwise.

    The one place this rule lives: ``"miso"`` puts every input's lags in each equation's lag
    vector; ``"siso"`` and ``"paired"`` (the paper's eqs. 35-38) one input, input ``j`` for
    output ``j``.

    Parameters
    ----------
    mode : {"siso", "paired", "miso"}
        MIMO structure.
    n_inputs : int
        Inputs of the record.
    """
    return n_inputs if mode == "miso" else 1


def column_labels(
    structure: Structure, output: str = "y", inputs: tuple[str, ...] = ("u",)
) -> list[str]:
    """Human-readable labels of the lag-vector entries, e.g. ``['y(n)', 'y(n-1)', ...]``."""

    def lab(name: str, lag: int) -> str:
        return f"{name}(n)" if lag == 0 else f"{name}(n-{lag})"

    labels = [lab(output, i) for i in range(structure.na + 1)]
    for name in inputs:
        labels += [lab(name, structure.nk + i) for i in range(structure.nb + 1)]
    return labels
