"""CLPC, the paper's appraiser (section V): a finite-state machine over sliding windows."""

from clpc.appraiser.facade import CLPC, numba_available, schur_stable
from clpc.appraiser.trace import Convergence, Trace

__all__ = ["CLPC", "Convergence", "Trace", "numba_available", "schur_stable"]
