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
  at the ambient precision;
* :func:`locked_methods` takes it around every public method of a class (its constructor and displays too).

sympy changes mpmath's precision as well, without asking: its numerical evaluation of a number such as
``acos(1/3)`` — in ``float()``, ``is_positive``, a comparison, printing (which orders terms by their value),
``collect`` — runs ``with mpmath.workprec(prec)`` (``Function._eval_evalf``), down to about 10 bits.  So every
public entry point of the package that does sympy or mpmath work holds the lock: problem construction, the
derivations, the results' symbolic views and exports, code generation, the references and validations
(:func:`locked` on functions, :func:`locked_methods` on classes).  Only pure-float paths stay lock-free — the
numerical integrators, and the float evaluators of a result once their data is compiled: :func:`locked_methods`
names them, and each takes the lock itself on its slow path (``tests/test_threads.py`` records every change of
mpmath's precision made without the lock over a representative set of public calls: there is none).
User code that evaluates sympy numbers or sets mpmath's precision beside lindstedt's threads holds
:func:`precision_lock` (the same lock, public).  A lock wrapper is a frame between the user and a warning:
:func:`warn_caller` attributes the results' warnings to the user's line all the same.

A single lock cannot deadlock against itself (re-entrant, and nothing taken inside it waits for another
thread's lock: the functions that run tasks on an executor hold it only in their tasks' sympy steps), and
costs about 0.2 µs uncontended: derivation is bound to the GIL anyway, and the float paths never take it
(``Expansion.frequency``'s scalar fast path; ``displacement`` and ``velocity`` evaluate the waveform over
the times outside it).  :class:`cached_property` is ``functools.cached_property``
without the per-class lock that Python ≤ 3.11 holds while computing (shared by every instance: a
computation that takes :data:`LOCK` under it deadlocks against a thread holding :data:`LOCK` that reads
the same property of another instance); a value computed twice by two threads is the same value.
"""

from __future__ import annotations

import contextlib
import functools
import os
import sys
import threading
import warnings
from typing import Any, Callable, TypeVar

import mpmath

__all__ = ["LOCK", "cached_property", "locked", "locked_methods", "precision_lock", "warn_caller", "workdps", "workprec"]

#: The lock of mpmath's process-wide precision and of the package's lazily grown derivations.
LOCK = threading.RLock()

Function = TypeVar("Function", bound=Callable[..., Any])


def precision_lock() -> Any:
    """The package's lock of mpmath's process-wide precision: a re-entrant lock (``threading.RLock``).

    Every public call of lindstedt that computes with sympy or mpmath holds it, so that no other call changes
    mpmath's working precision meanwhile.  Your own code is not covered: sympy evaluating a number such as
    ``acos(1/3)`` (in ``float()``, a comparison, printing) and ``mpmath.workdps`` set the one precision of the
    process too.  If such code runs in one thread while another thread uses lindstedt, hold this lock around it.

    Examples
    --------
    >>> import lindstedt, mpmath, sympy
    >>> with lindstedt.precision_lock():
    ...     with mpmath.workdps(30):
    ...         value = mpmath.acos(mpmath.mpf(1) / 3)
    ...     number = float(sympy.acos(sympy.Rational(1, 3)))
    >>> mpmath.nstr(value, 20), round(number, 12)
    ('1.2309594173407746821', 1.230959417341)
    """
    return LOCK


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

    if getattr(function, "__locked__", False):
        return function

    @functools.wraps(function)
    def run(*args: Any, **kwargs: Any) -> Any:
        with LOCK:
            return function(*args, **kwargs)

    run.__locked__ = True  # type: ignore[attr-defined]
    return run  # type: ignore[return-value]


#: Non-public names that are entry points too: the constructor, calls and the displays (repr, str, IPython's).
_ENTRY_DUNDERS = frozenset({"__init__", "__call__", "__repr__", "__str__", "__format__", "_ipython_display_"})


def _is_entry(name: str) -> bool:
    return not name.startswith("_") or name in _ENTRY_DUNDERS or (name.startswith("_repr_") and name.endswith("_"))


def _locked_member(owner: type, name: str, member: Any) -> Any:
    """``member`` (a class attribute) with its code run under :data:`LOCK`; None for what is not code."""
    if isinstance(member, staticmethod):
        return staticmethod(locked(member.__func__))
    if isinstance(member, classmethod):
        return classmethod(locked(member.__func__))
    if isinstance(member, functools.cached_property):  # computed once, then read from the instance lock-free
        wrapped = cached_property(locked(member.func))  # never functools' (its class-wide lock, Python <= 3.11)
        wrapped.__set_name__(owner, name)
        return wrapped
    if isinstance(member, property):
        return property(*(None if part is None else locked(part) for part in (member.fget, member.fset, member.fdel)),
                        member.__doc__)
    if callable(member) and not isinstance(member, type):
        return locked(member)
    return None


def locked_methods(*lock_free: str) -> Callable[[type], type]:
    """Class decorator: every public method, property and cached property the class defines — and its constructor,
    ``__call__`` and displays (``__repr__``, ``__str__``, IPython's ``_repr_*_``) — runs under :data:`LOCK`,
    except the ``lock_free`` ones: float evaluators whose fast path must not pay for the lock and whose slow
    path takes it itself.  Apply it above ``@dataclass`` (the generated constructor is then in the class).

    Examples
    --------
    >>> @locked_methods("fast")
    ... class Box:
    ...     def held(self):
    ...         return LOCK._is_owned()
    ...     def fast(self):
    ...         return LOCK._is_owned()
    >>> Box().held(), Box().fast()
    (True, False)
    """

    def decorate(cls: type) -> type:
        unknown = set(lock_free) - set(vars(cls))
        if unknown:
            raise TypeError(f"{cls.__name__} defines no {sorted(unknown)}")
        for name, member in list(vars(cls).items()):
            if name in lock_free or not _is_entry(name):
                continue
            wrapped = _locked_member(cls, name, member)
            if wrapped is not None:
                setattr(cls, name, wrapped)
        return cls

    return decorate


_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep


def warn_caller(warning: Warning) -> None:
    """``warnings.warn(warning)`` attributed to the first frame outside the package — the user's call — however
    many of the package's frames (the lock's wrappers among them, and contextlib's around a ``with`` block of the
    package) lie between.

    Examples
    --------
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warn_caller(UserWarning("checked"))
    >>> str(caught[0].message), caught[0].filename.endswith("_precision.py")
    ('checked', False)
    """
    frame, level = sys._getframe(0), 1
    while frame.f_back is not None and (frame.f_code.co_filename.startswith(_PACKAGE)
                                        or frame.f_code.co_filename == contextlib.__file__):
        frame, level = frame.f_back, level + 1
    warnings.warn(warning, stacklevel=level)


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
