"""Entry-point verbs of lindstedt: ``expand`` (Lindstedt–Poincaré for u'' + ω0² u + ε f(u) = 0)."""

from __future__ import annotations

from typing import Any, Mapping

from ._expansion import Expansion
from ._hierarchy import CacheInfo, LindstedtPoincare, cache_info, clear_cache, validate_order
from ._problem import Oscillator

__all__ = ["expand", "clear_cache", "cache_info", "CacheInfo"]


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
) -> Expansion:
    """Lindstedt–Poincaré expansion of ``u'' + ω0² u + ε f(u) = 0``, ``u(0) = a0``, ``u'(0) = 0``.

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

    Returns
    -------
    Expansion

    Examples
    --------
    >>> import lindstedt
    >>> lindstedt.expand("u**3", order=2, normalization="harmonic").omega
    (omega0, 3*a0**2/(8*omega0), -15*a0**4/(256*omega0**3))
    """
    validate_order(order)
    if isinstance(f, Oscillator):
        if a0 is not None or omega0 is not None or params is not None or normalization != "initial":
            raise TypeError("pass either an Oscillator or f with its problem arguments, not both")
        problem = f
    else:
        problem = Oscillator(f, a0=a0, omega0=omega0, params=params, normalization=normalization)
    # The hierarchy is taken from the process-wide cache (see lindstedt.clear_cache).
    return LindstedtPoincare(precision=precision, numeric=numeric).expand(problem, order)
