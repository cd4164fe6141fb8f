"""The LPC estimator (paper sections II-IV) and its companions.

``regressors`` builds the lag rows (eq. 36), ``solve`` solves the scatter (eqs. 24-32)
with the rules of :mod:`clpc.core.rules`, ``estimator`` is :class:`LPC`, ``arx`` the
least-squares baseline, ``order`` order and delay selection, ``noise`` noise variances.
"""

from clpc.lpc.arx import ARX, simulate_arx
from clpc.lpc.estimator import LPC, fit_info, lpc_solve, structure_blocks
from clpc.lpc.noise import NoiseEstimate, estimate_noise_variances
from clpc.lpc.order import DelaySelection, OrderSelection, select_delay, select_order
from clpc.lpc.solve import RobustRule

__all__ = [
    "ARX",
    "LPC",
    "DelaySelection",
    "NoiseEstimate",
    "OrderSelection",
    "RobustRule",
    "estimate_noise_variances",
    "fit_info",
    "lpc_solve",
    "select_delay",
    "select_order",
    "simulate_arx",
    "structure_blocks",
]
