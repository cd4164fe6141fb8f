"""Identified models: the structure (orders, delay), :class:`LinearModel`, verdicts."""

from clpc.model.linear import LinearModel, ModelError
from clpc.model.structure import MimoMode, Structure
from clpc.model.verdict import Verdict, describe_trace, fit_verdict

__all__ = [
    "LinearModel",
    "MimoMode",
    "ModelError",
    "Structure",
    "Verdict",
    "describe_trace",
    "fit_verdict",
]
