"""The cost model of an expansion: CPU seconds and memory of ``expand(f, N)`` from what the request holds.

An expansion to order N costs ``T = exp(θ · x)`` CPU seconds, where x are the request's features — the order
(``log(N + 1)``), the polynomial degree of f, its breakpoints B (``log B``), the symbolic parameters, the
working digits P (``log(P/30)``), a release with velocity, and products of these where the measurements
show the exponent of N to depend on them — and θ holds one fitted vector per kind of request:

* ``polynomial`` — f a polynomial in u, exact rational (or symbolic) arithmetic;
* ``analytic`` — f analytic but not polynomial (``sin(u)``), cosine series at P digits;
* ``piecewise`` — f piecewise polynomial, exact algebraic numbers (contact angles arccos κ);
* ``piecewise-float`` — the same at P digits (``numeric=True`` or floats in the input);
* ``contact-law`` — a non-polynomial contact law (Hertz), its contact arc solved in stretched time at P digits.

Memory is ``growth = c · T^γ · B^δ · (P/30)^η`` MB over the process (one fit over every kind, B ≥ 1 the
breakpoints, P the digits).  The constants come from ``benchmarks/bench_cost_model.py --fit --from-json
benchmarks/results/cost_model_calibration.json`` — least squares on the requests measured there on the benchmark
machine, where the ratio measured/estimated stays within :data:`lindstedt.limits.FACTOR`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import sympy

from ._errors import BudgetError
from ._precision import LOCK
from .limits import Estimate

__all__ = ["ExpansionFeatures", "expansion_check", "expansion_estimate", "expansion_features", "multiple_scales_estimate", "nnm_estimate",
           "shooting_estimate"]

_SWITCHES = (sympy.Max, sympy.Min, sympy.Heaviside, sympy.Abs, sympy.sign)

#: The features each kind's model uses (the measurements show no dependence on the others).
FEATURES_OF_KIND: dict[str, tuple[str, ...]] = {
    "polynomial": ("1", "n", "n2", "degree", "degree_n", "symbols", "symbols_n", "scale", "scale_n", "velocity"),
    "analytic": ("1", "n", "n2", "p", "p_n", "p_n2", "p2"),
    "piecewise": ("1", "n", "n2", "b", "b_n", "b2", "symbols", "symbols_n", "scale", "scale_n", "degree", "dn", "dn2",
                  "origin", "origin_n", "velocity"),
    "piecewise-float": ("1", "n", "b", "p", "p_n"),
    "contact-law": ("1", "n", "p", "p_n"),
}
#: θ per kind: {feature: coefficient} over :data:`FEATURES_OF_KIND` (fitted, see the module docstring).
_THETA: dict[str, dict[str, float]] = {
    "polynomial": {"1": -1.9237, "n": -3.3032, "n2": 0.5684, "degree": -2.7309, "degree_n": 1.5775,
                  "symbols": 0.0373, "symbols_n": 0.8608, "scale": 1.3214, "scale_n": -0.1717, "velocity": 1.9378},
    "analytic": {"1": -1.8177, "n": -2.4222, "n2": 0.9825, "p": -1.1955, "p_n": 0.2089, "p_n2": 0.0217, "p2": 0.6769},
    "piecewise": {"1": -5.2824, "n": -1.4166, "n2": 0.7951, "b": -1.2412, "b_n": 1.7515, "b2": 0.4558,
                 "symbols": 1.0835, "symbols_n": 0.6406, "scale": -1.5709, "scale_n": 3.4578, "degree": -1.2225,
                 "dn": 0.9739, "dn2": 0.2821, "origin": 0.443, "origin_n": -0.7766, "velocity": 0.2721},
    "piecewise-float": {"1": -7.8879, "n": 2.1409, "b": 0.7186, "p": 0.3286, "p_n": -0.1632},
    "contact-law": {"1": -2.7991, "n": 0.9765, "p": 1.8169, "p_n": -0.0145},
}
#: The fewest digits the model is fitted at (the default precision): fewer are priced as these (conservative).
_LEAST_DIGITS = 30
#: memory growth (MB) = _MEMORY[0] · T^_MEMORY[1] · B^_MEMORY[2] · (P/30)^_MEMORY[3] (B ≥ 1 the breakpoints, P the
#: digits), never below 1 MB
_MEMORY = (9.196, 0.656, 0.541, 0.086)


@dataclass(frozen=True)
class ExpansionFeatures:
    """What an expansion request holds that its cost depends on."""

    kind: str
    order: int
    degree: int
    breakpoints: int
    symbols: int
    symbolic_scale: bool
    digits: int
    initial_velocity: bool
    origin: bool = False

    def vector(self, order: int | None = None, digits: int | None = None,
               breakpoints: int | None = None) -> dict[str, float]:
        """The features x of the model ``log T = θ · x`` (at another order, digits or breakpoints if given).

        Grazing, whose gauge √ε doubles the coefficient indices, measured no dearer than its order: not priced.
        """
        order = self.order if order is None else order
        n = math.log(order + 1)
        b = math.log(max(self.breakpoints if breakpoints is None else breakpoints, 1))
        p = math.log((self.digits if digits is None else digits) / 30)
        degree = math.log(max(self.degree, 1))
        dn = math.log(max(self.degree, 1) * order + 1)
        scale = float(self.symbolic_scale)
        return {
            "1": 1.0, "n": n, "n2": n * n, "degree": degree, "degree_n": degree * n, "dn": dn, "dn2": dn * dn,
            "origin": float(self.origin), "origin_n": float(self.origin) * n, "b": b, "b_n": b * n, "b2": b * b,
            "symbols": float(self.symbols), "symbols_n": self.symbols * n, "scale": scale, "scale_n": scale * n,
            "p": p, "p_n": p * n, "p_n2": p * n * n, "p2": p * p, "velocity": float(self.initial_velocity),
        }

    def log_seconds(self) -> float:
        """log T: the fitted model made monotone — the most it gives over every lower order (from 1), fewer digits
        (down to 30, the fewest it was fitted at; fewer are priced as 30) and fewer breakpoints, so that asking for
        more never prices less."""
        theta = _THETA[self.kind]
        best = -math.inf
        for order in range(min(1, self.order), self.order + 1):  # order 0 alone: no fit below 1
            for digits in {_LEAST_DIGITS, max(self.digits, _LEAST_DIGITS)}:
                for breakpoints in {1, self.breakpoints}:
                    vector = self.vector(order, digits, breakpoints)
                    best = max(best, sum(value * vector[name] for name, value in theta.items()))
        return best

    def drivers(self) -> tuple[tuple[str, Any], ...]:
        """The features as they are named in messages."""
        items: list[tuple[str, Any]] = [("kind", self.kind), ("order", self.order)]
        if self.breakpoints:
            items.append(("breakpoints", self.breakpoints))
        if self.degree > 1:
            items.append(("degree", self.degree))
        if self.symbols:
            items.append(("symbolic parameters", self.symbols))
        if self.symbolic_scale:
            items.append(("symbolic a0/omega0", True))
        if self.kind in ("analytic", "piecewise-float", "contact-law"):
            items.append(("digits", self.digits))
        if self.initial_velocity:
            items.append(("initial velocity", True))
        if self.origin:
            items.append(("breakpoints at 0", True))
        return tuple(items)


def _degree(f: sympy.Expr, variable: sympy.Symbol) -> int:
    """The polynomial degree of f in u, reading every switch as linear (``Max(0, u)**2`` has degree 2)."""
    kinds = _SWITCHES + (sympy.Piecewise,)
    switches = f.atoms(*kinds)
    if any(argument.has(*kinds) for switch in switches for argument in switch.args):  # nested: bottom-up
        linear = f.replace(lambda e: isinstance(e, kinds), lambda e: variable)
    else:  # every switch is outermost: the same replacement as one substitution
        linear = f.xreplace({switch: variable for switch in switches})
    if linear == variable:
        return 1
    try:
        degree = sympy.Poly(linear, variable).degree()
        if degree.is_infinite if isinstance(degree, sympy.Basic) else False:  # the switches cancel: Max(0, u) - Max(0, -u)
            raise ValueError
        return max(1, int(degree))
    except (sympy.PolynomialError, sympy.GeneratorsNeeded, ValueError):
        powers = [int(p.exp) for p in f.atoms(sympy.Pow) if p.base.has(variable) and p.exp.is_Integer and p.exp > 0]
        return max([1, *powers])


def _at_origin(f: sympy.Expr, variable: sympy.Symbol) -> bool:
    """True when every switch of f turns at u = 0 (contact angle π/2: rational cosines, the cheapest algebra)."""
    arguments = [argument for atom in f.atoms(*_SWITCHES) for argument in atom.args if argument.has(variable)]
    return bool(arguments) and not f.atoms(sympy.Piecewise) and all(argument.xreplace({variable: 0}) == 0 for argument in arguments)


def _breakpoints(f: sympy.Expr, variable: sympy.Symbol) -> int:
    """How many breakpoints f has: one per switch of u (``Max(0, u - b)``, ``Heaviside(u)``, ...), and the
    conditions of a Piecewise."""
    switches = sum(1 for atom in f.atoms(*_SWITCHES) if atom.has(variable))
    return switches + sum(max(len(piecewise.args) - 1, 1) for piecewise in f.atoms(sympy.Piecewise))


def expansion_features(problem: Any, order: int, precision: int, numeric: bool) -> ExpansionFeatures:
    """The :class:`ExpansionFeatures` of ``LindstedtPoincare(precision, numeric).expand(problem, order)``."""
    from .problems.oscillator import DISPLACEMENT
    from .problems.piecewise_linear import has_non_polynomial_law

    f = problem.nonlinearity
    breakpoints = _breakpoints(f, DISPLACEMENT) if problem.is_non_smooth else 0
    if problem.is_non_smooth:
        if has_non_polynomial_law(f, DISPLACEMENT):
            kind = "contact-law"
        else:
            floats = numeric or any(isinstance(atom, sympy.Float) for atom in f.atoms(sympy.Number))
            kind = "piecewise-float" if floats else "piecewise"
    else:
        kind = "polynomial" if problem.is_polynomial else "analytic"
    exact_kind = kind in ("polynomial", "piecewise")
    return ExpansionFeatures(
        kind=kind,
        order=order,
        degree=_degree(f, DISPLACEMENT),
        breakpoints=breakpoints,
        symbols=len(problem.symbolic_parameters),
        symbolic_scale=not (problem.a0.is_number and problem.omega0.is_number),
        digits=30 if exact_kind else precision,
        initial_velocity=problem.has_initial_velocity,
        origin=problem.is_non_smooth and _at_origin(f, DISPLACEMENT),
    )


#: f → its text in an estimate's task (see :func:`_short`)
_LAW_TEXT: dict[Any, str] = {}


def expansion_estimate(problem: Any, order: int, precision: int, numeric: bool) -> Estimate:
    """The :class:`~lindstedt.limits.Estimate` of an expansion request (see the module docstring)."""
    features = expansion_features(problem, order, precision, numeric)
    seconds = math.exp(min(features.log_seconds(), 700.0))
    memory = _memory_mb(seconds, features.breakpoints, features.digits)
    advice = _advice(problem, features, precision)
    law = _LAW_TEXT.get(problem.f)
    if law is None:  # printing f costs more than the rest of the estimate: once per f (its parameters symbolic)
        if len(_LAW_TEXT) >= 256:
            _LAW_TEXT.clear()
        law = _LAW_TEXT[problem.f] = _short(problem.f)
    vector = features.vector()
    return Estimate(task=f"expansion of {law} to order {order}", seconds=seconds, memory_mb=memory,
                    drivers=features.drivers(), advice=advice,
                    features=tuple((name, vector[name]) for name in FEATURES_OF_KIND[features.kind]))


def _memory_mb(seconds: float, breakpoints: int, digits: int) -> float:
    scale, power, per_breakpoint, per_digit = _MEMORY
    return max(1.0, scale * seconds**power * max(breakpoints, 1) ** per_breakpoint * (digits / 30) ** per_digit)


#: (f with its parameters symbolic, order, digits) → (seconds, MB): the most a numeric expansion of that non-smooth f
#: is priced at, whatever its parameters' values (:func:`expansion_check`); bounded
_NUMERIC_BOUNDS: dict[tuple[Any, int, int], tuple[float, float]] = {}


def expansion_check(problem: Any, order: int, precision: int, numeric: bool) -> None:
    """``expansion_estimate(problem, order, precision, numeric).check()``, without pricing f at its parameters' values
    when a bound fits the budget.

    With ``numeric`` a non-smooth f is priced as "piecewise-float" or "contact-law" (its values decide which),
    whose models read the order, the digits and the breakpoints only and grow with the breakpoints; putting numbers
    into f can merge or remove switches, never add one, so the larger of the two at the breakpoints of f with its
    parameters symbolic bounds the estimate (made once per f, order and digits; a new value of a parameter needs no
    substitution into f).  A bound above the budget leaves the decision to the estimate itself.
    """
    if numeric and problem.is_non_smooth:
        key = (problem.f, order, precision)
        bound = _NUMERIC_BOUNDS.get(key)
        if bound is None:
            from .problems.oscillator import DISPLACEMENT

            breakpoints = _breakpoints(problem.f, DISPLACEMENT)
            seconds = max(math.exp(min(ExpansionFeatures(kind, order, 1, breakpoints, 0, False, precision, False)
                                       .log_seconds(), 700.0)) for kind in ("piecewise-float", "contact-law"))
            bound = (seconds, _memory_mb(seconds, breakpoints, precision))
            with LOCK:
                if len(_NUMERIC_BOUNDS) >= 256:
                    _NUMERIC_BOUNDS.clear()
                _NUMERIC_BOUNDS[key] = bound
        try:
            Estimate("numeric expansion", seconds=bound[0], memory_mb=bound[1]).check()
            return
        except BudgetError:
            pass
    expansion_estimate(problem, order, precision, numeric).check()


def _advice(problem: Any, features: ExpansionFeatures, precision: int) -> str:
    if features.kind == "piecewise":
        return "numeric=True computes the same coefficients in floats of `precision` digits, much faster; or ask for a lower order"
    if features.kind in ("analytic", "piecewise-float", "contact-law"):
        return "ask for fewer digits (precision) or a lower order"
    if features.symbols or features.symbolic_scale:
        return "give the symbolic parameters (and a0, omega0) numbers, or ask for a lower order"
    return "ask for a lower order"


#: The NNM expansion of an N-dof system with S springs: T = _NNM[0] · N^1.25 (S/3)^0.2 + [order ≥ 3] _NNM[1] · N^1.3 ·
#: 2.5^(order − 3) (S/3)^1.084 CPU seconds.  Recalibrated on the benchmark chain (3 springs) after the issue-26
#: modal refinement (packed columns, banded corrections): order ≤ 2 is the modal coupling, 0.28 / 0.30 s at N = 200
#: (orders 1, 2), 0.60 s at 500, 1.40 s at 1000, ~4.5 s at 2000; from order 3 the hierarchy's combination tones
#: dominate: after the shared right-hand sides of the order solve (issue 26) 0.49 / 0.79 / 2.09 s CPU at
#: N = 50 / 100 / 200 (order 3; it was 0.6 / 1.55 / 5.5 s, N^1.6) and ×2.2–2.5 an order (N = 50: 1.22 s at order 4,
#: 2.65 s at 5).  The coupling hardly depends on S (1000 dof, order 2: 1.28 s with one spring, 1.40 s with three;
#: 200 dof: 0.21 / 0.30 / 0.35 s with 1 / 3 / 6); the tones' springs exponent is the earlier fit's.  Session 14
#: (term-key harmonics that remember their hash, memoised particular solutions): order 3 CPU 0.19 / 0.39 / 1.24 s at
#: N = 50 / 100 / 200, estimate/measured 1.2–1.6 with _NNM[1] refitted.
_NNM = (3.4e-4, 1.4e-3)
#: Its memory: the float modal matrices (``_NNM_MEMORY[0] · N²`` MB: the modes, their gaps and projections; the
#: fixed-point shapes are refined a block at a time — chain of 1000 dof 59–65 MB, 2000 dof 106 MB measured over the
#: import baseline, so the N² term keeps a margin of 1.5–4×) or the hierarchy, whose peak grows with its work:
#: measured 41–57 MB per CPU second at orders 3 and 4 (springs only, 50…200 dof: 9 / 18 / 51 MB; Hertz + cubic, all
#: modes, order 3, 20 / 40 / 80 dof: 62 / 283 / 1372 MB; order 4, 20 dof: 640 MB), so ``_NNM_MEMORY[1] · T`` MB of
#: the estimated T: estimate/measured 1.6–2.4 on those (it was ``12 T^0.9``: half the 80-dof peak).
_NNM_MEMORY = (1e-4, 60.0)


#: Elements of other laws.  A stretched contact arc (a law with a fractional power, or an analytic part next to a
#: breakpoint) carries every modal component on one Chebyshev grid that resolves cos(β r_k τ) of the stiffest,
#: r_max = λ_N/λ_mode, in the variable (1 − τ)^(1/d) (d the exponent's denominator, 2 for Hertz; 1 for an analytic
#: law): ``(_NNM_ARC[0] + _NNM_ARC[1] · N · r_max · d) · (order + 1)/3`` s.  Measured (issue 26, after the mpfr node
#: arithmetic and the shared right-hand sides; the benchmark chain with a Hertz gap 1/100 and a cubic spring, mode 1,
#: order 2, wall): all modes N = 20 / 40 / 80 / 160 (r_max 13 / 26 / 52 / 102): 0.44 / 1.1 / 1.7 / 7.0 s, order 1 at
#: N = 20 0.23 s; through ResidualFlexibility(8) (13 components, r_max 93 / 453 / 903 at 200 / 1000 / 2000 dof):
#: 0.80 / 0.89 / 1.86 s.  Estimate/measured 0.6–1.2 with all modes, 0.9–2.9 reduced (a small contact angle β
#: there needs fewer nodes than r_max says; β is known only once the orbit is).  Products of branches (powers ≥ 2,
#: analytic laws) cost ``_NNM_PRODUCTS · N² · 9^(order − 2)`` s from order 3 on (combination tones of the N modal
#: frequencies; the benchmark chain, Hertz + cubic, order 3: 1.23 / 5.9 / 24.3 s CPU at N = 20 / 40 / 80 (session
#: 14; it was 2.6 / 11.2 / 45.9), order 4 at N = 20 15.1 s: estimate/measured 1.1–1.9); order 2 stays linear in N.
_NNM_ARC, _NNM_PRODUCTS = (0.3, 2e-4), 5e-4


def _law_costs(system: Any) -> tuple[int, bool]:
    """(the largest denominator d of a stretched contact arc's exponents — a law with a fractional power; 1 for an
    analytic part next to a breakpoint; 0 without an arc — and whether a law multiplies branches — a piece of
    degree ≥ 2 or an analytic law without breakpoints), read from the laws' pieces."""
    from ._errors import LindstedtError
    from .problems.piecewise_linear import decompose_piecewise
    from .problems.system import LAW_VARIABLE, UNILATERAL

    arc, products = 0, False
    for law in set(getattr(system, "laws", ())):
        if law == UNILATERAL:
            continue
        try:
            intervals = decompose_piecewise(law, LAW_VARIABLE)
        except LindstedtError:  # refused by the method itself, with its own words
            continue
        for interval in intervals:
            for _, _, exponent in interval.fractional:
                arc = max(arc, int(sympy.Rational(exponent).q))
        if len(intervals) > 1 and any(interval.analytic != 0 for interval in intervals):
            arc = max(arc, 1)
        # an analytic part next to a breakpoint multiplies on its arc (priced above), one without breakpoints branches
        products = products or any(len(interval.coefficients) > 2 for interval in intervals) or \
            (len(intervals) == 1 and intervals[0].analytic != 0)
    return arc, products


