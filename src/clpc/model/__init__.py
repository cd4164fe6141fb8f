"""Identified models: the structure (orders, delay), :class:`LinearModel`, verdicts."""

from clpc.model.dominant import DominantPole, dominant_poles
from clpc.model.excitation import excitation_order
from clpc.model.identifiability import (
    GainAssessment,
    Identifiability,
    assess_gain,
    gain_uncertainty,
    identifiability,
)
from clpc.model.linear import LinearModel, ModelError
from clpc.model.structure import MimoMode, Structure
from clpc.model.verdict import Verdict, describe_trace, fit_verdict

__all__ = [
    "DominantPole",
    "GainAssessment",
    "Identifiability",
    "LinearModel",
    "MimoMode",
    "ModelError",
    "Structure",
    "Verdict",
    "assess_gain",
    "describe_trace",
    "dominant_poles",
    "excitation_order",
    "fit_verdict",
    "gain_uncertainty",
    "identifiability",
]
