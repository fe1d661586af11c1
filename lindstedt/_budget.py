"""The machinery of :mod:`lindstedt.limits`: budgets, estimates, checkpoints (see that module for the story)."""

from __future__ import annotations

import contextlib
import contextvars
import math
import os
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any, Callable

from ._errors import BudgetError, Cancelled, ProblemError

__all__ = [
    "DEFAULT",
    "FACTOR",
    "Budget",
    "BudgetError",
    "Cancelled",
    "Estimate",
    "Progress",
    "budget",
    "checkpoint",
    "current",
    "set_default",
]

#: How far a measured cost may lie from its estimate on the benchmark machine (either way).
FACTOR = 5.0


def _limit(value: Any, what: str) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise ProblemError(f"a budget's {what} must be a positive finite number or None (no limit), got {value!r}")
    return float(value)


@dataclass(frozen=True)
class Budget:
    """The most a request may cost: CPU ``seconds`` and ``memory_mb`` megabytes (None: no limit).

    Examples
    --------
    >>> Budget(seconds=60)
    Budget(seconds=60.0, memory_mb=2048.0)
    >>> Budget(seconds=-1)
    Traceback (most recent call last):
    ...
    lindstedt._errors.ProblemError: a budget's seconds must be a positive finite number or None (no limit), got -1
    """

    seconds: float | None = 600.0
    memory_mb: float | None = 2048.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "seconds", _limit(self.seconds, "seconds"))
        object.__setattr__(self, "memory_mb", _limit(self.memory_mb, "memory_mb"))


#: The budget in force outside any ``with budget(...)`` block (see :func:`set_default`).
DEFAULT = Budget()
_default = DEFAULT
_default_lock = threading.Lock()


def set_default(new: Budget) -> Budget:
    """Make ``new`` the budget of every request outside a ``with budget(...)`` block; returns the previous one.

    Examples
    --------
    >>> previous = set_default(Budget(seconds=30, memory_mb=512))
    >>> current()
    Budget(seconds=30.0, memory_mb=512.0)
    >>> _ = set_default(previous)
    """
    global _default
    if not isinstance(new, Budget):
        raise ProblemError(f"set_default takes a lindstedt.limits.Budget, got {type(new).__name__}")
    with _default_lock:
        previous, _default = _default, new
    return previous


def _seconds_text(seconds: float) -> str:
    return f"{seconds:.2g} s" if seconds < 1e4 else f"{seconds:.1e} s ({seconds / 86400:.2g} days)"


@dataclass(frozen=True)
class Estimate:
    """What a request is expected to cost before it runs: CPU ``seconds`` and ``memory_mb`` of growth, the
    ``drivers`` they come from (``(name, value)`` pairs: order, breakpoints, digits, ...), and ``advice`` on making
    the request cheaper; ``features`` are the model's inputs x of ``log T = θ · x`` (what a benchmark refits θ on).
    The model holds within :data:`FACTOR` on the benchmark machine; ``least`` marks an estimate of the least the
    request can cost (a search whose length is not known before it runs: its checkpoints watch the rest).

    Examples
    --------
    >>> estimate = Estimate("a loop", seconds=120.0, memory_mb=50.0, drivers=(("steps", 10**6),), advice="take fewer steps")
    >>> print(estimate)
    a loop: ~1.2e+02 s and ~50 MB (steps 1000000)
    >>> with budget(seconds=60):
    ...     estimate.check()
    Traceback (most recent call last):
    ...
    lindstedt._errors.BudgetError: a loop: ~1.2e+02 s and ~50 MB (steps 1000000) estimated (within a factor 5), above the time budget of 60 s: take fewer steps; or raise the budget with lindstedt.limits.budget(seconds=...) (command line: --budget SECONDS)
    """

    task: str
    seconds: float
    memory_mb: float
    drivers: tuple[tuple[str, Any], ...] = ()
    advice: str = ""
    features: tuple[tuple[str, float], ...] = field(default=(), repr=False)
    least: bool = False

    def __str__(self) -> str:
        drivers = ", ".join(f"{name} {value}" if value is not True else name for name, value in self.drivers)
        return (f"{self.task}: ~{_seconds_text(self.seconds)} and ~{self.memory_mb:.2g} MB"
                .replace(".0 MB", " MB") + (f" ({drivers})" if drivers else ""))

    def check(self, limits: Budget | None = None) -> Estimate:
        """``self`` if it fits ``limits`` (default: the budget in force, :func:`current`); else a
        :class:`BudgetError` naming the estimate, the limit and the knobs."""
        limits = current() if limits is None else limits
        over = None
        if limits.seconds is not None and self.seconds > limits.seconds:
            over = f"the time budget of {limits.seconds:g} s", "seconds=...) (command line: --budget SECONDS)"
        elif limits.memory_mb is not None and self.memory_mb > limits.memory_mb:
            over = f"the memory budget of {limits.memory_mb:g} MB", "memory_mb=...) (command line: --budget-memory MB)"
        if over is None:
            return self
        advice = f"{self.advice}; or r" if self.advice else "R"
        how = "at the least" if self.least else f"estimated (within a factor {FACTOR:g})"
        raise BudgetError(f"{self} {how}, above {over[0]}: {advice}aise the budget "
                          f"with lindstedt.limits.budget({over[1]}", estimate=self, up_front=True)