def nnm_estimate(system: Any, mode: int, order: int) -> Estimate:
    """The :class:`~lindstedt.limits.Estimate` of the strained-coordinates NNM of ``system`` to ``order``."""
    n, springs = system.n_dof, max(len(system.b), 1)
    coupling, tones = _NNM
    seconds = coupling * n**1.25 * (springs / 3) ** 0.2 + (tones * n**1.3 * 2.5 ** (order - 3) * (springs / 3) ** 1.084
                                                           if order >= 3 else 0.0)
    denominator, products = _law_costs(system)
    if denominator:  # the float modes: cached on the system, the expansion reads them too
        frequencies = system.modes()[0]
        stiffest = float(frequencies[-1] / frequencies[mode - 1]) * denominator
        seconds += (_NNM_ARC[0] + _NNM_ARC[1] * n * stiffest) * (order + 1) / 3
    if products and order >= 3:
        seconds += _NNM_PRODUCTS * n**2 * 9.0 ** (order - 2)
    memory = max(1.0, _NNM_MEMORY[0] * n * n, _NNM_MEMORY[1] * seconds)
    return Estimate(task=f"NNM expansion of mode {mode} of a {n}-dof system to order {order}", seconds=seconds,
                    memory_mb=memory, drivers=(("degrees of freedom", n), ("springs", springs), ("order", order)),
                    advice="ask for a lower order, or reduce the model (fewer degrees of freedom)")


