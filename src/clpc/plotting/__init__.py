"""Headless figures (PNG) of records, fits, traces, pole-zero maps, step and Bode plots.

Every function draws on the caller's matplotlib axes (``ax=``) or on a fresh
:class:`matplotlib.figure.Figure` rendered by the Agg backend (no window opens, no global
pyplot state changes, works on servers and in threads), returns the figure (Jupyter shows
it) and also writes it as PNG when given a ``path``. matplotlib is an optional dependency
(``pip install '.[plot]'`` in the source tree), imported only when a figure is drawn. The same
quantity has the same colour in every figure (:data:`clpc.core.figure.COLORS`); records longer than
:data:`clpc.core.figure.MAX_POINTS` samples are drawn as min/max envelopes.

>>> import clpc, clpc.datasets as ds                                  # doctest: +SKIP
>>> trace = clpc.CLPC(order=2).run(ds.load("dryer"))                  # doctest: +SKIP
>>> fig = clpc.plotting.plot_trace(trace, "trace.png")                # doctest: +SKIP
"""

from clpc.core.figure import COLORS, MAX_POINTS, envelope
from clpc.plotting.multimodel import plot_multimodel
from clpc.plotting.records import plot_compare, plot_data, plot_fit
from clpc.plotting.residuals import plot_residuals
from clpc.plotting.responses import bode_frequencies, plot_bode, plot_pz, plot_step
from clpc.plotting.traces import plot_trace

__all__ = [
    "COLORS",
    "MAX_POINTS",
    "bode_frequencies",
    "envelope",
    "plot_bode",
    "plot_compare",
    "plot_data",
    "plot_fit",
    "plot_multimodel",
    "plot_pz",
    "plot_residuals",
    "plot_step",
    "plot_trace",
]
