"""Figures drawn by two forked processes while the caller works, or here, one by one.

A report's figures take as long as the rest of ``clpc track`` on a long record, and
importing matplotlib takes half a second more. :class:`Painter` forks a process when
started (POSIX only): the process imports matplotlib, loads a font and the compiled
filter while the caller goes on appraising the record on the other core; given the
figures (:meth:`Painter.submit`), it forks once more and the two draw them in parallel
(largest first, each to the less loaded process) while the caller writes the page. A
figure that fails there is drawn again here, so its error is raised with its own
traceback; without ``fork`` (Windows), off Linux unless ``CLPC_PAINTER=1``, with
``CLPC_PAINTER=0`` or ``enabled=False``, everything is drawn here.

The jobs travel by pickle: a job is a module-level function and its arguments.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

__all__ = ["FigureJob", "Painter", "draw_here"]

#: seconds to wait for the forked process before drawing everything here instead
TIMEOUT = 120.0


@dataclass(frozen=True)
class FigureJob:
    """One figure: ``draw(*args, **kwargs)`` writes it (a module-level function).

    ``cost`` is its relative drawing time, used to share the jobs between two processes.
    """

    draw: Callable[..., Any]
    args: tuple[Any, ...]
    kwargs: dict[str, Any] = field(default_factory=dict)
    cost: float = 1.0

    def run(self) -> None:
        """Draw the figure (the returned figure is dropped)."""
        self.draw(*self.args, **self.kwargs)


def draw_here(jobs: list[FigureJob]) -> None:
    """Draw ``jobs`` in this process, in order."""
    for job in jobs:
        job.run()


def _share(jobs: list[FigureJob]) -> tuple[list[int], list[int]]:
    """Two lists of job indices of about equal cost (largest first, to the lighter one)."""
    groups: tuple[list[int], list[int]] = ([], [])
    load = [0.0, 0.0]
    for i in sorted(range(len(jobs)), key=lambda i: -jobs[i].cost):
        k = 0 if load[0] <= load[1] else 1
        groups[k].append(i)
        load[k] += jobs[i].cost
    return groups


def _draw_some(jobs: list[FigureJob], which: list[int]) -> list[int]:
    """Draw ``jobs[which]``; the indices of those that failed."""
    failed = []
    for i in which:
        try:
            jobs[i].run()
        except Exception:
            failed.append(i)
    return failed


def _fork() -> int:
    sys.stdout.flush()
    sys.stderr.flush()
    with warnings.catch_warnings():  # Python >= 3.12 warns when threads exist (BLAS's idle pool)
        warnings.simplefilter("ignore", DeprecationWarning)
        return os.fork()


def _draw_in_two(jobs: list[FigureJob]) -> list[int]:
    """Draw ``jobs`` here and in a forked twin of this process; the failed indices."""
    mine, theirs = _share(jobs)
    if not theirs:
        return _draw_some(jobs, mine)
    pid = _fork()
    if pid == 0:  # the twin: draw, say by the exit status whether all went well
        code = 1
        try:
            code = 1 if _draw_some(jobs, theirs) else 0
        finally:
            os._exit(code)
    failed = _draw_some(jobs, mine)
    _, status = os.waitpid(pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        failed += theirs
    return failed


def _warm_up() -> None:
    """Import and touch what drawing needs: matplotlib, a font, the model's filter."""
    import numpy as np

    from clpc.core.figure import new_figure
    from clpc.core.filters import all_pole

    fig, axes = new_figure()
    axes[0, 0].set_title("warm-up")
    axes[0, 0].set_xscale("log")  # log-axis tick labels go through mathtext: its parser
    axes[0, 0].plot([1e-3, 1.0], [0.0, 1.0])
    fig.canvas.draw()
    all_pole(np.array([1.0, -0.5]), np.ones(4))


def _serve(conn: Any) -> None:
    """The forked process: warm up, then draw each list of jobs received until ``None``."""
    try:
        try:
            _warm_up()
        except Exception:  # drawing will fail and be redone by the caller
            pass
        while True:
            jobs = conn.recv()
            if jobs is None:
                break
            conn.send(_draw_in_two(jobs))
    except BaseException:  # the caller went away, or a signal: nothing to report
        pass
    finally:
        os._exit(0)