#: First-order multiple scales of a piecewise-polynomial f: the closed form f1(A) per regime costs
#: ``_MULTIPLE_SCALES[0] · d^_MULTIPLE_SCALES[1] · B`` CPU seconds (d the degree, B ≥ 1 the breakpoints; measured on
#: ``Max(0, u - 1/5)**d``, d = 2…64: sympy's simplification of each regime's coefficient dominates); its memory
#: ``_MULTIPLE_SCALES[2] · T^_MULTIPLE_SCALES[3]`` MB (10 MB at d = 32, 30 MB at d = 64).
_MULTIPLE_SCALES = (1.9e-3, 2.1, 5.0, 0.7)


def multiple_scales_estimate(problem: Any) -> Estimate:
    """The :class:`~lindstedt.limits.Estimate` of the multiple-scales response curve of a forced oscillator."""
    from .problems.oscillator import DISPLACEMENT

    f = problem.nonlinearity
    degree = _degree(f, DISPLACEMENT)
    breakpoints = max(_breakpoints(f, DISPLACEMENT), 1)
    seconds = _MULTIPLE_SCALES[0] * degree ** _MULTIPLE_SCALES[1] * breakpoints
    return Estimate(task=f"multiple-scales response of {_short(f)}", seconds=seconds,
                    memory_mb=max(1.0, _MULTIPLE_SCALES[2] * seconds ** _MULTIPLE_SCALES[3]),
                    drivers=(("degree", degree), ("breakpoints", breakpoints)),
                    advice="a law of lower degree, or the exact flow (method 'exact')")


