"""CLPC, the paper's appraiser (section V): a finite-state machine over sliding windows."""

from clpc.appraiser.facade import CLPC
from clpc.appraiser.trace import Convergence, Trace

__all__ = ["CLPC", "Convergence", "Trace"]
