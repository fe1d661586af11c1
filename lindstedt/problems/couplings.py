"""Polynomial couplings ``ε g(X)`` as elements ``ε Σ_i w_i (a_iᵀ X)^d_i``, exactly.

A :class:`~lindstedt.UnilateralSystem` may carry a force ``ε g(X)``, one polynomial ``g_r`` per degree of freedom
in the displacements ``x1 … xN`` (smooth couplings such as the geometric term ``x1**2*x2``).  Every monomial
``x^α`` of degree ``d = |α|`` is a combination of ``d``-th powers of linear forms (polarization):

    d! · x^α = Σ_{0 ≤ β ≤ α} (−1)^{d − |β|} ∏_i C(α_i, β_i) (β · x)^d.

(Proof: the coefficient of ``x^γ`` (``|γ| = d``) on the right is ``d!/γ! ∏_i Δ^{α_i}[t^{γ_i}](0)``, the
``α_i``-th forward difference of ``t^{γ_i}`` at 0, which is ``α_i! S(γ_i, α_i)`` (Stirling numbers of the second
kind), zero unless ``γ_i ≥ α_i``; with ``|γ| = |α|`` only ``γ = α`` remains, giving ``d!``.)  The term ``β = 0``
vanishes.  Each ``(β · x)^d`` is written on the primitive row ``a = β / gcd(β)`` as ``gcd(β)^d (a · x)^d``, and the
terms of every monomial of every component with the same ``(a, d)`` are summed into one force column ``w``
(``w_r`` collects component ``r``), so the elements are the distinct ``(a, d)`` with a nonzero column — element
``ε w (aᵀ X)^d``: row ``a`` of A, offset 0, law ``u**d``.  Arithmetic is exact (sympy rationals times the
polynomial's own exact coefficients).

Constant terms are loads and linear terms stiffness: both are refused with the fix (:func:`read_couplings`).
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import sympy

from .._errors import ParameterError, ProblemError, UnsupportedNonlinearityError
from .parsing import parse_expression

__all__ = ["MAX_TERMS", "coupling_elements", "displacements", "read_couplings"]

#: the most terms ``(β · x)^d`` the couplings of one system may expand into (``∏ (α_i + 1)`` per monomial), checked
#: before they are formed
MAX_TERMS = 20_000


def displacements(n: int) -> tuple[sympy.Symbol, ...]:
    """The displacement symbols ``x1 … xN`` (real) in which couplings are written.

    Examples
    --------
    >>> displacements(3)
    (x1, x2, x3)
    """
    return tuple(sympy.Symbol(f"x{k}", real=True) for k in range(1, n + 1))


def read_couplings(couplings: Any, n: int) -> tuple[sympy.Expr, ...]:
    """One polynomial ``g_r(x1 … xN)`` per degree of freedom, read by the one parser and checked.

    Strings go through :func:`~lindstedt.problems.parsing.parse_expression` with the names ``x1 … xN``; sympy
    expressions may use any symbols named ``x1 … xN``.  Refused with a :class:`~lindstedt.ProblemError` naming the
    fix: a count other than N, another name, a constant term (a load) or a linear term (a stiffness); with an
    :class:`~lindstedt.UnsupportedNonlinearityError`: an expression that is not a polynomial.

    Examples
    --------
    >>> read_couplings(["x1**2*x2", "(x1 + x2)**3/3"], 2)
    (x1**2*x2, x1**3/3 + x1**2*x2 + x1*x2**2 + x2**3/3)
    >>> read_couplings(["x1**2 + 1", "0"], 2)
    Traceback (most recent call last):
        ...
    lindstedt._errors.ProblemError: couplings[0] = 'x1**2 + 1' has the constant term 1: a constant force is a static load, not a coupling; write the problem about the loaded static equilibrium (X measured from it), where the load is gone and K and the couplings carry its shifted terms
    """
    symbols = displacements(n)
    names = {str(symbol): symbol for symbol in symbols}
    allowed = ", ".join(names) if n <= 3 else f"x1 … x{n}"
    if isinstance(couplings, (str, bytes, sympy.Basic)) or not isinstance(couplings, Sequence):
        raise ProblemError(f"couplings must be a list of one polynomial per degree of freedom ({n}), in {allowed}, "
                           f"e.g. {['x1**3'] + ['0'] * (n - 1)!r}; got {couplings!r}")
    if len(couplings) != n:
        raise ProblemError(f"couplings must have one polynomial per degree of freedom ({n}; '0' where there is none), "
                           f"got {len(couplings)}")
    read = []
    for r, text in enumerate(couplings):
        what = f"couplings[{r}]"
        try:
            expression = parse_expression(text, symbols=names, what=what)
        except ParameterError as error:  # a name that is not x1 … xN
            raise ProblemError(f"{str(error).split(', which')[0]}; a coupling is a polynomial in the displacements "
                               f"{allowed} only (1-based: x1 is the first degree of freedom)") from None
        strangers = sorted(str(s) for s in expression.free_symbols if str(s) not in names)
        if strangers:
            raise ProblemError(f"{what} uses {strangers}; a coupling is a polynomial in the displacements {allowed} "
                               "only (1-based: x1 is the first degree of freedom)")
        expression = sympy.expand(expression.xreplace({s: names[str(s)] for s in expression.free_symbols}))
        if not expression.is_polynomial(*symbols):
            raise UnsupportedNonlinearityError(
                f"{what} = {text!r} is not a polynomial in {allowed}; write a force that is not polynomial as an "
                "element: a row a of A and its law f(u) of u = aᵀX − b (laws=[...])")
        for monomial, coefficient in sympy.Poly(expression, *symbols).terms() if expression != 0 else ():
            degree = sum(monomial)
            if degree == 0:
                raise ProblemError(
                    f"{what} = {text!r} has the constant term {coefficient}: a constant force is a static load, not a "
                    "coupling; write the problem about the loaded static equilibrium (X measured from it), where the "
                    "load is gone and K and the couplings carry its shifted terms")
            if degree == 1:
                j = monomial.index(1)
                raise ProblemError(
                    f"{what} = {text!r} has the linear term {coefficient}*x{j + 1}: a linear force is a stiffness; put "
                    f"it in K (symmetric, not scaled by ε), or, scaled by ε, as an element: row e_{j + 1} of A, "
                    f"law 'u', column {coefficient}·e_{r + 1} of W")
        read.append(expression)
    return tuple(read)


def coupling_elements(couplings: Sequence[sympy.Expr]) -> tuple[tuple[tuple[int, ...], int, tuple[sympy.Expr, ...]], ...]:
    """The elements ``(a, d, w)`` with ``g(X) = Σ w (aᵀ X)^d`` exactly, for polynomials read by :func:`read_couplings`.

    ``a`` is a primitive row of non-negative integers, ``w`` the force column (one exact entry per degree of
    freedom); one element per distinct ``(a, d)``, ordered by degree, then by ``a`` (decreasing lexicographically).

    Examples
    --------
    >>> x1, x2 = displacements(2)
    >>> for a, d, w in coupling_elements([x1**3, x1**2 * x2]):
    ...     print(a, d, w)
    (2, 1) 3 (0, 1/6)
    (1, 1) 3 (0, -1/3)
    (1, 0) 3 (1, -1)
    (0, 1) 3 (0, 1/6)
    """
    n = len(couplings)
    symbols = displacements(n)
    polynomials = [sympy.Poly(g, *symbols).terms() if g != 0 else [] for g in couplings]
    terms = sum(math.prod(k + 1 for k in monomial) for terms in polynomials for monomial, _ in terms)
    if terms > MAX_TERMS:
        raise ProblemError(f"the couplings expand into {terms} powers of linear forms, more than the bound of "
                           f"{MAX_TERMS}; lower their degrees, or give the forces as elements (rows of A with laws)")
    columns: dict[tuple[tuple[int, ...], int], list[sympy.Expr]] = {}
    for r, polynomial in enumerate(polynomials):
        for alpha, coefficient in polynomial:
            d = sum(alpha)
            scale = coefficient / sympy.factorial(d)
            for beta in _boxes(alpha):
                divisor = math.gcd(*beta)
                if divisor == 0:
                    continue
                weight = (-1) ** (d - sum(beta)) * math.prod(math.comb(ai, bi) for ai, bi in zip(alpha, beta))
                key = (tuple(bi // divisor for bi in beta), d)
                column = columns.setdefault(key, [sympy.Integer(0)] * n)
                column[r] += scale * weight * divisor**d
    order = sorted(columns, key=lambda key: (key[1], tuple(-k for k in key[0])))
    return tuple((a, d, tuple(columns[a, d])) for a, d in order if any(entry != 0 for entry in columns[a, d]))


def _boxes(alpha: tuple[int, ...]) -> list[tuple[int, ...]]:
    """Every β with 0 ≤ β ≤ α entrywise."""
    boxes: list[tuple[int, ...]] = [()]
    for bound in alpha:
        boxes = [box + (k,) for box in boxes for k in range(bound + 1)]
    return boxes
