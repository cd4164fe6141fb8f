"""The paper's section VI experiment, reproduced as an application of the clpc library.

``clpc_paper.plants`` simulates the brushless servo (and the crank servo); ``clpc_paper.experiment``
identifies it with clpc's estimators and writes the figures and the report (``clpc demo``).
"""
