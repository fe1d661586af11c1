"""How far in ε the derivation of an expansion of ``u'' + ω0² u + ε f(u) = 0`` holds.

A Lindstedt–Poincaré series is derived for the contact regime of the orbit at ε = 0 (which
breakpoints it crosses) and sums to the true ω(ε) only inside its disc of convergence.  This
module follows the *true* orbit through the release state (u0, v0) (u0 = a0, v0 = 0 for a
release at rest) as ε moves away from 0, for every law the engine accepts: polynomial and
piecewise-polynomial f exactly, and pieces with fractional powers (Hertz ``Max(0, u - b)**(3/2)``)
or analytic terms (``sin(u)``, ``u/(1 + u**2)``, ``Max(0, u - b)*exp(u)``) numerically.

The potential ``V(u; ε) = ω0² u²/2 + ε F(u)`` (F = ∫_0^u f, continuous) and the energy
``E(ε) = v0²/2 + ω0² u0²/2 + ε F(u0)`` are both linear in ε.  The orbit is the interval
[low, high] ∋ u0 on which V ≤ E, bounded by the first roots of V − E on each side of u0; its end
points move continuously with ε except where one of them is a critical point of V (the period is
infinite there), so the orbit can change its regime only at

* a breakpoint b becoming a turning point: ``V(b; ε) = E(ε)``, i.e.
  ``ε = (E0 − ω0² b²/2) / (F(b) − F(u0))``, E0 = v0²/2 + ω0² u0²/2 (exact);
* a turning point meeting a critical point of V (a separatrix, or u0 becoming an equilibrium):
  ``V' = 0`` and ``V = E`` on one piece j (law g_j, primitive G_j).  On the curve of critical points
  ε(u) = −ω0² u / g_j(u) the condition ``V(u; ε(u)) = E(ε(u))`` is one scalar equation in u,
  ``D_j(u) = ω0² u (G_j(u) − F(u0)) − g_j(u) (ω0² u²/2 − E0) = 0``, and ε follows from V' = 0
  (from V = E at the origin when g_j(0) = 0: the origin is critical at every ε).
  A polynomial piece makes D_j a polynomial (all its roots, complex ones too).  For Duffing
  ``f = u³``, a0 = 1: roots u = ±1 give ε = −1 (the separatrix: the motion escapes for
  ε a0²/ω0² ≤ −1) and u = 0 gives ε = −2.  For ``f = sin u``, a0 = 1: u = 0 gives
  ε = −1/(2 (1 − cos 1)) ≈ −1.0877, where the orbit, which has been enclosing the hump V(0) = 0
  that the pitchfork at ε = −1 made, reaches it; below, the motion stays in the well u > 0;
* a linear piece losing its stiffness: ``ω0² + ε c_1 = 0``.

Pieces that are not polynomials are handled on a grid of u: uniform (spacing amplitude/64, halved
up to 8 times where f is not resolved) over |u| ≤ 4 amplitudes, the amplitude being
√(u0² + v0²/ω0²), then geometric (ratio 1.05) out to 10⁴ amplitudes, as long as every cell resolves
f (nearly linear, or monotone and convex on five points: power and exponential growth pass, an
oscillation does not — sin u is followed to ~12 amplitudes) and |f| stays below 1e150.  F is the
closed form of the polynomial and fractional terms plus 16-point Gauss–Legendre quadrature of the
analytic term on every cell; roots of V − E and of D_j are bracketed by sign changes on the grid
(and, for V − E, by the sign changes of V' that mark a hump inside a cell) and refined with Brent's
method; the release point, a double root of D_j, is added from ω0² u0 + ε f(u0) = 0.  Why this
interval: it holds the orbit of ε = 0 four times over, and an event outside it needs an orbit that
has grown past it — whose turning point then reaches the end of the interval first, itself an event
(``V(R; ε) = E(ε)``).  Past it the motion escapes (refused) where the grid ended at 10⁴ amplitudes
or where f overflows, and is *not followed* (a warning, not a refusal: the orbit may well be
periodic) where the grid ended because it no longer resolves f.  What the grid cannot see: a
tangency of D_j with 0 (a root of even multiplicity other than the release point), two roots of
D_j or two humps of V inside one cell, and structure of f finer than the refined core cells.
Measured cost: 0.5–5 ms per problem (18 ms for sin(20 u)); an expansion computes it once per
parameter point, when an ε is first judged.

Between consecutive such ε (the *events*) the orbit is computed once: its set of crossed
breakpoints, or that no periodic orbit exists (the motion escapes, or u0 is an equilibrium).  At
an event the orbit is also computed just on each side: if its turning points jump, a turning point
passed a hump of V (a separatrix), and beyond it the orbit is another one even where it crosses the
same breakpoints.  :class:`OrbitRange` holds

* ``lower < 0 < upper``: the open ε-interval on which the orbit keeps the derivation's regime
  (the first event on each side where it changes);
* ``radius``: the distance from 0 to the nearest singularity of ω(ε) that the law gives — the
  real events where the orbit changes, and, for polynomial pieces, the complex critical-level
  points — an upper estimate of the radius of convergence of the series (in ε; the gauge ε^{1/2}
  has √radius).  For pieces that are not polynomials only the real events are found: the radius is
  then an upper estimate that a complex singularity nearer to 0 can undercut (the series'
  growing-terms check still applies).

Not computed (None: judged only by the growing-terms check of the series): the "harmonic"
normalization, whose release point is itself a series in ε (a result of the expansion, not a
datum of the orbit), and a release shifted by ε a1 (its energy is not linear in ε, so the events
above do not hold as written).

Rule (:meth:`OrbitRange.judge`): no periodic orbit at ε → :class:`~lindstedt.ParameterError`
naming why; a periodic orbit in another regime (ε outside (lower, upper)) or ε beyond the radius →
the text of an :class:`~lindstedt.ExpansionValidityWarning` naming the bound.

Examples
--------
>>> import lindstedt
>>> expansion = lindstedt.expand("Max(0, u + 3/2)", order=2, a0=1, omega0=1)   # permanent contact at ε = 0
>>> bounds = expansion.epsilon_range()
>>> bounds.upper, bounds.lower      # leaves contact at ε = 1/5; no orbit once ω0² + ε ≤ 0
(0.2, -1.0)
>>> pendulum = lindstedt.expand("sin(u)", order=2, a0=1, omega0=1).epsilon_range()
>>> round(pendulum.lower, 10), round(-1 / (2 * (1 - math.cos(1))), 10)   # the hump at u = 0 is reached
(-1.0876713248, -1.0876713248)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import sympy

from .._errors import ParameterError, UnsupportedNonlinearityError
from ..problems.oscillator import DISPLACEMENT, Oscillator
from ..problems.piecewise_linear import decompose_piecewise

__all__ = ["OrbitRange", "orbit_range", "range_function"]

_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(16)
_CORE = 4.0  # the uniform part of the grid covers |u| <= _CORE amplitudes ...
_CORE_CELLS = 256  # ... in this many cells
_REACH = 1e4  # the geometric part continues to _REACH amplitudes ...
_RATIO = 1.05  # ... with this ratio
_HUGE = 1e150  # or until |f| exceeds this
_RESOLVED = 0.02  # a cell resolves f when f at its middle is the mean of its ends to this fraction of |f|
_REFINE = 8  # halvings of the core cells that do not


def range_function(problem: Oscillator, symbols: tuple[sympy.Symbol, ...]) -> Callable[..., tuple[Any, ...]] | None:
    """The data :func:`orbit_range` reads — ``(ω0, u0, v0, pieces)``, each piece ``(lower, upper, c_0 … c_d,
    fractional terms (c, b, p), analytic term as a function of u or None)``, ±inf for unbounded ends — as one
    function of the free ``symbols``; None when no range is computed: a release shifted by ε a1, the "harmonic"
    normalization (the release point is itself a series there), or a law :func:`decompose_piecewise` refuses."""
    if problem.normalization != "initial" or (not problem.has_initial_velocity and problem.a1 != 0):
        return None
    f = problem.nonlinearity
    if not problem.is_non_smooth and f.is_polynomial(DISPLACEMENT):
        pieces = [(None, None, sympy.Poly(f, DISPLACEMENT).all_coeffs()[::-1], (), sympy.S.Zero)]
    else:
        try:
            intervals = decompose_piecewise(f, DISPLACEMENT)
        except UnsupportedNonlinearityError:
            return None
        pieces = [(i.lower, i.upper, list(i.coefficients), i.fractional, i.analytic) for i in intervals]
    start, speed = (problem.u0, problem.v0) if problem.has_initial_velocity else (problem.a0, sympy.Integer(0))
    numbers: list[sympy.Expr] = [problem.omega0, start, speed]
    shape = []
    analytic_terms = []
    for lower, upper, coefficients, fractional, analytic in pieces:
        numbers += [-sympy.oo if lower is None else lower, sympy.oo if upper is None else upper, *coefficients]
        for coefficient, point, exponent in fractional:
            numbers += [coefficient, point, exponent]
        shape.append((len(coefficients), len(fractional)))
        analytic_terms.append(None if analytic == 0 else sympy.lambdify((DISPLACEMENT, *symbols), analytic, modules="numpy", dummify=True))
    compiled = sympy.lambdify(symbols, numbers, modules="math", dummify=True)

    def evaluate(*values: float) -> tuple[Any, ...]:
        flat = [float(value) for value in compiled(*values)]
        table, position = [], 3
        for (size, terms), term in zip(shape, analytic_terms):
            law = np.array(flat[position + 2 : position + 2 + size])
            cursor = position + 2 + size
            fractional = tuple(tuple(flat[cursor + 3 * k : cursor + 3 * k + 3]) for k in range(terms))
            function = None if term is None else _bind(term, values)
            table.append((flat[position], flat[position + 1], law, fractional, function))
            position = cursor + 3 * terms
        return flat[0], flat[1], flat[2], tuple(table)

    return evaluate


def _bind(term: Callable[..., Any], values: tuple[float, ...]) -> Callable[[np.ndarray], np.ndarray]:
    """The analytic term as a function of u alone (float arrays in and out, NaN where it is not real)."""

    def function(u: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            result = np.asarray(term(u, *values))
        if np.iscomplexobj(result):
            result = np.where(np.abs(result.imag) <= 1e-14 * np.abs(result.real), result.real, np.nan)
        return np.broadcast_to(np.asarray(result, dtype=float), np.shape(u))

    return function


def _polyval(coefficients: np.ndarray, u: Any) -> Any:
    return np.polynomial.polynomial.polyval(u, coefficients)


class _Piece:
    """f = Σ law[m] u^m + Σ c |u − b|^p + analytic(u) on (lower, upper) and F = ∫_0^u f on it (F continuous across
    the pieces, F(0) = 0).  A polynomial piece is solved exactly (roots of polynomials); any other one on ``nodes``,
    the part of the grid inside it where f is finite (``reach``: their extent)."""

    def __init__(self, lower: float, upper: float, law: np.ndarray, fractional: tuple, analytic: Any) -> None:
        self.lower, self.upper = lower, upper
        self.law = np.pad(law, (0, max(0, 2 - len(law))))
        self.primitive_law = np.concatenate([[0.0], self.law / np.arange(1, len(self.law) + 1)])
        self.fractional = tuple(fractional)
        self.analytic = analytic
        self.polynomial = not self.fractional and analytic is None
        self.constant = 0.0
        self.nodes = np.array([])
        self.cumulative = np.array([])
        self.reach = (lower, upper)
        self.unresolved = (False, False)  # whether the grid stops at an end because it no longer resolves f
        self.node_force = np.array([])
        self.node_primitive = np.array([])

    def force(self, u: Any) -> Any:
        u = np.asarray(u, dtype=float)
        with np.errstate(all="ignore"):
            value = _polyval(self.law, u)
            for coefficient, point, exponent in self.fractional:
                value = value + coefficient * np.abs(u - point) ** exponent
            if self.analytic is not None:
                value = value + self.analytic(u)
        return value

    def primitive(self, u: Any) -> Any:
        u = np.asarray(u, dtype=float)
        with np.errstate(all="ignore"):
            value = _polyval(self.primitive_law, u) + self.constant
            for coefficient, point, exponent in self.fractional:
                value = value + coefficient * np.sign(u - point) * np.abs(u - point) ** (exponent + 1) / (exponent + 1)
            if self.analytic is not None:
                value = value + self._quadrature(u)
        return value

    def _quadrature(self, u: np.ndarray) -> np.ndarray:
        """∫ analytic from the grid's anchor to u: the cumulative cell integrals to the node below u plus 16-point
        Gauss–Legendre from that node to u."""
        index = np.clip(np.searchsorted(self.nodes, u, side="right") - 1, 0, len(self.nodes) - 2)
        start = self.nodes[index]
        middle, half = (u + start) / 2, (u - start) / 2
        points = middle[..., None] + half[..., None] * _GAUSS_NODES
        return self.cumulative[index] + half * (self.analytic(points) @ _GAUSS_WEIGHTS)

    def prepare(self, scale: float, points: list[float]) -> None:
        """Nodes (see the module docstring) and the analytic term's cumulative integral (a piece that is not a
        polynomial)."""
        core = np.linspace(-_CORE * scale, _CORE * scale, 2 * _CORE_CELLS + 1)
        outer = _CORE * scale * _RATIO ** np.arange(1, int(math.log(_REACH / _CORE) / math.log(_RATIO)) + 2)
        grid = np.concatenate([-outer[::-1], core, outer, [p for p in points if math.isfinite(p)]])
        ends = [end for end in (self.lower, self.upper) if math.isfinite(end)]
        nodes = np.unique(np.concatenate([grid[(grid >= self.lower) & (grid <= self.upper)], ends]))
        for _ in range(_REFINE + 1):
            values, middle = self.force(nodes), (nodes[1:] + nodes[:-1]) / 2
            finite = np.isfinite(values) & (np.abs(values) <= _HUGE)
            scale_f = float(np.max(np.abs(values[finite & (np.abs(nodes) <= _CORE * scale)]), initial=1e-300))
            centre, ends_mean = self.force(middle), (values[1:] + values[:-1]) / 2
            quarters = self.force(np.stack([nodes[:-1], (nodes[:-1] + middle) / 2, middle, (middle + nodes[1:]) / 2, nodes[1:]], axis=1))
            with np.errstate(all="ignore"):
                steps = np.diff(quarters, axis=1)
                bends = np.diff(steps, axis=1)
                # a cell resolves f when f is nearly linear on it, or monotone and convex (or concave) on five points
                # (exponential and power growth on the geometric cells; an oscillation is neither)
                smooth = (np.all(steps > 0, axis=1) | np.all(steps < 0, axis=1)) & (np.all(bends >= 0, axis=1) | np.all(bends <= 0, axis=1))
                coarse = ~((np.abs(centre - ends_mean) <= _RESOLVED * np.maximum(scale_f, np.maximum(np.abs(values[1:]), np.abs(values[:-1]))))
                           | smooth)
            inner = coarse & (np.abs(middle) <= _CORE * scale) & finite[1:] & finite[:-1]
            if _ == _REFINE or not inner.any():
                break
            nodes = np.sort(np.concatenate([nodes, middle[inner]]))
        # keep the nodes joined to the anchor (0, or the end of the piece nearest to it) by cells where f is finite
        # and, outside the core, resolved
        blank = ~finite[1:] | ~finite[:-1]
        bad = blank | (coarse & (np.abs(middle) > _CORE * scale))
        anchor = int(np.argmin(np.abs(nodes - min(max(0.0, self.lower), self.upper))))
        below, above = np.flatnonzero(bad[:anchor]), np.flatnonzero(bad[anchor:])
        first = below[-1] + 1 if below.size else 0
        last = anchor + above[0] if above.size else len(nodes) - 1
        if last - first < 1 or not finite[anchor]:
            raise ParameterError(f"f is not finite on its piece ({self.lower:.6g}, {self.upper:.6g}): no orbit can be followed")
        # an end where f is still finite but no longer resolved: what lies beyond is not known (not an escape)
        self.unresolved = (bool(below.size) and not blank[below[-1]], bool(above.size) and not blank[anchor + above[0]])
        self.nodes = nodes[first : last + 1]
        self.reach = (float(self.nodes[0]), float(self.nodes[-1]))
        if self.analytic is not None:
            middle, half = (self.nodes[1:] + self.nodes[:-1]) / 2, (self.nodes[1:] - self.nodes[:-1]) / 2
            cells = half * (self.analytic(middle[:, None] + half[:, None] * _GAUSS_NODES) @ _GAUSS_WEIGHTS)
            anchor -= first
            cumulative = np.zeros(len(self.nodes))
            cumulative[anchor + 1 :] = np.cumsum(cells[anchor:])
            cumulative[:anchor] = -np.cumsum(cells[:anchor][::-1])[::-1]
            self.cumulative = cumulative

    def tabulate(self) -> None:
        """f and F at the nodes (once the constant of F is fixed)."""
        self.node_force, self.node_primitive = self.force(self.nodes), self.primitive(self.nodes)


def _refine(function: Callable[[float], float], a: float, b: float) -> float:
    from scipy.optimize import brentq  # here: importing scipy.optimize costs ~0.3 s, and most orbits need no root

    return float(brentq(function, a, b, xtol=1e-15 * max(abs(a), abs(b), 1e-300), rtol=4 * np.finfo(float).eps, maxiter=200))


@dataclass(frozen=True)
class _Orbit:
    """The real orbit at one ε: its turning points, or None with the reason there is none."""

    low: float | None
    high: float | None
    reason: str = ""
    lost: bool = False  # the orbit leaves the interval where f is resolved: not followed further


@dataclass(frozen=True)
class OrbitRange:
    """Where in ε the true orbit keeps the derivation's regime, and the nearest singularity of ω(ε).

    Attributes
    ----------
    lower, upper : float
        The open interval (lower, upper) ∋ 0 of ε on which the orbit through the release state
        crosses the same breakpoints as the derivation assumed and passes no hump of the potential
        (±inf: no bound).
    lower_reason, upper_reason : str
        What happens at the bound ("" when unbounded).
    radius : float
        Distance to the nearest singularity of ω(ε) found (+inf: none); the series in ε cannot
        converge beyond it.  An upper estimate of the radius of convergence (for pieces that are not
        polynomials, only real singularities are found).
    radius_reason : str
    """

    lower: float
    upper: float
    lower_reason: str
    upper_reason: str
    radius: float
    radius_reason: str
    _edges: np.ndarray = field(repr=False, compare=False)
    _states: Callable[[int], Any] = field(repr=False, compare=False)  # interval between edges -> frozenset or reason str
    _exact: Any = field(repr=False, compare=False)  # ε -> state (for ε exactly on an edge)

    def state(self, epsilon: float) -> Any:
        """The orbit's regime at ε: the frozenset of indices of the crossed breakpoints, or the reason (str) that
        no periodic orbit exists."""
        index = int(np.searchsorted(self._edges, epsilon))
        if index < len(self._edges) and self._edges[index] == epsilon:
            return self._exact(epsilon)
        return self._states(index)

    def judge(self, epsilon: Any, gauge: str = "eps") -> str | None:
        """Raise :class:`~lindstedt.ParameterError` where no periodic orbit exists at some ε of ``epsilon``; else the
        warning text for the first ε outside (lower, upper) or beyond the radius, or None."""
        if isinstance(epsilon, float):  # one ε inside the range and the disc: the common case, decided at once
            if self.lower < epsilon < self.upper and abs(epsilon) < self.radius:
                return None
        elif np.all((np.asarray(epsilon) > self.lower) & (np.asarray(epsilon) < self.upper)
                    & (np.abs(epsilon) < self.radius)):
            return None
        points = np.unique(np.asarray(epsilon, dtype=float))
        points = points[np.isfinite(points)]
        outside = points[(points <= self.lower) | (points >= self.upper)]
        for value in outside[np.argsort(np.abs(outside))]:
            state = self.state(float(value))
            if isinstance(state, str):
                bound, reason = (self.upper, self.upper_reason) if value >= self.upper else (self.lower, self.lower_reason)
                raise ParameterError(
                    f"no periodic orbit at eps = {value:.6g}: {state}. The expansion describes the periodic orbit through "
                    f"its release state for eps in ({self.lower:.6g}, {self.upper:.6g}) (at eps = {bound:.6g} {reason}); "
                    "there is nothing to approximate here"
                )
        if outside.size:
            value = float(outside[np.argmax(np.abs(outside))])
            side, reason = (self.upper, self.upper_reason) if value >= self.upper else (self.lower, self.lower_reason)
            return (
                f"eps = {value:.6g} is outside the range ({self.lower:.6g}, {self.upper:.6g}) where the orbit keeps the contact "
                f"regime this expansion was derived for: at eps = {side:.6g} {reason}. Beyond it the series describes another "
                "motion (its value is not the frequency of this orbit); use lindstedt.reference_solution or "
                "lindstedt.references.conservative_frequency"
            )
        far = points[np.abs(points) >= self.radius]
        if far.size:
            value = float(far[np.argmax(np.abs(far))])
            return (
                f"at eps = {value:.6g} the series in {gauge} is not converging: eps is beyond its radius of convergence "
                f"(|eps| < {self.radius:.6g}: "
                f"{self.radius_reason}); no truncation converges there, whatever its terms look like; use a smaller eps or "
                "lindstedt.reference_solution"
            )
        return None


def _clustered(roots: np.ndarray) -> list[complex]:
    """The roots with each cluster of nearby ones (a multiple root, split by rounding into ~1e-8 apart) replaced by
    its mean, which is accurate to rounding."""
    remaining = sorted((complex(root) for root in roots), key=lambda root: (root.real, root.imag))
    result: list[complex] = []
    while remaining:
        seed = remaining.pop(0)
        group = [seed] + [root for root in remaining if abs(root - seed) <= 1e-5 * (1 + abs(seed))]
        remaining = [root for root in remaining if all(root is not member for member in group)]
        result.append(sum(group) / len(group))
    return result


def _describe_change(before: Any, after: Any, breakpoints: tuple[float, ...], event: str) -> str:
    if isinstance(after, str):
        return f"{event}; beyond it there is no periodic orbit ({after})"
    if isinstance(after, tuple):
        return f"{event}; beyond it the orbit is not followed ({after[1]})"
    if isinstance(before, (str, tuple)):
        return f"{event}"
    gained = sorted(breakpoints[i] for i in after - before)
    lost = sorted(breakpoints[i] for i in before - after)
    parts = []
    if not gained and not lost:
        parts.append("the orbit passes a hump of the potential (a separatrix): beyond it, it is another orbit")
    if gained:
        parts.append("the orbit starts crossing the breakpoint " + ", ".join(f"u = {b:.6g}" for b in gained))
    if lost:
        parts.append("the orbit stops crossing the breakpoint " + ", ".join(f"u = {b:.6g}" for b in lost))
    return f"{event} ({' and '.join(parts)})"


def orbit_range(omega0: float, u0: float, v0: float, pieces: tuple[tuple[Any, ...], ...], gauge: int) -> OrbitRange:
    """The :class:`OrbitRange` of ``u'' + ω0² u + ε f(u) = 0`` through ``u(0) = u0``, ``u'(0) = v0``, f given by its
    ``pieces`` ``(lower, upper, c_0 … c_d[, fractional terms (c, b, p), analytic term or None])`` (increasing;
    :func:`range_function` makes them); ``gauge`` > 1: the series is in a root of ε past a grazing breakpoint (its
    regime is that of the orbit just after ε = 0)."""
    omega2 = omega0 * omega0
    table = [_Piece(piece[0], piece[1], np.asarray(piece[2], dtype=float), *(piece[3:] if len(piece) > 3 else ((), None)))
             for piece in pieces]
    breakpoints = tuple(piece.upper for piece in table[:-1])
    scale = math.sqrt(u0 * u0 + v0 * v0 / omega2)
    tolerance = 1e-10 * max(scale, 1e-300)
    if not all(piece.polynomial for piece in table):
        for piece in table:
            if not piece.polynomial:
                piece.prepare(scale, [u0, *breakpoints])
    # F continuous with F(0) = 0: fix each piece's constant from the piece holding 0 outwards
    home = next(j for j, piece in enumerate(table) if piece.lower <= 0.0 <= piece.upper and (piece.upper > 0 or j == len(table) - 1))
    table[home].constant = -float(table[home].primitive(0.0))
    for j in list(range(home + 1, len(table))) + list(range(home - 1, -1, -1)):
        join, neighbour = (table[j].lower, table[j - 1]) if j > home else (table[j].upper, table[j + 1])
        table[j].constant = float(neighbour.primitive(join)) - float(table[j].primitive(join))
        if table[j].polynomial:
            table[j].primitive_law[0] += table[j].constant
            table[j].constant = 0.0
    for piece in table:
        if not piece.polynomial:
            piece.tabulate()

    def piece_of(u: float, side: int) -> int:
        """Index of the piece holding u (on a breakpoint: the one on ``side``)."""
        return int(np.searchsorted(breakpoints, u, side="left" if side < 0 else "right"))

    F0 = float(table[piece_of(u0, 1)].primitive(u0))
    E0 = 0.5 * v0 * v0 + 0.5 * omega2 * u0 * u0

    def turning_point(piece: _Piece, epsilon: float, energy: float, start: float, direction: int) -> float | None:
        """The first root of V − E from ``start`` in ``direction`` inside ``piece`` (None: none in it)."""
        released = start == u0 and v0 == 0.0
        if piece.polynomial:
            polynomial = epsilon * piece.primitive_law.copy()
            polynomial = np.pad(polynomial, (0, max(0, 3 - len(polynomial))))
            polynomial[2] += 0.5 * omega2
            polynomial[0] -= energy
            if released:  # u0 is a root: deflate it
                polynomial, _ = np.polynomial.polynomial.polydiv(polynomial, np.array([-u0, 1.0]))
            trimmed = np.trim_zeros(polynomial, "b")
            roots = np.roots(trimmed[::-1]) if len(trimmed) > 1 else np.array([])
            real = [r.real for r in roots if abs(r.imag) <= 1e-9 * max(abs(r), scale)]
            if direction < 0:
                candidates = [r for r in real if piece.lower - tolerance <= r < start - (tolerance if start == u0 else -tolerance)]
                return max(candidates) if candidates else None
            candidates = [r for r in real if start + (tolerance if start == u0 else -tolerance) < r <= piece.upper + tolerance]
            return min(candidates) if candidates else None

        def excess(u: Any) -> Any:  # V − E
            return 0.5 * omega2 * np.square(u) + epsilon * piece.primitive(u) - energy

        def rising(u: Any) -> Any:  # V' in the direction of motion
            return direction * (omega2 * np.asarray(u) + epsilon * piece.force(u))

        if direction > 0:
            chosen = slice(int(np.searchsorted(piece.nodes, start + tolerance, side="right")), None)
        else:
            chosen = slice(int(np.searchsorted(piece.nodes, start - tolerance, side="left")) - 1, None, -1)
            if chosen.start < 0:
                chosen = slice(0, 0)
        points = np.concatenate([[start], piece.nodes[chosen]])
        values = np.concatenate([[float(excess(start))], 0.5 * omega2 * np.square(piece.nodes[chosen])
                                 + epsilon * piece.node_primitive[chosen] - energy])
        slopes = np.concatenate([[float(rising(start))], direction * (omega2 * piece.nodes[chosen] + epsilon * piece.node_force[chosen])])
        candidates = np.flatnonzero((values[1:] > 0) | ((slopes[:-1] > 0) & (slopes[1:] < 0)))
        for index in candidates:
            a, b = float(points[index]), float(points[index + 1])
            if index == 0 and released:  # V − E vanishes at u0 to rounding: start the bracket where it is negative
                fine = np.linspace(a, b, 65)[1:]
                negative = np.flatnonzero(excess(fine) < 0)
                if not negative.size:
                    return a  # an orbit below the grid's resolution: u0 is (nearly) an equilibrium
                a = float(fine[negative[0]])
            if values[index + 1] <= 0 or slopes[index] > 0 > slopes[index + 1]:  # a hump inside the cell
                if slopes[index] > 0 > slopes[index + 1]:
                    top = _refine(lambda u: float(rising(u)), a, b)
                    if float(excess(top)) < 0:
                        if values[index + 1] <= 0:
                            continue
                    else:
                        b = top
                        if float(excess(top)) == 0:
                            return top
            if float(excess(a)) >= 0:
                return a
            return _refine(lambda u: float(excess(u)), a, b)
        return None

    def orbit(epsilon: float) -> _Orbit:
        energy = E0 + epsilon * F0

        def slope(j: int, u: float) -> float:
            return omega2 * u + epsilon * float(table[j].force(u))

        if v0 != 0.0:
            directions = (-1, 1)
        else:
            left, right = slope(piece_of(u0, -1), u0), slope(piece_of(u0, 1), u0)
            if left > 1e-13 * (abs(omega2 * u0) + 1e-300):
                directions = (-1,)
            elif right < -1e-13 * (abs(omega2 * u0) + 1e-300):
                directions = (1,)
            else:
                return _Orbit(None, None, f"the release point u = {u0:.6g} is an equilibrium")
        ends = {}
        for direction in directions:
            j = piece_of(u0, direction)
            start = u0
            found = None
            while 0 <= j < len(table):
                piece = table[j]
                found = turning_point(piece, epsilon, energy, start, direction)
                if found is not None:
                    break
                end = piece.reach[0] if direction < 0 else piece.reach[1]
                if end != (piece.lower if direction < 0 else piece.upper):  # the grid ends before the piece does
                    if piece.unresolved[0 if direction < 0 else 1]:
                        return _Orbit(None, None, f"the orbit reaches u = {end:.6g}, beyond which f varies faster than the "
                                                  "grid that follows it resolves", lost=True)
                    side = "down" if direction < 0 else "up"
                    return _Orbit(None, None, f"the motion escapes {side} (no turning point: the potential stays below the "
                                              f"energy as far as it is followed, u = {end:.6g})")
                start, j = end, j + direction
            if found is None:
                where = table[0 if direction < 0 else -1]
                stiffness = omega2 + epsilon * where.law[1]
                detail = ""
                if where.polynomial and len(np.trim_zeros(where.law, "b")) <= 2 and stiffness <= 0:
                    region = f"u < {where.upper:.6g}" if direction < 0 and where.upper < math.inf else (
                        f"u > {where.lower:.6g}" if where.lower > -math.inf else "every u")
                    detail = (f"; on {region} the stiffness omega0**2 + eps*{where.law[1]:.6g} is not positive, "
                              f"it vanishes at eps = {-omega2 / where.law[1]:.6g}")
                side = "down" if direction < 0 else "up"
                return _Orbit(None, None, f"the motion escapes {side} to infinity (no turning point{detail})")
            ends[direction] = found
        return _Orbit(ends.get(-1, u0), ends.get(1, u0))

    orbits: dict[float, _Orbit] = {}

    def orbit_at(epsilon: float) -> _Orbit:
        if epsilon not in orbits:
            orbits[epsilon] = orbit(epsilon)
        return orbits[epsilon]

    def state(epsilon: float) -> Any:
        result = orbit_at(epsilon)
        if result.lost:
            return ("not followed", result.reason)
        if result.low is None:
            return result.reason
        width = 1e-9 * max(result.high - result.low, scale)
        return frozenset(i for i, b in enumerate(breakpoints) if result.low + width < b < result.high - width)

    # the events: where the regime can change
    events: dict[float, str] = {}
    nearness: dict[float, float] = {}  # distance from u0 of the point an event is about (the nearest one names it)

    def add(value: float, text: str, where: float = math.inf) -> None:
        value = float(value)
        if value not in events or abs(where - u0) < nearness[value]:
            events[value], nearness[value] = text, abs(where - u0)
    complex_events: list[tuple[complex, str]] = []

    def level_event(u: float, text: str) -> None:
        """The ε where the point u is on the orbit's energy level, V(u; ε) = E(ε)."""
        difference = float(table[piece_of(u, 1)].primitive(u)) - F0 if math.isfinite(u) else 0.0
        if abs(difference) > 1e-14 * max(abs(F0), 1.0) and abs(u - u0) > tolerance:
            add((E0 - 0.5 * omega2 * u * u) / difference, text, u)

    def critical_text(u: float) -> str:
        if v0 == 0.0 and abs(u - u0) <= 1e-7 * scale:
            return f"the release point u = {u0:.6g} becomes an unstable equilibrium (a separatrix: the period is infinite)"
        return f"a turning point meets the critical point u = {u:.6g} of the potential"

    def critical_events(piece: _Piece) -> None:
        """The real roots of D(u) = ω0² u (F(u) − F0) − f(u)(ω0² u²/2 − E0) on the grid of a piece that is not a
        polynomial (sign changes refined by Brent's method), each at its ε."""

        def determinant(u: Any) -> Any:
            return omega2 * u * (piece.primitive(u) - F0) - piece.force(u) * (0.5 * omega2 * np.square(u) - E0)

        nodes = piece.nodes
        with np.errstate(all="ignore"):
            values = omega2 * nodes * (piece.node_primitive - F0) - piece.node_force * (0.5 * omega2 * np.square(nodes) - E0)
        finite = np.isfinite(values)
        roots = [float(u) for u in nodes[finite & (values == 0)]]
        changes = np.flatnonzero(finite[:-1] & finite[1:] & (np.sign(values[:-1]) * np.sign(values[1:]) < 0))
        roots += [_refine(lambda u: float(determinant(u)), float(nodes[i]), float(nodes[i + 1])) for i in changes]
        size = max(abs(float(piece.force(min(max(u, piece.reach[0]), piece.reach[1])))) for u in (-scale, scale))
        origin = piece.lower <= 0.0 <= piece.upper and abs(float(piece.force(0.0))) <= 1e-12 * size
        for root in roots:
            if origin and abs(root) <= 1e-8 * scale:  # the origin is critical at every eps: on the level at one
                level = float(piece.primitive(root)) - F0
                value = (E0 - 0.5 * omega2 * root * root) / level if abs(level) > 1e-14 * max(abs(F0), 1.0) else math.nan
            else:
                force = float(piece.force(root))
                value = -omega2 * root / force if force != 0 else math.nan
            if math.isfinite(value) and abs(value) > 1e-12:
                add(value, critical_text(root), root)

    if v0 == 0.0:  # the release point is a critical point of V (D has a double root there: no sign change to see)
        for side in (-1, 1):
            force = float(table[piece_of(u0, side)].force(u0))
            if force != 0.0 and abs(omega2 * u0 / force) > 1e-12:
                add(-omega2 * u0 / force, critical_text(u0), u0)
    for b in breakpoints:
        level_event(b, f"the orbit's turning point reaches the breakpoint u = {b:.6g}")
    for piece in table:
        law = piece.law
        if piece.polynomial and law[1] != 0 and not np.any(law[2:]):
            add(-omega2 / law[1], f"the stiffness omega0**2 + eps*{law[1]:.6g} of the piece vanishes")
        if not piece.polynomial:
            for end, bound in zip(piece.reach, (piece.lower, piece.upper)):
                if end != bound:
                    level_event(end, f"the orbit's turning point reaches u = {end:.6g}, the end of the interval searched")
            critical_events(piece)
            continue
        # ω0² u (G(u) − F0) − g(u)(ω0² u²/2 − E0)
        shifted = piece.primitive_law.copy()
        shifted[0] -= F0
        first = np.polynomial.polynomial.polymul([0.0, omega2], shifted)
        second = np.polynomial.polynomial.polymul(law, [-E0, 0.0, 0.5 * omega2])
        determinant = np.polynomial.polynomial.polysub(first, second)
        size = np.max(np.abs(np.concatenate([first, second])))
        determinant = np.where(np.abs(determinant) <= 1e-13 * size, 0.0, determinant)
        trimmed = np.trim_zeros(determinant, "b")
        if len(trimmed) == 1:
            continue
        if not len(trimmed):  # a homogeneous linear piece: its critical point u = 0 at the level E(ε)
            level = float(piece.primitive_law[0]) - F0
            if abs(level) > 1e-14 * max(abs(F0), 1.0):
                add(E0 / level, "the orbit reaches the equilibrium u = 0 of a piece", 0.0)
            continue
        for root in _clustered(np.roots(trimmed[::-1])):
            force = complex(np.polynomial.polynomial.polyval(root, law))
            if abs(force) > 1e-10 * (1 + abs(root)) ** (len(law) - 1) * np.max(np.abs(law)):
                value = -omega2 * root / force
            else:
                level = complex(np.polynomial.polynomial.polyval(root, piece.primitive_law)) - F0
                if abs(level) <= 1e-14:
                    continue
                value = (E0 - 0.5 * omega2 * root * root) / level
            if not np.isfinite(value) or abs(value) <= 1e-12:
                continue
            if abs(value.imag) <= 1e-6 * abs(value):
                add(value.real, critical_text(root.real), root.real)
            else:
                complex_events.append((value, f"the orbit meets a critical point of the potential at complex eps = {value:.4g}"))

    merged: list[float] = []
    for value in sorted(value for value in events if abs(value) > 1e-12):
        if merged and value - merged[-1] <= 1e-9 * max(1.0, abs(value)):
            if nearness[value] < nearness[merged[-1]]:
                events[merged[-1]] = events[value]
                nearness[merged[-1]] = nearness[value]
            continue
        merged.append(value)
    edges = np.array(merged)
    points = np.concatenate([edges[:1] - 1.0 - abs(edges[:1]), (edges[1:] + edges[:-1]) / 2, edges[-1:] + 1.0 + abs(edges[-1:])]) \
        if edges.size else np.array([1.0])
    computed: dict[int, Any] = {}

    def states(index: int) -> Any:  # the regime on the interval between edges (computed when first asked)
        if index not in computed:
            computed[index] = state(float(points[index]))
        return computed[index]

    # the interval holding 0: probe each side of it where 0 splits it
    split = int(np.searchsorted(edges, 0.0))
    below_edge = edges[split - 1] if split > 0 else -math.inf
    above_edge = edges[split] if split < len(edges) else math.inf
    probe_plus = 0.5 * above_edge if math.isfinite(above_edge) else 1.0
    probe_minus = 0.5 * below_edge if math.isfinite(below_edge) else -1.0
    reference_plus = state(probe_plus) if gauge > 1 else state(0.0)
    reference_minus = state(0.0)

    def jumps(index: int) -> bool:
        """Whether the orbit's turning points jump at ``edges[index]`` (a turning point passes a hump of V)."""
        edge = float(edges[index])
        neighbours = [abs(edge - float(edges[k])) for k in (index - 1, index + 1) if 0 <= k < len(edges)] + [abs(edge)]
        delta = min(1e-8 * max(1.0, abs(edge)), 0.25 * min(neighbours))
        before, after = orbit_at(edge - delta), orbit_at(edge + delta)
        if before.low is None or after.low is None:
            return (before.low is None) != (after.low is None)
        return abs(after.low - before.low) + abs(after.high - before.high) > 1e-3 * scale

    def sweep(direction: int, reference: Any) -> tuple[float, str]:
        indices = range(split, len(edges)) if direction > 0 else range(split - 1, -1, -1)
        near = state(probe_plus if direction > 0 else probe_minus)
        if near != reference:
            return 0.0, _describe_change(reference, near, breakpoints, "at eps = 0 already")
        previous = reference
        for index in indices:
            after = states(index + 1 if direction > 0 else index)
            if after != previous:
                return float(edges[index]), _describe_change(previous, after, breakpoints, events[float(edges[index])])
            if isinstance(after, frozenset) and jumps(index):
                return float(edges[index]), _describe_change(previous, after, breakpoints, events[float(edges[index])])
        return (math.inf if direction > 0 else -math.inf), ""

    upper, upper_reason = sweep(1, reference_plus)
    lower, lower_reason = sweep(-1, reference_minus)
    # the nearest real singularity: where the orbit changes (the series in a root of eps continues the crossing orbit,
    # not the real one at eps < 0)
    radius, radius_reason = math.inf, ""
    for bound, reason in ((upper, upper_reason), (lower, lower_reason) if gauge == 1 else (math.inf, "")):
        if 0 < abs(bound) < radius:
            radius, radius_reason = abs(bound), f"at eps = {bound:.6g} {reason}"
    for value, text in complex_events:
        if abs(value) < radius:
            radius, radius_reason = abs(value), text
    return OrbitRange(lower, upper, lower_reason, upper_reason, radius, radius_reason, edges, states, state)