def _short(expression: Any) -> str:
    text = str(expression)
    return text if len(text) <= 60 else text[:57] + "..."


#: One exact event-driven flow over a period of an N-dof UnilateralSystem: ``_SHOOTING_FLOW · N²`` CPU seconds
#: (measured by nnm_point on chains with two springs: 3 ms at N = 10, 3.6 ms at N = 20, 66 ms at N = 40).
_SHOOTING_FLOW = 4.1e-5


#: One DOP853 flow with its variational equations over half a period of mode 1, for systems with other laws:
#: ``_DOP853_FLOW + _DOP853_FLOW_N2 · N²`` CPU seconds (measured on chains with a cubic and a Hertz element: 31 ms at
#: N = 5, 49 ms at N = 10, 0.10 s at N = 20, 0.35 s at N = 40; the constants are below every measurement: a floor)
_DOP853_FLOW, _DOP853_FLOW_N2 = 0.01, 1.5e-4


def shooting_estimate(system: Any, flows: int, task: str) -> Estimate:
    """The least a shooting request costs: ``flows`` flows over a period of ``system`` (the Newton iterations of
    one point, or the first point of a continuation; more points cost more, watched by the budget's checkpoints):
    exact event-driven flows for unilateral springs, DOP853 with variational equations for other laws."""
    n = system.n_dof
    if getattr(system, "unilateral", True):
        seconds = flows * _SHOOTING_FLOW * n * n
    else:
        seconds = flows * (_DOP853_FLOW + _DOP853_FLOW_N2 * n * n)
    return Estimate(task=task, seconds=seconds, memory_mb=max(1.0, 8e-6 * n * n * (len(system.b) + 2)),
                    drivers=(("degrees of freedom", n), ("flows at least", flows)),
                    advice="reduce the model (fewer degrees of freedom)", least=True)