class Painter:
    """Draw figures in a forked process (see the module's notes); a context manager.

    Parameters
    ----------
    enabled : bool, optional
        Fork a process at :meth:`start`. Default: ``CLPC_PAINTER=1`` turns it on wherever
        ``os.fork`` exists, ``CLPC_PAINTER=0`` off; unset, on Linux only (on macOS a
        forked child that touches system frameworks such as Accelerate may crash).

    Examples
    --------
    >>> with Painter() as painter:          # doctest: +SKIP
    ...     painter.start()                 # forks: the process imports matplotlib
    ...     trace = appraise(record)        # meanwhile
    ...     painter.submit([FigureJob(plot_trace, (trace, "trace.png"))])
    ...     html = make_page(trace)         # meanwhile, the figures are drawn
    ...     painter.wait()                  # every figure is written
    """

    def __init__(self, enabled: bool | None = None) -> None:
        if enabled is None:
            flag = os.environ.get("CLPC_PAINTER", "")
            enabled = flag == "1" or (flag != "0" and sys.platform.startswith("linux"))
        self.enabled = bool(enabled and hasattr(os, "fork"))
        self._conn: Any = None
        self._pid: int | None = None
        self._jobs: list[FigureJob] = []
        self._sender: threading.Thread | None = None
        self._send_error: Exception | None = None

    @property
    def forked(self) -> bool:
        """Whether a forked process draws (``False``: everything is drawn here)."""
        return self._conn is not None

    def start(self) -> None:
        """Fork the drawing process (once; nothing when not enabled).

        Fork after the compiled kernels have been loaded (numba's set-up, 0.3 s, is then
        not repeated there) and before the work the process should overlap.
        """
        if not self.enabled or self._pid is not None:
            return
        from multiprocessing import Pipe

        mine, theirs = Pipe()
        try:
            pid = _fork()
        except OSError:  # no process to spare (a limit, memory): everything drawn here
            mine.close()
            theirs.close()
            self.enabled = False
            return
        if pid == 0:
            mine.close()
            _serve(theirs)
        theirs.close()
        self._conn, self._pid = mine, pid

    def submit(self, jobs: list[FigureJob]) -> None:
        """Hand the figures over (drawn meanwhile when forked, else by :meth:`wait`).

        The jobs (a long trace is several MB) are sent by a thread: the caller goes on
        while the forked process finishes its warm-up and reads them.
        """
        self._jobs = list(jobs)
        if self._conn is not None and self._jobs:
            self._sender = threading.Thread(
                target=self._send, args=(self._jobs,), name="clpc-painter-send"
            )
            self._sender.start()

    def _send(self, jobs: list[FigureJob]) -> None:
        try:
            self._conn.send(jobs)
        except Exception as exc:  # an unpicklable job, the process gone: drawn here
            self._send_error = exc

    def wait(self) -> None:
        """Return when every submitted figure is written.

        Raises
        ------
        Exception
            Whatever a figure raises (one that failed in the forked process is drawn
            again here, so its error comes with its own traceback).
        """
        jobs, failed = self._jobs, list(range(len(self._jobs)))
        self._jobs = []
        sent, self._sender = self._sender, None
        if sent is not None:
            sent.join()
        if self._send_error is not None:
            self._send_error = None
            self.close(kill=True)
        if sent is not None and self._conn is not None:
            try:
                if self._conn.poll(TIMEOUT):
                    failed = list(self._conn.recv())
                else:
                    self.close(kill=True)
            except Exception:  # the process died: draw here
                self.close(kill=True)
        draw_here([jobs[i] for i in failed])

    def draw(self, jobs: list[FigureJob]) -> None:
        """:meth:`submit` then :meth:`wait`."""
        self.submit(jobs)
        self.wait()

    def close(self, kill: bool = False) -> None:
        """End the forked process (``kill``: at once, without waiting for its warm-up)."""
        if self._conn is None or self._pid is None:
            return
        if self._sender is not None and not kill:
            self._sender.join()
        conn, pid = self._conn, self._pid
        self._conn = self._pid = None
        try:
            if kill:
                os.kill(pid, signal.SIGKILL)
            else:
                conn.send(None)
        except OSError:
            pass
        conn.close()
        try:
            os.waitpid(pid, 0)
        except ChildProcessError:
            pass

    def __enter__(self) -> Painter:
        return self

    def __exit__(self, exc_type: Any, *rest: Any) -> None:
        self.close(kill=exc_type is not None)
