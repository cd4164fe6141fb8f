"""clpc - system identification with Last Principal Components (LPC) and Cluster LPC.

The LPC estimator fits a linear difference equation ``A(q) y + B(q) u = r`` to measured
input/output data by total least squares (the eigenvector of the smallest eigenvalue of the
centered scatter matrix of lag vectors); CLPC runs it window by window as a finite-state
machine and reports time-varying parameters and the degree of linearity of each cluster.
"""

from .appraiser import CLPC
from .arx import ARX, simulate_arx
from .data import DataError, IOData, as_iodata
from .io import load_iodata, read_table, write_table
from .lpc import LPC, lpc_solve
from .metrics import fit_percent, kstep_fit, rmse, vaf, whiteness_test
from .model import LinearModel, ModelError
from .model_io import load_model, save_model
from .noise import NoiseEstimate, estimate_noise_variances
from .order import DelaySelection, OrderSelection, select_delay, select_order
from .regressors import Structure
from .solve import RobustRule
from .trace import Convergence, Trace
from .verdict import Verdict, describe_trace, fit_verdict

__version__ = "0.1.0"

__all__ = [
    "ARX",
    "CLPC",
    "LPC",
    "Convergence",
    "DataError",
    "DelaySelection",
    "IOData",
    "LinearModel",
    "ModelError",
    "NoiseEstimate",
    "OrderSelection",
    "RobustRule",
    "Structure",
    "Trace",
    "Verdict",
    "as_iodata",
    "describe_trace",
    "estimate_noise_variances",
    "fit_percent",
    "fit_verdict",
    "kstep_fit",
    "load_iodata",
    "load_model",
    "lpc_solve",
    "read_table",
    "rmse",
    "save_model",
    "select_delay",
    "select_order",
    "simulate_arx",
    "vaf",
    "whiteness_test",
    "write_table",
]
