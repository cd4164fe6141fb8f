"""Multi-models: local linear models blended by validity functions (issue 18).

:class:`MultiModel` (in :mod:`clpc.multimodel.model`) identifies a nonlinear plant as
local LPC models of a scheduling variable; :func:`simulate_time_varying` runs a model that
changes every sample (e.g. CLPC's held window models).
"""

from clpc.multimodel.model import MultiModel
from clpc.multimodel.varying import simulate_time_varying

__all__ = ["MultiModel", "simulate_time_varying"]
