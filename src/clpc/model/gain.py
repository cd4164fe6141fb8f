"""The DC gain of a fitted model with its standard deviation, and whether the data decide it.

:func:`gain_uncertainty` gives ``G(1)`` and its standard deviation by the delta method on
the model's parameter covariance (``info["covariance"]`` of the monic parameters
``np.r_[den[1:], num]`` per output; :func:`clpc.model.uncertainty.dc_gain_std`).
:func:`assess_gain` judges every input/output pair: the gain is *undetermined* when
``sigma * GAIN_SIGMAS > |gain|`` (:data:`GAIN_SIGMAS`: the data do not even decide its
sign) and sigma is more than :data:`GAIN_SCALE_FRACTION` of the record's scale
``std(y) / std(u)`` (below it the gain is decided to be small: consistent with 0). An input
not persistently exciting of the needed order (:mod:`clpc.model.excitation`) leaves every
gain undetermined, whatever its sigma: that sigma is the spread of one choice among models
the input cannot tell apart. :mod:`clpc.model.identifiability` puts the findings first in a
verdict.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.core.polynomials import pole_class
from clpc.model import uncertainty
from clpc.model.errors import ModelError
from clpc.model.excitation import inputs_of, stored_excitation

__all__ = [
    "GAIN_SCALE_FRACTION",
    "GAIN_SIGMAS",
    "GainAssessment",
    "assess_gain",
    "gain_uncertainty",
]

#: The DC gain is undetermined when its standard deviation times this exceeds ``|gain|``:
#: at one sigma the data do not decide the gain's sign ...
GAIN_SIGMAS = 1.0
#: ... unless that standard deviation is at most this fraction of the record's gain scale
#: ``std(y) / std(u)`` (the gain that would explain all of the output's variation by the
#: input): then the data do decide that the gain is small, consistent with 0 (a
#: cross-coupling a MIMO plant does not have, a differentiating plant).
GAIN_SCALE_FRACTION = 0.1


@dataclass(frozen=True)
class GainAssessment:
    """The DC gain of one input/output pair and whether the data determine it.

    Attributes
    ----------
    output, input : str
        Channel names.
    output_index, input_index : int
        Channel indices.
    gain : float
        ``G(1)`` in output units per input unit (``+-inf`` for an integrator).
    std : float
        Its standard deviation (delta method); ``nan`` only when there is none, ``note``
        then says why.
    determined : bool or None
        ``None`` for an integrating model (a pole within
        :data:`~clpc.core.polynomials.UNIT_CIRCLE_TOL` of ``z = 1``: no finite DC gain);
        ``False`` when ``std * GAIN_SIGMAS > |gain|`` (``cause`` ``"sigma"``) or when the
        record's input is not persistently exciting of the order the structure needs
        (``cause`` ``"excitation"``: the sigma is then that of one choice among models the
        input cannot tell apart, however small); ``None`` when it cannot be judged (no
        covariance, an integrator); else ``True``.
    note : str
        Why ``determined`` is not ``True``, in words; ``""`` when it is, except for a gain
        within one sigma of 0 that is determined to be small (``cause`` ``"zero"``).
    cause : str
        ``"sigma"``, ``"excitation"``, ``"no sigma"``, ``"integrating"``, ``"zero"``
        (determined, consistent with 0) or ``""``.
    """

    output: str
    input: str
    output_index: int
    input_index: int
    gain: float
    std: float
    determined: bool | None
    note: str = ""
    cause: str = ""

    @property
    def value(self) -> str:
        """``"0.891 ± 0.031"``: the gain to the last digit of sigma's two (``"0.891"``: none)."""
        g, sd = self.gain, self.std
        if not (np.isfinite(sd) and sd > 0 and np.isfinite(g)):
            return f"{g:.3g}" + ("" if np.isnan(sd) else f" ± {sd:.2g}")
        digits = 1 - int(np.floor(np.log10(sd)))
        if not 0 <= digits <= 12 or abs(g) >= 1e6 or abs(g) < sd:
            return f"{g:.2g} ± {sd:.2g}"
        return f"{g:.{digits}f} ± {sd:.{digits}f}"

    @property
    def text(self) -> str:
        """``"0.891 ± 0.031"``, ``"undetermined: -0.079 ± 0.22"``, ``"0.891 (no sigma: ..)"``.

        An integrating model's reads ``"integrating (pole at z = 1): no finite DC gain"``.

        An undetermined gain for want of excitation says so:
        ``"undetermined: 0.122 ± 0.002 (input persistently exciting of order 2, needs 5)"``.
        """
        if self.cause == "integrating":
            return self.note
        if self.determined is None:
            return f"{self.gain:.3g} ({self.note})"
        if self.determined:
            return self.value + (" (consistent with 0)" if self.cause == "zero" else "")
        more = f" ({self.note.split(':')[0]})" if self.cause == "excitation" else ""
        return f"undetermined: {self.value}{more}"

    def finding(self) -> str:
        """The verdict's words on an undetermined gain, with its numbers and threshold."""
        return f"DC gain {self.input} -> {self.output} undetermined: {self.value} - {self.note}"


