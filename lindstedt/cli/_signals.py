"""Ctrl-C while a ``lindstedt`` command runs: a KeyboardInterrupt that no library can lose.

Python turns SIGINT into a KeyboardInterrupt wherever the program is, and some libraries swallow it: mpmath
imports gmpy2 inside a bare ``except: pass`` (a Ctrl-C in those ~30 ms was silently ignored and the command
ran to its end), an import lock's weakref callback reports it as "Exception ignored" and goes on.  While a
command runs, :data:`INTERRUPTS` remembers every SIGINT, :meth:`Interrupts.check` raises it again at the
command's checkpoints (each progress step, the end), and such imports run with the interrupt deferred.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Iterator
from typing import Any

__all__ = ["INTERRUPTS", "Interrupts"]


class Interrupts:
    """The SIGINT handler of a running command (installed by ``with INTERRUPTS:``, in the main thread only).

    Examples
    --------
    >>> with Interrupts() as interrupts, interrupts.deferred():
    ...     interrupts.received      # a SIGINT here would set it, and be raised as the block ends
    False
    >>> interrupts.check()           # no Ctrl-C came: nothing to raise
    """

    def __init__(self) -> None:
        self.received, self.deferring, self.ignoring = False, 0, False
        self._saved: tuple[Any, Any] | None = None

    def __enter__(self) -> Interrupts:
        self.received, self.deferring, self.ignoring = False, 0, False
        if threading.current_thread() is threading.main_thread():  # only it may set signal handlers
            self._saved = (signal.signal(signal.SIGINT, self._handle), sys.unraisablehook)
            sys.unraisablehook = self._unraisable
        return self

    def __exit__(self, *_: Any) -> None:
        if self._saved is not None:
            handler, sys.unraisablehook = self._saved
            signal.signal(signal.SIGINT, handler if handler is not None else signal.SIG_DFL)
            self._saved = None

    def _handle(self, signum: int, frame: Any) -> None:
        if self.ignoring:
            return
        self.received = True
        if not self.deferring:
            raise KeyboardInterrupt

    def _unraisable(self, unraisable: Any) -> None:
        """A KeyboardInterrupt raised in a callback is remembered (``received``), not printed."""
        if not issubclass(unraisable.exc_type, KeyboardInterrupt):
            self._saved[1](unraisable)

    def check(self) -> None:
        """Raise KeyboardInterrupt if a Ctrl-C came (and was lost on the way)."""
        if self.received and not self.ignoring:
            raise KeyboardInterrupt

    @contextlib.contextmanager
    def deferred(self) -> Iterator[None]:
        """A block during which a Ctrl-C is only remembered; it is raised when the block ends."""
        self.deferring += 1
        try:
            yield
        finally:
            self.deferring -= 1
        self.check()

    def ignore(self) -> None:
        """From now on (the command is ending) a Ctrl-C does nothing."""
        self.ignoring = True


#: the handler of the command that runs in this process
INTERRUPTS = Interrupts()