@dataclass(frozen=True)
class Progress:
    """What a checkpoint reports to a ``progress`` callback: ``stage`` (what runs), ``done`` of ``total`` steps
    (``total`` None when unknown) and the ``seconds`` since the ``with budget(...)`` block began."""

    stage: str
    done: int
    total: int | None
    seconds: float


@dataclass
class _Watch:
    """One ``with budget(...)`` block: its limits, when and at what memory it began, its event and callback."""

    limits: Budget
    started: float
    resident: float | None
    cancel: Any
    progress: Callable[[Progress], Any] | None
    outer: _Watch | None = field(default=None, repr=False)


_WATCH: contextvars.ContextVar[_Watch | None] = contextvars.ContextVar("lindstedt_budget", default=None)
_KEEP: Any = object()


def current() -> Budget:
    """The budget in force here: the innermost ``with budget(...)`` block's, else the default.

    Examples
    --------
    >>> with budget(seconds=5):
    ...     current().seconds
    5.0
    """
    watch = _WATCH.get()
    return _default if watch is None else watch.limits


@contextlib.contextmanager
def budget(seconds: Any = _KEEP, memory_mb: Any = _KEEP, *, cancel: Any = None,
           progress: Callable[[Progress], Any] | bool | None = None) -> Iterator[Budget]:
    """Run a block within ``seconds`` of time and ``memory_mb`` megabytes of growth (None: no limit; a limit not
    given is kept from the enclosing block or the default).

    Requests priced above the budget are refused before they start (:class:`BudgetError`); the block's
    checkpoints stop the work once its time or memory is spent (:class:`BudgetError`), once ``cancel`` (anything
    with ``is_set()``, e.g. a ``threading.Event``) is set (:class:`Cancelled`), and report to ``progress`` (a
    callable taking a :class:`Progress`, or ``True`` for tqdm bars, one per stage).
    The block holds in the thread (and the tasks of ``concurrent.futures`` sweeps) that entered it.

    Examples
    --------
    >>> import threading, lindstedt
    >>> lindstedt.clear_cache()              # every order below is solved here, none read from the cache
    >>> stop = threading.Event()
    >>> seen = []
    >>> def report(step):
    ...     seen.append(step.done)
    ...     if step.done == 3:
    ...         stop.set()
    >>> with budget(cancel=stop, progress=report):
    ...     lindstedt.expand("u**3 + u**5", order=12, a0=1, omega0=1).omega
    Traceback (most recent call last):
    ...
    lindstedt._errors.Cancelled: cancelled at order 4 of 12 ...
    >>> seen
    [1, 2, 3]
    """
    outer = _WATCH.get()
    base = current()
    limits = Budget(base.seconds if seconds is _KEEP else seconds, base.memory_mb if memory_mb is _KEEP else memory_mb)
    if cancel is not None and not callable(getattr(cancel, "is_set", None)):
        raise ProblemError(f"cancel must have an is_set() method (e.g. threading.Event()), got {type(cancel).__name__}")
    if progress is True:
        progress = _bars()
    elif progress is not None and progress is not False and not callable(progress):
        raise ProblemError(f"progress must be a callable or True (tqdm bars), got {type(progress).__name__}")
    progress = progress or None
    watch = _Watch(limits, time.monotonic(), _resident_mb(), cancel, progress, outer)
    token = _WATCH.set(watch)
    try:
        yield limits
    finally:
        _WATCH.reset(token)


