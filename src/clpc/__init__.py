"""clpc - system identification with Last Principal Components (LPC) and Cluster LPC.

The LPC estimator fits a linear difference equation ``A(q) y + B(q) u = r`` to measured
input/output data by total least squares (the eigenvector of the smallest eigenvalue of the
centered scatter matrix of lag vectors); CLPC runs it window by window as a finite-state
machine and reports time-varying parameters and the degree of linearity of each cluster.
"""

from clpc import _moved
from clpc._version import __version__
from clpc.analysis.metrics import fit_percent, kstep_fit, rmse, vaf, whiteness_test
from clpc.analysis.operating_point import operating_point_diagnostics
from clpc.appraiser import CLPC, Convergence, Trace
from clpc.data import DataError, IOData, as_iodata
from clpc.io import load_iodata, load_model, read_table, save_model, write_table
from clpc.lpc import (
    ARX,
    LPC,
    OE,
    DelaySelection,
    Identification,
    NoiseEstimate,
    OrderSelection,
    RobustRule,
    estimate_noise_variances,
    identify,
    lpc_solve,
    select_delay,
    select_order,
    simulate_arx,
)
from clpc.model import LinearModel, ModelError, Structure, Verdict, describe_trace, fit_verdict
from clpc.model.residuals import ResidualAnalysis, residual_analysis
from clpc.multimodel import MultiModel

_moved.install()

__all__ = [
    "ARX",
    "CLPC",
    "LPC",
    "OE",
    "Convergence",
    "DataError",
    "DelaySelection",
    "IOData",
    "Identification",
    "LinearModel",
    "ModelError",
    "MultiModel",
    "NoiseEstimate",
    "OrderSelection",
    "ResidualAnalysis",
    "RobustRule",
    "Structure",
    "Trace",
    "Verdict",
    "__version__",
    "as_iodata",
    "describe_trace",
    "estimate_noise_variances",
    "fit_percent",
    "fit_verdict",
    "identify",
    "kstep_fit",
    "load_iodata",
    "load_model",
    "lpc_solve",
    "operating_point_diagnostics",
    "read_table",
    "residual_analysis",
    "rmse",
    "save_model",
    "select_delay",
    "select_order",
    "simulate_arx",
    "vaf",
    "whiteness_test",
    "write_table",
]
