"""One source, two ways to run it: plain Python, or compiled by numba.

Every estimator rule and every kernel loop is written once, as a plain Python function in
numba's subset, and marked with :func:`kernel`. The module keeps the plain function, so
calling it runs Python (the ``"python"`` engine: for debugging, coverage and a reference).
:func:`compiled` returns its numba twin: the same code object with its globals copied and
every marked function it calls replaced by that function's twin, compiled on first call
and cached on disk. No rule exists twice; the engines differ only in who runs the code.

numba caches a compiled function by its own source file only; a twin also depends on the
files of the functions it calls. The cache stamp of every marked function is therefore
the digest of every file of the package that marks functions (found by reading the
package, not by what happens to be imported), so editing a rule invalidates every kernel
that inlines it and nothing else does.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import os
import sys
import types
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

F = TypeVar("F", bound=Callable[..., Any])

__all__ = [
    "COMPILE_NOTICE",
    "ENGINES",
    "compiled",
    "kernel",
    "numba_available",
    "resolve_engine",
]

_MARKED: dict[int, Callable[..., Any]] = {}
_TWINS: dict[int, Any] = {}


def numba_available() -> bool:
    """Whether numba can be imported (it is a core dependency; this guards odd installs)."""
    return importlib.util.find_spec("numba") is not None


ENGINES = ("auto", "compiled", "python")


def resolve_engine(engine: Any) -> str:
    """The engine to use: ``engine``, with ``"auto"`` read from ``CLPC_ENGINE`` if set."""
    if engine == "auto":
        engine = os.environ.get("CLPC_ENGINE", "auto") or "auto"
    if engine not in ENGINES:
        raise ValueError(
            f"engine must be 'auto', 'compiled' or 'python' (argument or CLPC_ENGINE); got "
            f"{engine!r}."
        )
    if engine == "compiled" and not numba_available():
        raise ValueError(
            "engine='compiled' needs numba, which is not installed: pip install numba, "
            "or use engine='python' (slow)."
        )
    if engine == "auto":
        return "compiled" if numba_available() else "python"
    return str(engine)


def kernel(fn: F) -> F:
    """Mark ``fn`` as part of the compiled engine; the plain function is returned unchanged."""
    _MARKED[id(fn)] = fn
    return fn


def compiled(fn: Callable[..., Any]) -> Any:
    """The numba twin of a :func:`kernel` function (built once, compiled on first call).

    Parameters
    ----------
    fn : callable
        A function marked with :func:`kernel`.

    Returns
    -------
    numba dispatcher
        Runs ``fn``'s code with every marked callee replaced by its own twin.
    """
    key = id(fn)
    if key not in _MARKED:
        raise ValueError(f"{fn.__qualname__} is not marked with clpc.core.jit.kernel.")
    if key in _TWINS:
        return _TWINS[key]
    import numba

    _install_stamp()
    _install_notice()
    scope = dict(fn.__globals__)
    twin = types.FunctionType(fn.__code__, scope, fn.__name__, fn.__defaults__, fn.__closure__)
    twin.__qualname__ = fn.__qualname__
    twin.__module__ = fn.__module__
    twin.__doc__ = fn.__doc__
    dispatcher = numba.njit(cache=True, nogil=True, error_model="numpy")(twin)
    _TWINS[key] = dispatcher  # before the callees: recursion through the call graph ends here
    for name, value in list(scope.items()):
        if callable(value) and id(value) in _MARKED:
            scope[name] = compiled(value)
    return dispatcher


_DIGEST: list[str] = []


@functools.cache
def _engine_files() -> frozenset[Path]:
    """Every source file of the package that marks functions with :func:`kernel`."""
    root = Path(__file__).resolve().parent.parent
    return frozenset(
        path
        for path in root.rglob("*.py")
        if path.name != "jit.py" and "@kernel" in path.read_text(encoding="utf-8")
    )


def _engine_digest() -> str:
    if not _DIGEST:
        digest = hashlib.sha256()
        for path in sorted(_engine_files()):
            digest.update(path.name.encode())
            digest.update(path.read_bytes())
        _DIGEST.append(digest.hexdigest())
    return _DIGEST[0]


_STAMP_INSTALLED = False
_NOTICE: dict[str, Any] = {"installed": False, "said": False}

#: The line written to standard error when clpc's kernels start compiling (not loading
#: from numba's cache): the CLPC kernel takes 15-20 s on its first use in a fresh
#: environment, the model's filter about 1 s.
COMPILE_NOTICE = (
    "clpc: compiling clpc's kernels (first use in this environment: up to about 20 s; "
    "cached for later runs)..."
)


def _install_notice() -> None:
    """Say once per process, on standard error, when a clpc kernel starts compiling.

    A listener on numba's ``"numba:compile"`` event, which numba broadcasts only when it
    compiles (a kernel loaded from the on-disk cache is silent).
    """
    if _NOTICE["installed"]:
        return
    _NOTICE["installed"] = True
    try:
        from numba.core import event
    except ImportError:  # pragma: no cover - numba without the event module
        return

    class _Notice(event.Listener):
        def on_start(self, ev: Any) -> None:
            dispatcher = (ev.data or {}).get("dispatcher")
            module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
            if module.startswith("clpc.") and not _NOTICE["said"]:
                _NOTICE["said"] = True
                print(COMPILE_NOTICE, file=sys.stderr, flush=True)

        def on_end(self, ev: Any) -> None:
            """Nothing to say at the end."""

    event.register("numba:compile", _Notice())


def _install_stamp() -> None:
    """Make numba's cache stamp of engine files the digest of all engine files."""
    global _STAMP_INSTALLED
    if _STAMP_INSTALLED:
        return
    _STAMP_INSTALLED = True
    try:
        from numba.core import caching
    except ImportError:  # pragma: no cover - numba without the caching module
        return
    impl = getattr(caching, "CacheImpl", None)
    mixin = getattr(caching, "_SourceFileBackedLocatorMixin", None)
    if impl is None or mixin is None:  # pragma: no cover - numba internals moved
        return  # numba's own stamp (the function's file) still works, only less strictly

    def stamp(self: Any) -> Any:
        if Path(self._py_file).resolve() in _engine_files():
            return _engine_digest()
        return super(type(self), self).get_source_stamp()

    extra = [
        type(f"Engine{cls.__name__}", (cls,), {"get_source_stamp": stamp})
        for cls in impl._locator_classes
        if issubclass(cls, mixin)
    ]
    impl._locator_classes = [*extra, *impl._locator_classes]
