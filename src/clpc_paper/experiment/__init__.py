"""The paper's section VI experiment on the simulated brushless servo, end to end.

``decimate`` is the appraiser's own (:func:`clpc.appraiser.decimate`), re-exported.
"""

from clpc.appraiser import decimate
from clpc_paper.experiment.analysis import error_profile, free_run, stable_inverse
from clpc_paper.experiment.run import run_experiment

__all__ = ["decimate", "error_profile", "free_run", "run_experiment", "stable_inverse"]
