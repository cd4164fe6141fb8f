"""What ``clpc stream`` meets outside the data: its pipes and the signals that stop it.

Exit codes of ``clpc stream`` beyond those of every command (0, 1, 2): 128 + the signal's
number when SIGHUP (129), SIGINT (130) or SIGTERM (143) stopped it, after the state was
saved; 141 (128 + SIGPIPE, as a tool the signal kills) when the reader of standard output
went away.
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Iterator
from types import FrameType, TracebackType

import click

from clpc.io.budget import LINE_ENV, limit, line_too_long
from clpc.workflows.stream_lines import CutLine

__all__ = ["EXIT_CLOSED_PIPE", "STOP_SIGNALS", "Interrupts", "Stopped", "stdin_batches"]

#: the signals that stop a stream (the state is saved first); those this system has
STOP_SIGNALS = tuple(
    getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name)
)
#: exit code when standard output was closed by its reader (128 + SIGPIPE)
EXIT_CLOSED_PIPE = 141


class Stopped(BaseException):
    """A stop signal arrived; ``signum`` is its number."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum

    @property
    def name(self) -> str:
        """The signal's name, e.g. ``"SIGTERM"``."""
        return signal.Signals(self.signum).name

    @property
    def exit_code(self) -> int:
        """128 + the signal's number, as a shell reports a process the signal killed."""
        return 128 + self.signum


class Interrupts:
    """Stop signals caught while in use: at once while waiting for input, else between batches.

    A sample batch is never cut in the middle, so the appraiser's state stays whole. Outside
    the main thread (where handlers cannot be set) the signals keep their handlers.
    """

    def __init__(self) -> None:
        self.signum: int | None = None
        self.waiting = False  # blocked on standard input: stop at once
        self._old: dict[int, object] = {}

    def __enter__(self) -> Interrupts:
        if threading.current_thread() is threading.main_thread():
            for sig in STOP_SIGNALS:
                self._old[sig] = signal.signal(sig, self._handle)
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        for sig, old in self._old.items():
            signal.signal(sig, old)  # type: ignore[arg-type]
        self._old = {}

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        self.signum = signum
        if self.waiting:
            raise Stopped(signum)

    def check(self) -> None:
        """Raise :class:`Stopped` if a stop signal arrived."""
        if self.signum is not None:
            raise Stopped(self.signum)


def stdin_batches(stops: Interrupts) -> Iterator[list[str]]:
    """Complete lines of standard input, in batches of what has arrived so far.

    ``read1`` returns what the pipe holds (at most 64 KiB) without waiting for more, so a
    slow producer gets its updates at once and a fast one is processed in vectorised batches.
    A last line without a newline comes as a :class:`CutLine`. One line may hold at most
    ``CLPC_MAX_LINE_BYTES`` bytes (:mod:`clpc.io.budget`, 4 MiB by default; its newline not
    counted): the unfinished line is kept in a growing buffer that is refused as soon as it
    passes the limit, so a longer line is never held whole and costs time linear in its
    length. The lines before it are yielded first.

    Parameters
    ----------
    stops : Interrupts
        Checked before each read; a stop signal while waiting ends the read at once.

    Yields
    ------
    list of str
        Lines without their newlines.

    Raises
    ------
    DataError
        A line longer than the line limit; the message names its line number, the limit
        and the variable that raises it.
    click.ClickException
        Standard input is closed.
    """
    if sys.stdin is None:
        raise click.ClickException(
            "standard input is closed; pipe the samples in (e.g. my_daq | clpc stream ...)."
        )
    longest = limit(LINE_ENV)
    raw = getattr(sys.stdin, "buffer", None)
    text_only = raw is None or not hasattr(raw, "read1")
    rest = bytearray()  # the start of a line whose newline has not arrived yet
    done = 0  # lines yielded so far
    while True:
        stops.check()
        stops.waiting = True
        try:
            if text_only:
                block = sys.stdin.readline(longest + 1).encode("utf-8", errors="replace")
            else:
                assert raw is not None
                block = raw.read1(1 << 16)
        except ValueError:  # "I/O operation on closed file"
            raise click.ClickException("standard input was closed while reading.") from None
        finally:
            stops.waiting = False
        if not block:
            break
        end = block.rfind(b"\n")
        if end < 0:
            rest += block  # amortised: no copy of the whole line per block
            if len(rest) > longest:
                raise line_too_long("standard input", done + 1)
            continue
        lines = (rest + block[:end]).split(b"\n")
        rest = bytearray(block[end + 1 :])
        long = next((i for i, line in enumerate(lines) if len(line) > longest), None)
        if long is not None:
            if long:
                yield [line.decode("utf-8", errors="replace") for line in lines[:long]]
            raise line_too_long("standard input", done + long + 1)
        done += len(lines)
        yield [line.decode("utf-8", errors="replace") for line in lines]
        if len(rest) > longest:
            raise line_too_long("standard input", done + 1)
    if rest:
        yield [CutLine(rest.decode("utf-8", errors="replace"))]
