"""The method of strained coordinates (Lindstedt–Poincaré) for u'' + ω0² u + ε f(u) = 0: the verb ``expand``.

:class:`LindstedtPoincare` chooses the engine for the problem — the smooth
hierarchy (:mod:`lindstedt.engine.smooth`, cosine series) or the branch one
(:mod:`lindstedt.engine.branches`, analytic branches between moving contact
angles, fed by :mod:`lindstedt.engine.contact`) — and wraps it in an :class:`~lindstedt.Expansion`.  Hierarchies are lazy
and kept in one bounded process-wide cache (:func:`clear_cache`, :func:`cache_info`).
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from typing import Any, Callable, Hashable, Mapping, NamedTuple

from .._errors import OrderError, ProblemError
from .._precision import LOCK, locked, locked_methods
from ..results.expansion import Expansion
from ..problems.oscillator import DISPLACEMENT, Oscillator
from ..problems.piecewise_linear import has_non_polynomial_law
from ..engine.branches import BranchHierarchy
from ..engine.contact import contact_normal_form
from ..engine.smooth import MAX_ORDER, SmoothHierarchy, normal_form
from ..compiled.family import forget_families
from .._cost import expansion_check, expansion_estimate
from ..limits import Estimate

__all__ = ["CACHE_MAXSIZE", "CacheInfo", "LindstedtPoincare", "cache_info", "clear_cache", "expand", "expansion_cost",
           "validate_order"]


#: Most hierarchies kept by the process-wide cache (least recently used evicted first).
CACHE_MAXSIZE = 64


class CacheInfo(NamedTuple):
    """Statistics of the hierarchy cache (see :func:`cache_info`)."""

    hits: int
    misses: int
    size: int
    maxsize: int


class _HierarchyCache:
    """Process-wide LRU store of hierarchies, keyed by a canonical description of problem and method.

    A hierarchy is lazy and only ever grows (orders are appended, never
    changed), so one object serves every expansion of its problem: a higher
    order reuses the lower ones, a lower order reads them.
    """

    def __init__(self, maxsize: int):
        self.maxsize = maxsize
        self._entries: OrderedDict[Hashable, Any] = OrderedDict()
        self._lock = threading.Lock()
        self.hits = 0
        self.misses = 0

    def get(self, key: Hashable, build: Callable[[], Any]) -> Any:
        value = self._lookup(key)
        if value is not None:
            return value
        # A miss is built under the derivation lock (building is GIL-bound anyway): threads asking for the
        # same new problem build it once and the others find it.  The cache's own lock is never held while
        # waiting for that one (no lock-order deadlock).
        with LOCK:
            value = self._lookup(key)
            if value is not None:
                return value
            with self._lock:
                self.misses += 1
            value = build()
            with self._lock:
                self._entries[key] = value
                while len(self._entries) > self.maxsize:
                    self._entries.popitem(last=False)
        return value

    def _lookup(self, key: Hashable) -> Any:
        """The entry (counted as a hit), or None."""
        with self._lock:
            if key not in self._entries:
                return None
            self._entries.move_to_end(key)
            self.hits += 1
            return self._entries[key]

    def clear(self) -> None:
        with self._lock:
            self._entries.clear()
            self.hits = self.misses = 0

    def info(self) -> CacheInfo:
        with self._lock:
            return CacheInfo(self.hits, self.misses, len(self._entries), self.maxsize)


_CACHE = _HierarchyCache(CACHE_MAXSIZE)


def clear_cache() -> None:
    """Forget every cached hierarchy and compiled evaluator family (and reset the statistics of :func:`cache_info`).

    ``lindstedt.expand`` keeps the hierarchies of the last :data:`CACHE_MAXSIZE`
    (64) problems, so that asking again, or to a higher order, reuses the work
    done (float expansions of polynomial pieces, ``numeric=True`` on gaps, about a
    millisecond each, are derived afresh instead).  Results are the same with or
    without the cache; clearing frees the
    memory and makes the next expansion start from scratch (e.g. for timing).

    Examples
    --------
    >>> import lindstedt
    >>> lindstedt.clear_cache()
    >>> lindstedt.cache_info()
    CacheInfo(hits=0, misses=0, size=0, maxsize=64)
    >>> _ = lindstedt.expand("u**3", order=2, a0=1, omega0=1)
    >>> _ = lindstedt.expand("u**3", order=4, a0=1, omega0=1)
    >>> lindstedt.cache_info()
    CacheInfo(hits=1, misses=1, size=1, maxsize=64)
    >>> lindstedt.clear_cache()
    >>> lindstedt.cache_info().size
    0
    """
    _CACHE.clear()
    forget_families()


def cache_info() -> CacheInfo:
    """Hits, misses, current size and maximum size of the hierarchy cache (see :func:`clear_cache`).

    Examples
    --------
    >>> import lindstedt
    >>> lindstedt.cache_info().maxsize
    64
    """
    return _CACHE.info()


def _problem_key(problem: Oscillator) -> tuple:
    """Canonical, hashable description of ``problem``: exact sympy data in the problem's fixed symbols.

    Parameters are sorted by name (their declaration order does not change the problem).
    """
    params = tuple(sorted(problem.params, key=lambda item: item[0].name))
    key = (problem.f, problem.a0, problem.omega0, params, problem.normalization, problem.a1)
    if problem.has_initial_velocity:  # the turning-point series handed to the engine: its data and its length
        key += (problem.u0, problem.v0, problem.release_order, getattr(problem, "_release_digits", None))
    return key


def _release_order_for(order: int) -> int:
    """ε-orders of the turning-point series an order-``order`` expansion from (u0, v0) hands to its engine: N + 1.

    The evaluators ask for ω through ω_{N+2} (one more power of the gauge ε^{1/2} at grazing), whose
    waveforms need A_1 … A_{N+1}; :class:`~lindstedt.Expansion` refuses indices beyond what the series covers.
    """
    return order + 1


@locked_methods()
class LindstedtPoincare:
    """The method of strained coordinates (Lindstedt–Poincaré) for one oscillator.

    One verb: :meth:`expand`.  The hierarchy behind it is cached (process-wide,
    the last :data:`CACHE_MAXSIZE` problems, see :func:`clear_cache`), so
    expanding the same problem again, or to a higher order, reuses all the work
    already done — except a float hierarchy of polynomial pieces (``numeric=True``
    on gaps and clearances), which costs about a millisecond to derive and is
    derived afresh rather than kept.

    Parameters
    ----------
    precision : int
        Decimal digits for non-polynomial (analytic) f, whose expansion is
        numeric, and for ``numeric=True``.  Polynomial f is always exact.
    numeric : bool
        Piecewise-linear f: compute in a ``RealField`` of ``precision`` digits
        (fast) instead of exactly.  Floats in the input also select it.

    Examples
    --------
    >>> from lindstedt.problems.oscillator import Oscillator
    >>> method = LindstedtPoincare()
    >>> method.expand(Oscillator("u**3", a0=1, omega0=1), order=2).omega
    (1, 3/8, -21/256)
    """

    def __init__(self, precision: int = 30, numeric: bool = False):
        if not isinstance(precision, int) or precision < 15 or precision > 1000:
            raise ProblemError("precision must be an integer number of decimal digits between 15 and 1000")
        self.precision = precision
        self.numeric = bool(numeric)

    def _released(self, problem: Oscillator, order: int) -> Oscillator:
        """The problem from (u0, v0) with its turning-point series long enough for ``order`` (numeric hierarchies of
        non-polynomial analytic f get it rounded to the working digits plus 20)."""
        analytic = not problem.is_polynomial and not problem.is_non_smooth
        return problem.with_release_order(_release_order_for(order), self.precision + 20 if analytic else None)

    def hierarchy(self, problem: Oscillator, order: int = 4) -> tuple[Any, Any]:
        """The normal form of ``problem`` and its (cached) hierarchy: smooth, or the branch hierarchy.

        ``order`` is the highest order that will be asked for; float hierarchies
        of piecewise problems near grazing add guard digits for it.

        The cache key is the problem's exact data (:func:`_problem_key`) and what
        of the method's settings the hierarchy depends on: the working digits of
        a float hierarchy, ``precision`` for non-polynomial smooth f.  A problem
        from initial data (u0, v0) is expanded from its positive turning point,
        with the release series A_1 … A_{order+1} (:meth:`Oscillator.with_release_order`);
        u0, v0 and that length are part of the key.
        """
        if problem.has_initial_velocity:
            # (u0, v0): the release series A_1 … A_M must cover every order the hierarchy will be asked for
            problem = self._released(problem, order)
        problem_key = _problem_key(problem)
        if problem.is_non_smooth:
            # exact unless asked for floats or a piece is not polynomial (Hertz, exp: its contact arc is numeric)
            contact_law = has_non_polynomial_law(problem.nonlinearity, DISPLACEMENT)
            if not (self.numeric or contact_law):
                # Exact: the normal form does not depend on the order; it is built only on a miss
                # (its domain has fresh Dummy generators and must not enter the key).
                key, make_form = (problem_key, "piecewise", None), lambda: contact_normal_form(problem, None)
            else:
                # Float: the working digits (precision + guard digits near grazing, which grow with
                # the order) decide the hierarchy; the float normal form is cheap, build it to know them.
                form = contact_normal_form(problem, self.precision, order_hint=order + 1)
                key, make_form = (problem_key, "piecewise", form.domain.dps), lambda: form

            def build() -> tuple[Any, Any]:
                built = make_form()
                return built, BranchHierarchy(built.system, problem.normalization)

            if self.numeric and not contact_law:
                # Polynomial pieces in floats: derived afresh (~1.4 ms to order 4, 36 ms to order 20), not kept.
                # Kept, a sweep over a parameter turns the cache over at every value, and the evicted hierarchies
                # (~1000 objects each) outlive the young generations: measured over 600 new κ at 16 and 30
                # digits (two runs each), median unchanged (~1.5 ms), 99th percentile 6.5–15 → 1.7–2.9 ms.
                return build()
            return _CACHE.get(key, build)
        digits = None if problem.is_polynomial else self.precision

        def build_smooth() -> tuple[Any, Any]:
            built = normal_form(problem, self.precision)
            return built, SmoothHierarchy(built, problem.normalization)

        return _CACHE.get((problem_key, "smooth", digits), build_smooth)

    def estimate(self, problem: Oscillator, order: int) -> Estimate:
        """What :meth:`expand` of ``problem`` to ``order`` will cost (every ω_k, α_k, v_k up to ``order``): CPU
        seconds and memory from the cost model of :mod:`lindstedt.limits`, before any work.

        Examples
        --------
        >>> from lindstedt.problems.oscillator import Oscillator
        >>> LindstedtPoincare().estimate(Oscillator("u**3", a0=1, omega0=1), 10).seconds < 1
        True
        """
        validate_order(order)
        return expansion_estimate(problem, order, self.precision, self.numeric)

    def expand(self, problem: Oscillator, order: int):
        """Lindstedt–Poincaré expansion of ``problem`` to ``order``.

        The request is priced first (:meth:`estimate`) and refused with a :class:`~lindstedt.BudgetError`
        if it exceeds the budget in force (:mod:`lindstedt.limits`).

        Returns
        -------
        Expansion
            Lazy, frozen result; nothing beyond the requested quantities is computed.
        """
        validate_order(order)
        expansion_check(problem, order, self.precision, self.numeric)  # self.estimate(problem, order).check()
        form, hierarchy = self.hierarchy(problem, order)
        if problem.has_initial_velocity:  # the copy (== problem) that knows how far its release series goes
            problem = self._released(problem, order)
        return Expansion(problem=problem, order=order, _hierarchy=hierarchy, _form=form,
                         _method=self)


def validate_order(order: Any) -> int:
    """Check that ``order`` is an integer in [0, MAX_ORDER]."""
    if isinstance(order, bool) or not isinstance(order, int):
        raise OrderError(f"order must be an integer, got {order!r}")
    if order < 0:
        raise OrderError(f"order must be >= 0, got {order}")
    if order > MAX_ORDER:
        raise OrderError(
            f"order {order} is above the limit {MAX_ORDER}: the cost grows like order^4; ask for at most {MAX_ORDER}"
        )
    return order


@locked
def expand(
    f: Any,
    order: int = 2,
    *,
    a0: Any = None,
    omega0: Any = None,
    params: Mapping[str, Any] | None = None,
    normalization: str = "initial",
    precision: int = 30,
    numeric: bool = False,
    a1: Any = 0,
    u0: Any = None,
    v0: Any = None,
) -> Expansion:
    """Lindstedt–Poincaré expansion of ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = a0``, ``u'(0) = 0``
    (or ``u(0) = u0``, ``u'(0) = v0``).

    Parameters
    ----------
    f : str, sympy expression or Oscillator
        The nonlinearity in ``u`` (or a ready problem, then the other
        problem arguments must be left at their defaults).
    order : int
        Highest order N of ω_k, α_k, v_k.
    a0, omega0 : number, str or sympy expression, optional
        Amplitude and linear frequency; symbolic by default.
    params : mapping, optional
        Values of the parameters used by f (``None`` keeps one symbolic).
    normalization : {"initial", "harmonic"}
        ``a0`` is u(0), or the first-harmonic amplitude.
    precision : int
        Decimal digits for non-polynomial f (computed numerically) and for ``numeric=True``.
    numeric : bool
        Piecewise-linear f: work in ``precision``-digit floats instead of exactly
        (much faster at high order; exact inputs otherwise give exact results).
    a1 : number, str or sympy expression
        Release at u(0) = a0 + ε a1 (default 0), e.g. just inside a gap that a0 touches.
    u0, v0 : number or numeric string, optional
        General initial data u(0) = u0, u'(0) = v0 instead of ``a0``/``a1`` (a missing one is 0;
        ``"initial"`` normalization).  The expansion is released at the positive turning point
        A(ε) = Σ A_k ε^k of that orbit (``Expansion.amplitude``) and ``u(t) = v(ω t + φ(ε))``
        with the phase series ``Expansion.phase``; ``v0 = 0`` is exactly the release at rest
        ``a0 = u0``.

    Returns
    -------
    Expansion

    Examples
    --------
    >>> import lindstedt
    >>> lindstedt.expand("u**3", order=2, normalization="harmonic").omega
    (omega0, 3*a0**2/(8*omega0), -15*a0**4/(256*omega0**3))
    >>> moving = lindstedt.expand("u**3", order=1, u0="3/5", v0="4/5", omega0=1)
    >>> moving.amplitude, moving.omega                      # the orbit turns at A = 1 - 136/625 eps + ...
    ((1, -136/625), (1, 3/8))
    >>> round(float(moving.displacement(0.0, 0.01)), 4), round(float(moving.velocity(0.0, 0.01)), 4)   # O(eps^2)
    (0.6, 0.8)
    """
    validate_order(order)
    problem = _problem(f, a0=a0, omega0=omega0, params=params, normalization=normalization, a1=a1, u0=u0, v0=v0)
    # The hierarchy is taken from the process-wide cache (see lindstedt.clear_cache).
    return LindstedtPoincare(precision=precision, numeric=numeric).expand(problem, order)


def _problem(f: Any, **arguments: Any) -> Oscillator:
    """``f`` if it is an :class:`Oscillator` (then ``arguments`` must be the defaults), else the problem they make
    (``arguments``: those of :class:`Oscillator`, a0, omega0, params, normalization, a1, u0, v0)."""
    if isinstance(f, Oscillator):
        defaults = {"a0": None, "omega0": None, "params": None, "normalization": "initial", "a1": 0, "u0": None,
                    "v0": None}
        if any(arguments.get(name, default) is not default and arguments.get(name, default) != default
               for name, default in defaults.items()):
            raise TypeError("pass either an Oscillator or f with its problem arguments, not both")
        return f
    return Oscillator(f, **arguments)


@locked
def expansion_cost(f: Any, order: int = 2, *, precision: int = 30, numeric: bool = False, **problem: Any) -> Estimate:
    """What :func:`expand` with the same arguments will cost, before any work: an
    :class:`~lindstedt.limits.Estimate` (CPU seconds, memory, what drives them, how to make it cheaper).

    ``expand`` refuses a request whose estimate exceeds the budget in force (:mod:`lindstedt.limits`); this
    prices it without refusing.  ``problem`` holds expand's problem arguments (a0, omega0, params,
    normalization, a1, u0, v0).

    Examples
    --------
    >>> import lindstedt
    >>> cost = lindstedt.expansion_cost("Max(0, u - 1/3)", order=40, a0=1, omega0=1)
    >>> cost.seconds > lindstedt.limits.DEFAULT.seconds, dict(cost.drivers)["breakpoints"]
    (True, 1)
    >>> lindstedt.expansion_cost("Max(0, u - 1/3)", order=40, a0=1, omega0=1, numeric=True).seconds < 60
    True
    """
    return LindstedtPoincare(precision=precision, numeric=numeric).estimate(_problem(f, **problem), order)