def tqdm_or_warn() -> Any:
    """tqdm's bar class for ``progress=True``; None, with a warning naming ``pip install tqdm`` (attributed to the
    caller's line), when the optional dependency is missing (the budget's bars and the sweeps' bar)."""
    try:
        from tqdm.auto import tqdm
    except ImportError:
        from ._precision import warn_caller

        warn_caller(UserWarning("progress=True needs tqdm: pip install tqdm (no progress bar shown)"))
        return None
    return tqdm


def _bars() -> Callable[[Progress], Any] | None:
    """A ``progress`` callback drawing one tqdm bar per stage (orders, continuation points, ...); None when tqdm is
    missing (:func:`tqdm_or_warn`)."""
    tqdm = tqdm_or_warn()
    if tqdm is None:
        return None
    bars: dict[str, Any] = {}

    def report(step: Progress) -> None:
        bar = bars.get(step.stage)
        if bar is None or bar.total != step.total:
            if bar is not None:
                bar.close()
            bar = bars[step.stage] = tqdm(total=step.total, desc=step.stage, leave=False)
        bar.update(step.done - bar.n)

    return report


def _resident_mb() -> float | None:
    """The process's resident memory now, in MB (Linux ``/proc/self/statm``), else None (not watched)."""
    try:
        with open("/proc/self/statm", "rb") as statm:
            pages = int(statm.read().split()[1])
    except (OSError, ValueError, IndexError):
        return None
    return pages * _PAGE / 2**20


try:
    _PAGE = os.sysconf("SC_PAGE_SIZE")
except (AttributeError, ValueError, OSError):  # not POSIX: memory is priced, not watched
    _PAGE = 4096


def checkpoint(stage: str, done: int, total: int | None = None) -> None:
    """A point where a long request may stop: checks every enclosing ``with budget(...)`` block (time, memory,
    cancel event) and reports ``Progress(stage, done, total, seconds)`` to their callbacks.

    The package calls it between orders, continuation steps and Newton iterations; call it in your own loops
    over lindstedt requests to make them cancellable the same way.  Outside any block it costs one lookup.

    Examples
    --------
    >>> checkpoint("step", 1, 10)          # no block: nothing to check
    >>> with budget(seconds=1e-9):
    ...     time.sleep(0.001)
    ...     checkpoint("step", 2, 10)
    Traceback (most recent call last):
    ...
    lindstedt._errors.BudgetError: stopped at step 2 of 10 after 0.0... s, over the time budget ...
    """
    watch = _WATCH.get()
    while watch is not None:
        _check(watch, stage, done, total)
        watch = watch.outer


def _check(watch: _Watch, stage: str, done: int, total: int | None) -> None:
    elapsed = time.monotonic() - watch.started
    where = f"{stage} {done}" + (f" of {total}" if total is not None else "")
    if watch.cancel is not None and watch.cancel.is_set():
        raise Cancelled(f"cancelled at {where} after {elapsed:.3g} s (the cancel event of lindstedt.limits.budget "
                        "was set)")
    limits = watch.limits
    if limits.seconds is not None and elapsed > limits.seconds:
        raise BudgetError(f"stopped at {where} after {elapsed:.3g} s, over the time budget of {limits.seconds:g} s; "
                          "raise it with lindstedt.limits.budget(seconds=...) (command line: --budget SECONDS) or ask "
                          "for less")
    if limits.memory_mb is not None and watch.resident is not None:
        grown = (_resident_mb() or watch.resident) - watch.resident
        if grown > limits.memory_mb:
            raise BudgetError(f"stopped at {where} after the process grew by {grown:.0f} MB, over the memory budget "
                              f"of {limits.memory_mb:g} MB; raise it with lindstedt.limits.budget(memory_mb=...) "
                              "(command line: --budget-memory MB) or ask for less")
    if watch.progress is not None:
        watch.progress(Progress(stage, done, total, elapsed))
