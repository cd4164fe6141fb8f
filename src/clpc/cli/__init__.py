"""The ``clpc`` command line (click): parsing and printing over :mod:`clpc.workflows`.

Commands: ``identify`` (structure and estimator chosen, or batch LPC alone), ``track`` (the
CLPC appraiser over a file, read in chunks), ``stream`` (the appraiser on standard input, one
JSON line per update), ``simulate``, ``compare``, ``datasets`` and ``demo``. Run
``clpc COMMAND --help``.

Exit codes: 0 success, 1 a data or model error (one line on standard error, no traceback),
2 a usage error (unknown option, bad option value); see :mod:`clpc.cli.errors`.

Modules: ``app`` (the group, ``main``, the process entry ``run``), ``errors``, ``options``
(shared options), ``output`` (JSON and CSV printing), one module per command group:
``identify``, ``track``, ``stream``, ``models`` (simulate, compare), ``info`` (datasets,
demo).
"""

from clpc.cli.app import cli, main, run

__all__ = ["cli", "main", "run"]
