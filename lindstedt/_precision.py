"""One lock for mpmath's process-wide precision and for every lazily grown derivation.

mpmath keeps its working precision in one process-wide context (``mpmath.mp``): ``mpmath.workdps(n)``
sets it for every thread, and restores on exit whatever it found on entry, so two threads inside such
blocks compute at each other's precision and can leave it changed for good.  The hierarchies of
:mod:`lindstedt.engine` grow order by order on first use (lists appended, memo dictionaries filled);
two threads extending one of them at once append the same order twice and poison it for the rest of the
process.  Both are one problem — shared mutable state of a GIL-bound computation — with one answer:

* :data:`LOCK`, one process-wide re-entrant lock;
* :class:`workdps` / :class:`workprec` take it and then set mpmath's precision (the package's only way
  to change it), so a thread's precision holds for the whole block;
* :func:`locked` takes it around a method that grows a shared structure or computes with mpmath numbers
  at the ambient precision.

A single lock cannot deadlock against itself (re-entrant, and nothing taken inside it waits for another
thread's lock), and costs nothing measurable: derivation is bound to the GIL anyway, and the compiled
float evaluators of the results never take it.  :class:`cached_property` is ``functools.cached_property``
without the per-class lock that Python ≤ 3.11 holds while computing (shared by every instance: a
computation that takes :data:`LOCK` under it deadlocks against a thread holding :data:`LOCK` that reads
the same property of another instance); a value computed twice by two threads is the same value.
"""

from __future__ import annotations

import functools
import threading
from typing import Any, Callable, TypeVar

import mpmath

__all__ = ["LOCK", "cached_property", "locked", "workdps", "workprec"]

#: The lock of mpmath's process-wide precision and of the package's lazily grown derivations.
LOCK = threading.RLock()

Function = TypeVar("Function", bound=Callable[..., Any])


class workprec:
    """``with workprec(bits):`` — mpmath at ``bits`` bits of precision, this thread only (holds :data:`LOCK`).

    Examples
    --------
    >>> import mpmath
    >>> with workprec(100):
    ...     mpmath.mp.prec
    100
    """

    __slots__ = ("_precision", "_saved")

    def __init__(self, bits: int):
        self._precision = bits

    def _set(self, value: int) -> None:
        mpmath.mp.prec = value

    def __enter__(self) -> None:
        LOCK.acquire()
        try:
            self._saved = mpmath.mp.prec
            self._set(self._precision)
        except BaseException:
            LOCK.release()
            raise

    def __exit__(self, *_: Any) -> None:
        try:
            mpmath.mp.prec = self._saved
        finally:
            LOCK.release()


class workdps(workprec):
    """``with workdps(digits):`` — mpmath at ``digits`` decimal digits, this thread only (holds :data:`LOCK`).

    The drop-in replacement of ``mpmath.workdps`` used everywhere in the package.

    Examples
    --------
    >>> import mpmath
    >>> with workdps(40):
    ...     print(mpmath.mp.dps, mpmath.mpf(1) / 3)
    40 0.3333333333333333333333333333333333333333
    """

    __slots__ = ()

    def _set(self, value: int) -> None:
        mpmath.mp.dps = value


def locked(function: Function) -> Function:
    """``function`` run under :data:`LOCK` (a method that grows a shared structure, or computes with mpmath).

    Examples
    --------
    >>> @locked
    ... def held():
    ...     return LOCK._is_owned()
    >>> held()
    True
    """

    @functools.wraps(function)
    def run(*args: Any, **kwargs: Any) -> Any:
        with LOCK:
            return function(*args, **kwargs)

    return run  # type: ignore[return-value]


class cached_property(functools.cached_property):  # noqa: N801 — the name of what it replaces
    """``functools.cached_property`` without Python ≤ 3.11's class-wide lock (Python 3.12 semantics).

    Examples
    --------
    >>> class Box:
    ...     @cached_property
    ...     def value(self):
    ...         return [1]
    >>> box = Box()
    >>> box.value is box.value
    True
    """

    def __get__(self, instance: Any, owner: Any = None) -> Any:
        if instance is None:
            return self
        cache = instance.__dict__
        try:
            return cache[self.attrname]
        except KeyError:
            value = self.func(instance)
            return cache.setdefault(self.attrname, value)  # a value another thread stored first wins
