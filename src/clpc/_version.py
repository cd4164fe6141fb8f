"""The package version, its one source (``pyproject.toml`` reads it: ``dynamic = ["version"]``).

Its own module, so that any layer can read it without a cycle.
"""

__version__ = "0.1.0"
