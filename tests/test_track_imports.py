"""`clpc track`'s start-up: heavy modules are imported only where they are used (issue 16).

Each check runs in a fresh interpreter (a subprocess), since this test session has long
imported everything.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest


def _modules_after(code: str) -> set[str]:
    """The top modules of interest imported after running ``code`` in a fresh interpreter."""
    probe = textwrap.dedent(code) + textwrap.dedent(
        """
        import sys
        print(" ".join(m for m in ("scipy.signal", "scipy.optimize", "scipy.stats",
                                   "matplotlib", "pandas") if m in sys.modules))
        """
    )
    res = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return set(res.stdout.split())


def _record_csv(path, n: int, seed: int):
    """A ``u,y`` CSV of ``n`` samples of a small FIR system with a little output noise."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = np.convolve(u, [0.0, 0.5, 0.2])[:n] + 0.01 * rng.standard_normal(n)
    np.savetxt(path, np.column_stack([u, y]), delimiter=",", header="u,y", comments="")
    return path


def test_the_track_command_imports_neither_scipy_signal_nor_matplotlib():
    loaded = _modules_after("import clpc.cli.track, clpc.workflows.track, clpc.appraiser")
    assert not loaded & {"scipy.signal", "scipy.optimize", "matplotlib"}, loaded


def test_the_fast_reader_and_trace_writer_do_not_import_pandas(tmp_path):
    pytest.importorskip("pyarrow")
    pytest.importorskip("pandas")  # the point: pyarrow's to_numpy / pa.array would load it
    path = _record_csv(tmp_path / "rec.csv", 600, seed=3)
    out = tmp_path / "trace.csv"
    loaded = _modules_after(
        f"""
        from clpc.io import iter_table_chunks
        from clpc.appraiser import CLPC
        from clpc.appraiser.tracefile import TraceWriter
        a = CLPC(order=1, window_size=40, cluster_size=5)
        with TraceWriter({str(out)!r}) as w:
            for _, v in iter_table_chunks({str(path)!r}, 250, columns=["u", "y"]):
                w.write(a.push(v[:, :1], v[:, 1:]))
        """
    )
    assert "pandas" not in loaded
    assert out.read_text().count("\n") > 10  # the trace was written


def test_the_whole_track_run_with_its_report_needs_neither_scipy_signal_nor_stats(tmp_path):
    """Simulation, prediction, the Bode plot and the residual tests of the report use
    clpc.core.filters and scipy.special (0.6-0.8 s of imports fewer)."""
    path = _record_csv(tmp_path / "rec.csv", 4000, seed=5)
    out = tmp_path / "out"
    loaded = _modules_after(
        f"""
        import contextlib, io
        from clpc.cli import main
        with contextlib.redirect_stdout(io.StringIO()):
            try:
                main(["track", {str(path)!r}, "-u", "u", "-y", "y", "--out", {str(out)!r}])
            except SystemExit as exc:
                assert exc.code in (0, None), exc.code
        """
    )
    assert (out / "bode.png").exists() and (out / "report.html").exists()
    assert "matplotlib" in loaded  # the figures were drawn here
    assert not loaded & {"scipy.signal", "scipy.stats", "scipy.optimize"}, loaded
