"""Module paths that moved when the package was laid out in layers, and their aliases.

``import clpc.solve`` (the old flat path) still works: a meta-path finder answers each old
name with the module that now holds its code (``clpc.lpc.solve``), the same module object,
so ``clpc.solve.RobustRule is clpc.lpc.solve.RobustRule``. New code imports the new paths.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
from types import ModuleType

#: old module path -> the module that holds its code now
MOVED = {
    "clpc.small_eigh": "clpc.core.small_eigh",
    "clpc.regressors": "clpc.lpc.regressors",
    "clpc.solve": "clpc.lpc.solve",
    "clpc.arx": "clpc.lpc.arx",
    "clpc.order": "clpc.lpc.order",
    "clpc.noise": "clpc.lpc.noise",
    "clpc.verdict": "clpc.model.verdict",
    "clpc.metrics": "clpc.analysis.metrics",
    "clpc.trace": "clpc.appraiser.trace",
    "clpc.tracefile": "clpc.appraiser.tracefile",
    "clpc.window_kernel": "clpc.appraiser.kernel",
    "clpc.model_io": "clpc.io.model_files",
}


class _AliasLoader(importlib.abc.Loader):
    def __init__(self, target: str) -> None:
        self.target = target

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        return importlib.import_module(self.target)

    def exec_module(self, module: ModuleType) -> None:
        """The target module is already executed."""


class _AliasFinder(importlib.abc.MetaPathFinder):
    def find_spec(
        self, fullname: str, path: object = None, target: object = None
    ) -> importlib.machinery.ModuleSpec | None:
        new = MOVED.get(fullname)
        if new is None:
            return None
        return importlib.machinery.ModuleSpec(fullname, _AliasLoader(new))


def install() -> None:
    """Put the alias finder on ``sys.meta_path`` (once)."""
    if not any(isinstance(f, _AliasFinder) for f in sys.meta_path):
        sys.meta_path.append(_AliasFinder())
