"""What a long command of ``lindstedt`` shows on stderr while it runs (stdout stays the result alone).

When stderr is a terminal and tqdm is installed: a bar (or a counter, when the total is unknown), cleared
when the command ends.  Otherwise (a pipe, a file, a CI log, no tqdm): one summary line when the command
succeeds, e.g. ``forced: 214 points, 2 folds, 3.1 s``.  A failure prints its ``error:`` line instead.
"""

from __future__ import annotations

import os
import sys
import time
from typing import Any, TextIO

from ._signals import INTERRUPTS

__all__ = ["Progress"]


class Progress:
    """``with Progress("forced", unit="point") as progress: ...; progress.update(status=...); progress.summary = "..."``.

    Parameters
    ----------
    name : str
        The command, printed first (the bar's label, the summary's prefix).
    total : int, optional
        The number of steps when known (a bar), else a counter.
    unit : str
        What a step is ("point", "order", ...).
    stream : file, optional
        Where to write (default: stderr at the time of the call).

    Examples
    --------
    >>> import io
    >>> stream = io.StringIO()
    >>> with Progress("expand", total=3, unit="order", stream=stream) as progress:
    ...     progress.update(3)
    ...     progress.summary = "orders 0-2"
    >>> stream.getvalue().startswith("expand: orders 0-2, ")
    True
    """

    def __init__(self, name: str, *, total: int | None = None, unit: str = "step", stream: TextIO | None = None) -> None:
        self.name, self.summary = name, ""
        self.stream = sys.stderr if stream is None else stream
        self.started = time.perf_counter()
        self.bar = self._bar(total, unit)

    def _bar(self, total: int | None, unit: str) -> Any:
        try:  # a terminal with a width (a pseudo-terminal of 0 columns would show an empty bar)
            terminal = self.stream.isatty() and os.get_terminal_size(self.stream.fileno()).columns > 0
        except (AttributeError, ValueError, OSError):  # no isatty or fileno, a closed stream
            terminal = False
        if not terminal:
            return None
        try:
            from tqdm import tqdm
        except ImportError:  # the optional dependency is missing: the summary line instead
            return None
        return tqdm(total=total, desc=self.name, unit=f" {unit}s", leave=False, file=self.stream, dynamic_ncols=True)

    def update(self, steps: int = 1, status: str | None = None) -> None:
        """Advance by ``steps``; ``status`` is shown after the bar (e.g. ``Ω = 1.13, 2 folds``).

        A checkpoint of Ctrl-C too: raises KeyboardInterrupt if one came and a library swallowed it.
        """
        INTERRUPTS.check()
        if self.bar is not None:
            if status is not None:
                self.bar.set_postfix_str(status, refresh=False)
            self.bar.update(steps)

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, kind: Any, *_: Any) -> None:
        """Clear the bar; without one, print the summary (when the block ended normally and set one)."""
        if self.bar is not None:
            self.bar.close()
        elif kind is None and self.summary:
            print(f"{self.name}: {self.summary}, {time.perf_counter() - self.started:.1f} s", file=self.stream, flush=True)
