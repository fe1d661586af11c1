"""Piecewise-polynomial nonlinearities f(u): unilateral springs a·(u − b)_+, contact laws such as
(u − b)_+², u|u|, forces that jump, c·H(u − b).

Any such f can be written with breakpoints ``u_1 < … < u_n`` and one polynomial
``f(u) = Σ_m c_{j,m} u^m`` on each of the n + 1 intervals.  :func:`decompose_piecewise`
finds that form from an expression written with ``Max``/``Min``/``Abs``/``Heaviside``/
``sign``/``Piecewise`` (``a*Max(0, u - b)``, ``a*(u - b)*Heaviside(u - b)``, sums of
several springs on either side, ``Max(0, -u - b)`` for a spring acting on negative
displacements, ``Max(0, u)**2``, ``u*Abs(u)``, ``Heaviside(u)*u**2``, plus any
polynomial, and ``c*Heaviside(u - b)``, ``sign(u)``: a force that jumps at the
breakpoint), and refuses anything else with a message that names what is supported.
A jump is allowed: u stays C¹ across it (u'' jumps), which is all the branch
hierarchy's matching needs.  :func:`decompose_piecewise_linear` is the degree-one case
(the exact piecewise-linear flow needs it).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy

from .._errors import UnsupportedNonlinearityError

__all__ = ["PolynomialInterval", "decompose_piecewise", "decompose_piecewise_linear", "has_non_polynomial_law"]

_SWITCHING = (sympy.Max, sympy.Min, sympy.Abs, sympy.Heaviside, sympy.sign, sympy.Piecewise)
_SUPPORTED = (
    "supported non-smooth f: piecewise-polynomial laws such as a*Max(0, u - b), "
    "a*(u - b)*Heaviside(u - b), Max(0, -u - b), Abs(u - b), Max(0, u - b)**2, u*Abs(u), "
    "Heaviside(u)*u**2, c*Heaviside(u - b), sign(u), "
    "Piecewise((polynomial, u < b), ..., (polynomial, True)), plus polynomial terms, "
    "and fractional powers of the distance to a breakpoint such as the Hertz law c*Max(0, u - b)**(3/2) "
    "(rational exponent p > 0); analytic non-polynomial laws such as Max(0, u - b)*exp(u) on the contact arc "
    "that holds a turning point"
)


@dataclass(frozen=True)
class PolynomialInterval:
    """f(u) = Σ_m coefficients[m]·u^m for u between ``lower`` and ``upper`` (None = unbounded)."""

    lower: sympy.Expr | None
    upper: sympy.Expr | None
    coefficients: tuple[sympy.Expr, ...]  # increasing degree, at least (c_0, c_1)
    # terms c·|u − b|^p with b = lower or upper, p a positive non-integer rational: (c, b, p)
    fractional: tuple[tuple[sympy.Expr, sympy.Expr, sympy.Rational], ...] = ()
    # the rest of the law when it is not a polynomial: an analytic expression in u (zero if none)
    analytic: sympy.Expr = sympy.S.Zero

    @property
    def slope(self) -> sympy.Expr:
        """c_1 (the whole law on a linear interval is slope·u + intercept)."""
        return self.coefficients[1]

    @property
    def intercept(self) -> sympy.Expr:
        """c_0."""
        return self.coefficients[0]


def _switching_atoms(expression: sympy.Expr) -> list[sympy.Expr]:
    atoms = []
    for atom in sympy.preorder_traversal(expression):
        if isinstance(atom, _SWITCHING):
            atoms.append(atom)
    return atoms


def _linear_argument(argument: sympy.Expr, variable: sympy.Symbol, f: sympy.Expr) -> tuple[sympy.Expr, sympy.Expr]:
    if not argument.has(variable):
        return sympy.Integer(0), argument
    if not argument.is_polynomial(variable):  # e.g. sin(1/u): infinitely many switching points
        raise UnsupportedNonlinearityError(f"f = {f}: the switching argument {argument} is not linear in u; {_SUPPORTED}")
    polynomial = sympy.Poly(sympy.expand(argument), variable)
    if polynomial.degree() > 1 or any(_switching_atoms(c) for c in polynomial.coeffs()):
        raise UnsupportedNonlinearityError(f"f = {f}: the switching argument {argument} is not linear in u; {_SUPPORTED}")
    slope = polynomial.coeff_monomial(variable)
    offset = polynomial.coeff_monomial(1)
    if not slope.is_number:
        raise UnsupportedNonlinearityError(
            f"f = {f}: the slope of {argument} in u must be a number (gaps may be symbolic); {_SUPPORTED}"
        )
    return slope, offset


def _branch_value(atom: sympy.Expr, sign_of_argument: int) -> sympy.Expr:
    """The smooth expression that a switching atom equals where its argument has the given sign."""
    if isinstance(atom, sympy.Heaviside):
        return sympy.Integer(1 if sign_of_argument > 0 else 0)
    if isinstance(atom, sympy.sign):
        return sympy.Integer(sign_of_argument)
    if isinstance(atom, sympy.Abs):
        return atom.args[0] * sign_of_argument
    # Max/Min with two arguments: decided by the sign of (first - second).
    first, second = atom.args
    if isinstance(atom, sympy.Max):
        return first if sign_of_argument > 0 else second
    return second if sign_of_argument > 0 else first


def _piece_at(atom: sympy.Piecewise, variable: sympy.Symbol, point: sympy.Expr, f: sympy.Expr) -> sympy.Expr:
    """The value of the first piece of ``atom`` whose condition holds at ``point`` (strictly inside an interval)."""
    for value, condition in atom.args:
        holds = condition.subs(variable, point)
        if holds not in (sympy.true, sympy.false):
            holds = sympy.simplify(holds)
        if holds is sympy.true:
            return value
        if holds is not sympy.false:
            raise UnsupportedNonlinearityError(f"f = {f}: cannot decide the Piecewise condition {condition} between breakpoints")
    raise UnsupportedNonlinearityError(f"f = {f}: the Piecewise {atom} is undefined between breakpoints (add a last piece (…, True))")


def has_non_polynomial_law(f: sympy.Expr, variable: sympy.Symbol) -> bool:
    """True when a piece of f is not a polynomial in u: a non-integer power of an expression in u, or a
    function of u other than the switches (its contact arc is then solved numerically).

    Examples
    --------
    >>> import sympy
    >>> u = sympy.Symbol("u", real=True)
    >>> [has_non_polynomial_law(f, u) for f in (sympy.Max(0, u)**sympy.Rational(3, 2), sympy.Max(0, u)**2, sympy.Max(0, u)*sympy.exp(u))]
    [True, False, True]
    """
    powers = any(atom.base.has(variable) and not (atom.exp.is_Integer and atom.exp >= 0) for atom in f.atoms(sympy.Pow))
    functions = any(not isinstance(atom, _SWITCHING) and atom.has(variable) for atom in f.atoms(sympy.Function))
    return powers or functions


def decompose_piecewise_linear(f: sympy.Expr, variable: sympy.Symbol) -> list[PolynomialInterval]:
    """:func:`decompose_piecewise` for a piecewise-linear f (a piece of higher degree is refused).

    Examples
    --------
    >>> import sympy
    >>> u, b = sympy.Symbol("u", real=True), sympy.Symbol("b", real=True)
    >>> [(i.slope, i.intercept) for i in decompose_piecewise_linear(2*sympy.Max(0, u - b), u)]
    [(0, 0), (2, -2*b)]
    >>> [(i.slope, i.intercept) for i in decompose_piecewise_linear(sympy.Heaviside(u), u)]   # a jump at 0
    [(0, 0), (0, 1)]
    """
    return decompose_piecewise(f, variable, max_degree=1)


def decompose_piecewise(f: sympy.Expr, variable: sympy.Symbol, max_degree: int | None = None) -> list[PolynomialInterval]:
    """Split a piecewise-polynomial f(u) (continuous, or jumping at its breakpoints) into polynomial intervals.

    Parameters
    ----------
    f : sympy expression
    variable : sympy.Symbol
        The displacement u.
    max_degree : int, optional
        Refuse pieces of higher degree in u.

    Returns
    -------
    list of PolynomialInterval
        Ordered by u; consecutive intervals share a breakpoint.

    Raises
    ------
    UnsupportedNonlinearityError
        For a piece that is not a polynomial in u (or of degree above ``max_degree``),
        nested switches, Max/Min of more than two arguments, or breakpoints whose
        order cannot be decided (several symbolic gaps).

    Examples
    --------
    >>> import sympy
    >>> u = sympy.Symbol("u", real=True)
    >>> [i.coefficients for i in decompose_piecewise(u*sympy.Abs(u), u)]
    [(0, 0, -1), (0, 0, 1)]
    """
    atoms = _switching_atoms(f)
    switching: list[tuple[sympy.Expr, sympy.Expr]] = []  # (atom, argument whose sign decides it)
    piecewise: list[sympy.Piecewise] = []  # decided by their conditions, each a comparison linear in u
    for atom in atoms:
        if any(_switching_atoms(argument) for argument in atom.args):
            raise UnsupportedNonlinearityError(f"f = {f}: nested switching functions are not supported; {_SUPPORTED}")
        if isinstance(atom, sympy.Piecewise):
            piecewise.append(atom)
        elif isinstance(atom, (sympy.Max, sympy.Min)):
            if len(atom.args) != 2:
                raise UnsupportedNonlinearityError(f"f = {f}: Max/Min must have exactly two arguments; {_SUPPORTED}")
            switching.append((atom, atom.args[0] - atom.args[1]))
        else:
            switching.append((atom, atom.args[0]))
    breakpoints: list[sympy.Expr] = []
    slopes: list[sympy.Expr] = []
    for _, argument in switching:
        slope, offset = _linear_argument(argument, variable, f)
        if slope == 0:
            raise UnsupportedNonlinearityError(f"f = {f}: a switch whose argument does not depend on u; {_SUPPORTED}")
        breakpoints.append(-offset / slope)
        slopes.append(slope)
    for atom in piecewise:
        for _, condition in atom.args:
            if condition is sympy.true:
                continue
            if not isinstance(condition, (sympy.StrictLessThan, sympy.LessThan, sympy.StrictGreaterThan, sympy.GreaterThan)):
                raise UnsupportedNonlinearityError(f"f = {f}: the Piecewise condition {condition} is not one comparison; {_SUPPORTED}")
            slope, offset = _linear_argument(condition.lhs - condition.rhs, variable, f)
            if slope == 0:
                raise UnsupportedNonlinearityError(f"f = {f}: the Piecewise condition {condition} does not depend on u")
            breakpoints.append(-offset / slope)
    unique: list[sympy.Expr] = []
    for point in breakpoints:
        if not any(sympy.simplify(point - other) == 0 for other in unique):
            unique.append(point)
    try:
        unique.sort(key=lambda point: point if point.is_number else sympy.nan)
        for left, right in zip(unique, unique[1:]):
            if (right - left).is_positive is not True:
                raise TypeError
    except TypeError:
        raise UnsupportedNonlinearityError(
            f"f = {f}: cannot order the breakpoints {unique}; give numeric gaps when there are several springs"
        ) from None

    def test_point(index: int) -> sympy.Expr:
        if not unique:
            return sympy.Integer(0)
        if index == 0:
            return unique[0] - 1
        if index == len(unique):
            return unique[-1] + 1
        return (unique[index - 1] + unique[index]) / 2

    intervals: list[PolynomialInterval] = []
    for index in range(len(unique) + 1):
        point = test_point(index)
        replacements = {}
        for (atom, argument), slope in zip(switching, slopes):
            sign_value = sympy.sign(sympy.simplify(argument.subs(variable, point)))
            if sign_value not in (1, -1):
                raise UnsupportedNonlinearityError(f"f = {f}: cannot decide the sign of {argument} between breakpoints")
            replacements[atom] = _branch_value(atom, int(sign_value))
        for atom in piecewise:
            replacements[atom] = _piece_at(atom, variable, point, f)
        piece = f.xreplace(replacements)
        lower = unique[index - 1] if index > 0 else None
        upper = unique[index] if index < len(unique) else None
        fractional: list[tuple[sympy.Expr, sympy.Expr, sympy.Rational]] = []
        if max_degree is None and not piece.has(*_SWITCHING):
            # powers of the distance to an end of the interval stand as placeholders while the rest is expanded
            placeholders = {
                atom: sympy.Dummy("power")
                for atom in piece.atoms(sympy.Pow)
                if atom.base.has(variable) and not (atom.exp.is_Integer and atom.exp >= 0)
                and _vanishes_at_an_end(atom.base, variable, (lower, upper))
            }
            piece = sympy.expand(piece.xreplace(placeholders))
            for atom, placeholder in placeholders.items():
                coefficient = piece.coeff(placeholder)
                piece = sympy.expand(piece - coefficient * placeholder)
                if coefficient.has(variable) or coefficient.has(*placeholders.values()):
                    raise UnsupportedNonlinearityError(f"f = {f}: the term {coefficient * atom} is not c*Max(0, u - b)**p; {_SUPPORTED}")
                fractional.append(_fractional_term(coefficient, atom, variable, (lower, upper), point, f))
        piece = sympy.expand(piece)
        analytic = sympy.S.Zero
        if max_degree is None and not piece.has(*_SWITCHING) and not piece.is_polynomial(variable):
            analytic = sympy.Add(*[term for term in sympy.Add.make_args(piece) if not term.is_polynomial(variable)])
            piece = sympy.expand(piece - analytic)
        if piece.has(*_SWITCHING) or not piece.is_polynomial(variable):
            raise UnsupportedNonlinearityError(f"f = {f} is not piecewise polynomial in u (piece {piece}); {_SUPPORTED}")
        degree = max(sympy.degree(piece, variable), 1)
        if max_degree is not None and degree > max_degree:
            raise UnsupportedNonlinearityError(f"f = {f} is not piecewise linear in u (piece {piece}); {_SUPPORTED}")
        coefficients = tuple(sympy.simplify(piece.coeff(variable, power)) for power in range(degree + 1))
        intervals.append(PolynomialInterval(lower, upper, coefficients, tuple(fractional), analytic))
    return intervals


def _vanishes_at_an_end(base: sympy.Expr, variable: sympy.Symbol, ends: tuple) -> bool:
    """True when ``base`` is linear in u and vanishes at an end of the interval."""
    polynomial = sympy.Poly(sympy.expand(base), variable) if base.is_polynomial(variable) else None
    if polynomial is None or polynomial.degree() != 1:
        return False
    root = -polynomial.coeff_monomial(1) / polynomial.coeff_monomial(variable)
    return any(end is not None and sympy.simplify(root - end) == 0 for end in ends)


def _fractional_term(coefficient: sympy.Expr, power: sympy.Pow, variable: sympy.Symbol, ends: tuple, inside: sympy.Expr, f: sympy.Expr):
    """``(c', b, p)`` for ``coefficient·(±(u − b))^p = c'·|u − b|^p``: p a positive non-integer rational, b an
    end of the interval and the base positive inside it (anything else is refused)."""
    term = coefficient * power
    base, exponent = power.base, power.exp
    if not exponent.is_Rational:
        raise UnsupportedNonlinearityError(f"f = {f}: the exponent {exponent} of {term} must be a rational number; {_SUPPORTED}")
    if exponent <= 0:
        raise UnsupportedNonlinearityError(
            f"f = {f}: the force {term} is unbounded where {base} vanishes (exponent {exponent} <= 0); {_SUPPORTED}"
        )
    slope, offset = _linear_argument(base, variable, f)
    root = -offset / slope
    if not any(end is not None and sympy.simplify(root - end) == 0 for end in ends):
        raise UnsupportedNonlinearityError(
            f"f = {f}: the power {term} must vanish at a breakpoint of its piece (write it as Max(0, u - b)**p); {_SUPPORTED}"
        )
    sign = sympy.sign(sympy.simplify(base.subs(variable, inside)))
    if sign != 1:
        raise UnsupportedNonlinearityError(f"f = {f}: the base of {term} must be positive on its piece; {_SUPPORTED}")
    # c·(slope (u − root))^p = c·|slope|^p |u − root|^p (slope·(u − root) > 0 inside)
    return sympy.simplify(coefficient * abs(slope) ** exponent), root, exponent
