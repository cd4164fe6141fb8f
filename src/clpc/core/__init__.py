"""The bottom layer: estimator rules, polynomial helpers, the small eigen-solver, checks.

Nothing here imports from the rest of the package.
"""