def gain_uncertainty(model: Any, output: int = 0, input: int = 0) -> tuple[float, float]:
    """The DC gain ``G(1)`` of one pair and its standard deviation (delta method).

    The covariance is ``info["covariance"]`` of the monic parameters ``np.r_[den[1:],
    num]`` per output (:mod:`clpc.model.uncertainty`); the gain ``sum(num) / sum(den)`` is
    differentiated through it (:func:`clpc.model.uncertainty.dc_gain_std`).

    Parameters
    ----------
    model : LinearModel
        A fitted model.
    output, input : int
        Channel pair (default 0, 0).

    Returns
    -------
    gain : float
        ``G(1)`` in output units per input unit (``+-inf`` for an integrator).
    sigma : float
        Its standard deviation, same units; ``nan`` when the model has no covariance
        (:func:`assess_gain` says why).
    """
    gain = float(model.dc_gain()[output, input])
    try:
        sigma = float(uncertainty.dc_gain_std(model)[output, input])
    except ModelError:
        sigma = float("nan")
    return gain, sigma


def assess_gain(model: Any) -> list[GainAssessment]:
    """The DC gain of every input/output pair with its standard deviation, judged.

    Parameters
    ----------
    model : LinearModel
        A fitted model (its ``info["covariance"]`` and ``info["excitation_order"]`` are
        computed when first read, from the record a clpc fit keeps).

    Returns
    -------
    list of GainAssessment
        One per pair, output by output (a ``"paired"`` model: its diagonal pairs only, the
        others are zero by construction). ``.determined`` is ``False`` when the gain's
        standard deviation exceeds ``|gain|`` (:data:`GAIN_SIGMAS`) or the input is not
        persistently exciting of the needed order, ``None`` when it cannot be judged
        (``.note`` says why).
    """
    gains = model.dc_gain()
    try:
        stds: np.ndarray | None = uncertainty.dc_gain_std(model)
        missing = ""
    except ModelError:
        why = model.info.get("covariance_note") or "the model has no parameter covariance"
        stds, missing = None, f"no sigma: {why}"
    scales = np.full(gains.shape, np.nan)  # unknown without a record: never "zero"
    if "output_std" in model.info:
        out_std = np.atleast_1d(np.asarray(model.info["output_std"], dtype=np.float64))
        in_std = np.atleast_1d(np.asarray(model.info["input_std"], dtype=np.float64))
        with np.errstate(divide="ignore", invalid="ignore"):
            scales = out_std[:, None] / in_std[None, :]  # a constant input: inf or nan
    kinds = [pole_class(model.poles(j)) for j in range(model.n_outputs)]
    out = []
    for j, oname in enumerate(model.output_names):
        pe = stored_excitation(model.info, j)
        for i in inputs_of(model, j):
            g = float(gains[j, i])
            s = float("nan") if stds is None else float(stds[j, i])
            if not np.isfinite(g) or kinds[j] == "integrating":
                ok, cause = None, "integrating"
                note = "integrating (pole at z = 1): no finite DC gain"
            elif pe is not None and pe[0] < pe[1]:
                ok, cause = False, "excitation"
                note = (
                    f"input persistently exciting of order {pe[0]}, needs {pe[1]}: its sigma "
                    "is that of one choice among models the input cannot tell apart"
                )
            elif missing or not np.isfinite(s):
                ok, cause = None, "no sigma"
                note = missing or "no sigma: the delta method gives no finite value"
            elif s * GAIN_SIGMAS > abs(g) and s <= GAIN_SCALE_FRACTION * scales[j, i]:
                ok, cause = True, "zero"
                note = (
                    f"|gain| < {GAIN_SIGMAS:g} sigma, but sigma <= {GAIN_SCALE_FRACTION:g} "
                    f"std(y)/std(u) = {GAIN_SCALE_FRACTION * scales[j, i]:.2g}: consistent with 0"
                )
            elif s * GAIN_SIGMAS > abs(g):
                ok, cause = False, "sigma"
                note = f"|gain| < {GAIN_SIGMAS:g} sigma: the data do not decide its sign"
            else:
                ok, cause, note = True, "", ""
            out.append(GainAssessment(oname, model.input_names[i], j, i, g, s, ok, note, cause))
    return out
