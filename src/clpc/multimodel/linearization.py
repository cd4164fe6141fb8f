"""The frozen-validity linear model of a multi-model at one scheduling value."""

from __future__ import annotations

import numpy as np

from clpc.model import LinearModel
from clpc.model.structure import Structure
from clpc.multimodel.fitting import Fitted, monic_arrays
from clpc.multimodel.validity import validity

__all__ = ["linearize"]


def linearize(
    fitted: Fitted, structure: Structure, n_inputs: int, dt: float, operating_point: float
) -> LinearModel:
    """The validity-weighted mean of the local models' monic coefficients at one point.

    :meth:`clpc.MultiModel.linearize`; ``info["operating_point"]`` records the point.
    """
    den, num, icpt = monic_arrays(fitted.local_models)
    phi = validity(np.float64(operating_point), fitted.centres, fitted.widths)
    d, nm, ic = phi @ den, np.tensordot(phi, num, axes=1), float(phi @ icpt)
    s = structure
    theta = np.concatenate([d, *(-nm[c, s.nk :] for c in range(n_inputs))])
    scale = float(np.linalg.norm(theta))
    return LinearModel(
        theta=np.atleast_2d(theta / scale),
        structure=s,
        n_inputs=n_inputs,
        mode="siso" if n_inputs == 1 else "miso",
        c=np.array([ic / scale]),
        dt=dt,
        info={"method": "multimodel-linearization", "operating_point": float(operating_point)},
    )
