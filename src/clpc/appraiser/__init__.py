"""CLPC, the paper's appraiser (section V): a finite-state machine over sliding windows.

``decimate`` decimates a whole record exactly as :class:`CLPC` does; ``usable`` marks the
updates of a :class:`Trace` that count for its convergence and steady state.
"""

from clpc.appraiser.clpc import CLPC
from clpc.appraiser.convergence import usable
from clpc.appraiser.decimation import decimate
from clpc.appraiser.trace import Convergence, Trace

__all__ = ["CLPC", "Convergence", "Trace", "decimate", "usable"]
