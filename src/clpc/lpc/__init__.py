"""The LPC estimator (paper sections II-IV) and its companions.

``regressors`` builds the lag rows (eq. 36), ``solve`` solves the scatter (eqs. 24-32)
with the rules of :mod:`clpc.core.rules`, ``estimator`` is :class:`LPC`, ``arx`` the
least-squares baseline, ``order`` order and delay selection, ``noise`` noise variances,
``oe`` the output-error estimator, ``subspace`` subspace identification (PO-MOESP),
``eiv`` the errors-in-variables check, ``selection`` ``identify`` (the best of LPC, least
squares and OE on held-out data).
"""

from clpc.lpc.arx import ARX, simulate_arx
from clpc.lpc.eiv import EivCheck, check_eiv
from clpc.lpc.estimator import LPC, fit_info, lpc_solve, structure_blocks
from clpc.lpc.noise import NoiseEstimate, estimate_noise_variances
from clpc.lpc.oe import OE
from clpc.lpc.order import DelaySelection, OrderSelection, select_delay, select_order
from clpc.lpc.selection import Identification, identify
from clpc.lpc.solve import RobustRule
from clpc.lpc.subspace import Subspace

__all__ = [
    "ARX",
    "LPC",
    "OE",
    "DelaySelection",
    "EivCheck",
    "Identification",
    "NoiseEstimate",
    "OrderSelection",
    "RobustRule",
    "Subspace",
    "check_eiv",
    "estimate_noise_variances",
    "fit_info",
    "identify",
    "lpc_solve",
    "select_delay",
    "select_order",
    "simulate_arx",
    "structure_blocks",
]
