"""clpc - system identification with Last Principal Components (LPC) and Cluster LPC.

The LPC estimator fits a linear difference equation ``A(q) y + B(q) u = r`` to measured
input/output data by total least squares (the eigenvector of the smallest eigenvalue of the
centered scatter matrix of lag vectors); CLPC runs it window by window as a finite-state
machine and reports time-varying parameters and the degree of linearity of each cluster.

``import clpc`` is cheap: every exported name is imported from its module on first use
(module-level ``__getattr__``), so a script that needs only :class:`LPC` never pays for
scipy.stats or the CLPC engine.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from clpc._version import __version__

if TYPE_CHECKING:  # the names mypy and editors see; at run time they load on first use
    from clpc.analysis.metrics import fit_percent, kstep_fit, rmse, vaf, whiteness_test
    from clpc.analysis.operating_point import operating_point_diagnostics
    from clpc.appraiser import CLPC, Convergence, Trace
    from clpc.data import DataError, IOData, as_iodata
    from clpc.distributed.fleet import track_many
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
        Subspace,
        estimate_noise_variances,
        identify,
        lpc_solve,
        select_delay,
        select_order,
        simulate_arx,
    )
    from clpc.model import (
        DominantPole,
        GainAssessment,
        LinearModel,
        ModelError,
        Structure,
        Verdict,
        assess_gain,
        describe_trace,
        dominant_poles,
        excitation_order,
        fit_verdict,
        gain_uncertainty,
    )
    from clpc.model.residuals import ResidualAnalysis, residual_analysis
    from clpc.multimodel import MultiModel

#: exported name -> the module that defines it (imported on first access)
_LAZY: dict[str, str] = {
    **dict.fromkeys(
        ("fit_percent", "kstep_fit", "rmse", "vaf", "whiteness_test"), "clpc.analysis.metrics"
    ),
    "operating_point_diagnostics": "clpc.analysis.operating_point",
    **dict.fromkeys(("CLPC", "Convergence", "Trace"), "clpc.appraiser"),
    **dict.fromkeys(("DataError", "IOData", "as_iodata"), "clpc.data"),
    **dict.fromkeys(
        ("load_iodata", "load_model", "read_table", "save_model", "write_table"), "clpc.io"
    ),
    **dict.fromkeys(
        (
            "ARX",
            "LPC",
            "OE",
            "DelaySelection",
            "Identification",
            "NoiseEstimate",
            "OrderSelection",
            "RobustRule",
            "Subspace",
            "estimate_noise_variances",
            "identify",
            "lpc_solve",
            "select_delay",
            "select_order",
            "simulate_arx",
        ),
        "clpc.lpc",
    ),
    **dict.fromkeys(
        (
            "DominantPole",
            "GainAssessment",
            "LinearModel",
            "ModelError",
            "Structure",
            "Verdict",
            "assess_gain",
            "describe_trace",
            "dominant_poles",
            "excitation_order",
            "fit_verdict",
            "gain_uncertainty",
        ),
        "clpc.model",
    ),
    **dict.fromkeys(("ResidualAnalysis", "residual_analysis"), "clpc.model.residuals"),
    "MultiModel": "clpc.multimodel",
    "track_many": "clpc.distributed.fleet",
}


def __getattr__(name: str) -> Any:
    """Import an exported name (or a subpackage such as ``clpc.lpc``) on first access."""
    module = _LAZY.get(name)
    if module is not None:
        value = getattr(importlib.import_module(module), name)
        globals()[name] = value  # later look-ups skip this function
        return value
    if not name.startswith("__"):
        try:
            return importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as exc:
            if exc.name != f"{__name__}.{name}":
                raise
    raise AttributeError(f"module 'clpc' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})


__all__ = [
    "ARX",
    "CLPC",
    "LPC",
    "OE",
    "Convergence",
    "DataError",
    "DelaySelection",
    "DominantPole",
    "GainAssessment",
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
    "Subspace",
    "Trace",
    "Verdict",
    "__version__",
    "as_iodata",
    "assess_gain",
    "describe_trace",
    "dominant_poles",
    "estimate_noise_variances",
    "excitation_order",
    "fit_percent",
    "fit_verdict",
    "gain_uncertainty",
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
    "track_many",
    "vaf",
    "whiteness_test",
    "write_table",
]
