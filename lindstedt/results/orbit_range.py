"""How far in ε the derivation of an expansion of ``u'' + ω0² u + ε f(u) = 0`` holds.

A Lindstedt–Poincaré series is derived for the contact regime of the orbit at ε = 0 (which
breakpoints it crosses) and sums to the true ω(ε) only inside its disc of convergence.  This
module follows the *true* orbit through the release state (u0, v0) (u0 = a0, v0 = 0 for a
release at rest) as ε moves away from 0, for f polynomial or piecewise polynomial.

The potential ``V(u; ε) = ω0² u²/2 + ε F(u)`` (F = ∫_0^u f, continuous) and the energy
``E(ε) = v0²/2 + ω0² u0²/2 + ε F(u0)`` are both linear in ε, so the orbit — the interval
between the turning points V = E around u0 — can change its regime only at

* a breakpoint b becoming a turning point: ``V(b; ε) = E(ε)``, i.e.
  ``ε = (E0 − ω0² b²/2) / (F(b) − F(u0))``, E0 = v0²/2 + ω0² u0²/2 (exact);
* a turning point meeting a critical point of V (a separatrix, or u0 becoming an equilibrium):
  ``V' = 0`` and ``V = E`` on one polynomial piece j (law g_j, primitive G_j); eliminating ε,
  u is a root of ``ω0² u (G_j(u) − F(u0)) − g_j(u) (ω0² u²/2 − E0)`` and ε follows from V' = 0.
  For Duffing ``f = u³``, a0 = 1: roots u = ±1 give ε = −1 (the separatrix: the motion escapes
  for ε a0²/ω0² ≤ −1) and u = 0 gives ε = −2 (m = 1 of the elliptic integral K(m),
  m = ε a0²/(2(ω0² + ε a0²)));
* a linear piece losing its stiffness: ``ω0² + ε c_1 = 0``.

Between consecutive such ε (the *events*) the orbit is computed once, from the roots of
V − E piece by piece: its set of crossed breakpoints, or that no periodic orbit exists (the
motion escapes, or u0 is an equilibrium).  :class:`OrbitRange` holds

* ``lower < 0 < upper``: the open ε-interval on which the orbit keeps the derivation's regime
  (the first event on each side where it changes);
* ``radius``: the distance from 0 to the nearest singularity of ω(ε) that the law gives — the
  real events where the orbit changes, and the complex critical-level points — an upper
  estimate of the radius of convergence of the series (in ε; the gauge ε^{1/2} has √radius).

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

_ESCAPE = "escape"
_EQUILIBRIUM = "equilibrium"


@dataclass(frozen=True)
class _Piece:
    """f = Σ law[m] u^m on (lower, upper); ``primitive`` is F on it (ascending coefficients, F continuous, F(0) = 0)."""

    lower: float
    upper: float
    law: np.ndarray
    primitive: np.ndarray


def range_function(problem: Oscillator, symbols: tuple[sympy.Symbol, ...]) -> Callable[..., tuple[float, ...]] | None:
    """The numbers :func:`orbit_range` reads — ``(ω0, u0, v0, then lower, upper, c_0 … c_d per polynomial piece)``,
    ±inf for unbounded ends — as one compiled function of the free ``symbols``; None when no range is computed:
    a piece that is not a polynomial (fractional or analytic contact laws, non-polynomial smooth f), a release
    shifted by ε a1, or the "harmonic" normalization (the release point is itself a series there)."""
    if problem.normalization != "initial" or (not problem.has_initial_velocity and problem.a1 != 0):
        return None
    f = problem.nonlinearity
    if not problem.is_non_smooth:
        if not f.is_polynomial(DISPLACEMENT):
            return None
        pieces = [(None, None, sympy.Poly(f, DISPLACEMENT).all_coeffs()[::-1])]
    else:
        try:
            intervals = decompose_piecewise(f, DISPLACEMENT)
        except UnsupportedNonlinearityError:
            return None
        if any(interval.fractional or interval.analytic != 0 for interval in intervals):
            return None
        pieces = [(interval.lower, interval.upper, list(interval.coefficients)) for interval in intervals]
    start, speed = (problem.u0, problem.v0) if problem.has_initial_velocity else (problem.a0, sympy.Integer(0))
    numbers: list[sympy.Expr] = [problem.omega0, start, speed]
    shape = []
    for lower, upper, coefficients in pieces:
        numbers += [-sympy.oo if lower is None else lower, sympy.oo if upper is None else upper, *coefficients]
        shape.append(len(coefficients))
    compiled = sympy.lambdify(symbols, numbers, modules="math")

    def evaluate(*values: float) -> tuple[Any, ...]:
        flat = [float(value) for value in compiled(*values)]
        table, position = [], 3
        for size in shape:
            table.append((flat[position], flat[position + 1], np.array(flat[position + 2 : position + 2 + size])))
            position += 2 + size
        return flat[0], flat[1], flat[2], tuple(table)

    return evaluate


def _polyval(coefficients: np.ndarray, u: Any) -> Any:
    return np.polynomial.polynomial.polyval(u, coefficients)


@dataclass(frozen=True)
class _Orbit:
    """The real orbit at one ε: its turning points, or None with the reason there is none."""

    low: float | None
    high: float | None
    reason: str = ""


@dataclass(frozen=True)
class OrbitRange:
    """Where in ε the true orbit keeps the derivation's regime, and the nearest singularity of ω(ε).

    Attributes
    ----------
    lower, upper : float
        The open interval (lower, upper) ∋ 0 of ε on which the orbit through the release state
        crosses the same breakpoints as the derivation assumed (±inf: no bound).
    lower_reason, upper_reason : str
        What happens at the bound ("" when unbounded).
    radius : float
        Distance to the nearest singularity of ω(ε) found (+inf: none); the series in ε cannot
        converge beyond it.
    radius_reason : str
    """

    lower: float
    upper: float
    lower_reason: str
    upper_reason: str
    radius: float
    radius_reason: str
    _edges: np.ndarray = field(repr=False, compare=False)
    _states: tuple[Any, ...] = field(repr=False, compare=False)  # per interval between edges: frozenset or reason str
    _reference: Any = field(repr=False, compare=False)
    _exact: Any = field(repr=False, compare=False)  # ε -> state (for ε exactly on an edge)
    _breakpoints: tuple[float, ...] = field(repr=False, compare=False)

    def state(self, epsilon: float) -> Any:
        """The orbit's regime at ε: the frozenset of indices of the crossed breakpoints, or the reason (str) that
        no periodic orbit exists."""
        index = int(np.searchsorted(self._edges, epsilon))
        if index < len(self._edges) and self._edges[index] == epsilon:
            return self._exact(epsilon)
        return self._states[index]

    def judge(self, epsilon: Any, gauge: str = "eps") -> str | None:
        """Raise :class:`~lindstedt.ParameterError` where no periodic orbit exists at some ε of ``epsilon``; else the
        warning text for the first ε outside (lower, upper) or beyond the radius, or None."""
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
    if isinstance(before, str):
        return f"{event}"
    gained = sorted(breakpoints[i] for i in after - before if isinstance(i, int))
    lost = sorted(breakpoints[i] for i in before - after if isinstance(i, int))
    parts = []
    if not gained and not lost:
        parts.append("the orbit passes a hump of the potential (a separatrix): beyond it, it is another orbit")
    if gained:
        parts.append("the orbit starts crossing the breakpoint " + ", ".join(f"u = {b:.6g}" for b in gained))
    if lost:
        parts.append("the orbit stops crossing the breakpoint " + ", ".join(f"u = {b:.6g}" for b in lost))
    return f"{event} ({' and '.join(parts)})"


def orbit_range(omega0: float, u0: float, v0: float, pieces: tuple[tuple[float, float, np.ndarray], ...], gauge: int) -> OrbitRange:
    """The :class:`OrbitRange` of ``u'' + ω0² u + ε f(u) = 0`` through ``u(0) = u0``, ``u'(0) = v0``, f given by its
    polynomial ``pieces`` ``(lower, upper, c_0 … c_d)`` (increasing; :func:`range_function` makes them); ``gauge`` 2:
    the series is in ε^{1/2} past a grazing breakpoint (its regime is that of the orbit just after ε = 0)."""
    omega2 = omega0 * omega0
    numeric = [(lower, upper, np.pad(law, (0, max(0, 2 - len(law))))) for lower, upper, law in pieces]
    # F continuous with F(0) = 0: integrate each piece, fix its constant from the piece holding 0 outwards
    home = next(j for j, (lower, upper, _) in enumerate(numeric) if lower <= 0.0 <= upper and (upper > 0 or j == len(numeric) - 1))
    primitives: list[np.ndarray | None] = [None] * len(numeric)
    for order in (range(home, len(numeric)), range(home, -1, -1)):
        for j in order:
            lower, upper, law = numeric[j]
            integral = np.concatenate([[0.0], law / np.arange(1, len(law) + 1)])
            if j == home:
                integral[0] = 0.0
            else:
                join, neighbour = (lower, primitives[j - 1]) if j > home else (upper, primitives[j + 1])
                integral[0] = _polyval(neighbour, join) - _polyval(integral, join)
            primitives[j] = integral
    table = tuple(_Piece(lower, upper, law, primitive) for (lower, upper, law), primitive in zip(numeric, primitives))
    breakpoints = tuple(piece.upper for piece in table[:-1])
    scale = math.sqrt(u0 * u0 + v0 * v0 / omega2)
    tolerance = 1e-10 * max(scale, 1e-300)

    def piece_of(u: float, side: int) -> int:
        """Index of the piece holding u (on a breakpoint: the one on ``side``)."""
        index = int(np.searchsorted(breakpoints, u, side="left" if side < 0 else "right"))
        return index

    F0 = float(_polyval(table[piece_of(u0, 1)].primitive, u0))
    E0 = 0.5 * v0 * v0 + 0.5 * omega2 * u0 * u0

    def orbit(epsilon: float) -> _Orbit:
        energy = E0 + epsilon * F0

        def slope(j: int, u: float) -> float:
            return omega2 * u + epsilon * float(_polyval(table[j].law, u))

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
                polynomial = epsilon * piece.primitive.copy()
                polynomial = np.pad(polynomial, (0, max(0, 3 - len(polynomial))))
                polynomial[2] += 0.5 * omega2
                polynomial[0] -= energy
                if start == u0 and v0 == 0.0:  # u0 is a root: deflate it
                    polynomial, _ = np.polynomial.polynomial.polydiv(polynomial, np.array([-u0, 1.0]))
                trimmed = np.trim_zeros(polynomial, "b")
                roots = np.roots(trimmed[::-1]) if len(trimmed) > 1 else np.array([])
                real = [r.real for r in roots if abs(r.imag) <= 1e-9 * max(abs(r), scale)]
                lower, upper = piece.lower, piece.upper
                if direction < 0:
                    candidates = [r for r in real if lower - tolerance <= r < start - (tolerance if start == u0 else -tolerance)]
                    if candidates:
                        found = max(candidates)
                        break
                    start, j = lower, j - 1
                else:
                    candidates = [r for r in real if start + (tolerance if start == u0 else -tolerance) < r <= upper + tolerance]
                    if candidates:
                        found = min(candidates)
                        break
                    start, j = upper, j + 1
            if found is None:
                where = table[0 if direction < 0 else -1]
                stiffness = omega2 + epsilon * (where.law[1] if len(where.law) > 1 else 0.0)
                detail = ""
                if len(np.trim_zeros(where.law, "b")) <= 2 and stiffness <= 0:
                    region = f"u < {where.upper:.6g}" if direction < 0 and where.upper < math.inf else (
                        f"u > {where.lower:.6g}" if where.lower > -math.inf else "every u")
                    detail = (f"; on {region} the stiffness omega0**2 + eps*{where.law[1]:.6g} is not positive, "
                              f"it vanishes at eps = {-omega2 / where.law[1]:.6g}")
                side = "down" if direction < 0 else "up"
                return _Orbit(None, None, f"the motion escapes {side} to infinity (no turning point{detail})")
            ends[direction] = found
        low = ends.get(-1, u0)
        high = ends.get(1, u0)
        return _Orbit(low, high)

    def state(epsilon: float) -> Any:
        result = orbit(epsilon)
        if result.low is None:
            return result.reason
        width = 1e-9 * max(result.high - result.low, scale)
        crossed = frozenset(i for i, b in enumerate(breakpoints) if result.low + width < b < result.high - width)
        return crossed | {("humps", hump_count(epsilon, result.low + width, result.high - width))}

    def hump_count(epsilon: float, low: float, high: float) -> int:
        """How many local maxima of V lie inside the orbit (none for an orbit in one well): it changes where a turning
        point passes a hump of the potential and the orbit spills over into the next well.  A kink of V at a force
        jump is not counted: the orbit reaches it as a turning point first (a breakpoint event)."""
        count = 0
        for piece in table:
            derivative = np.polynomial.polynomial.polyadd(epsilon * piece.law, [0.0, omega2])
            second = np.polynomial.polynomial.polyder(derivative)
            trimmed = np.trim_zeros(derivative, "b")
            lower, upper = max(piece.lower, low), min(piece.upper, high)
            if len(trimmed) > 1:
                count += sum(1 for root in _clustered(np.roots(trimmed[::-1]))
                             if abs(root.imag) <= 1e-9 * max(abs(root), scale) and lower < root.real < upper
                             and _polyval(second, root.real) < 0)
        return count

    # the events: where the regime can change
    events: dict[float, str] = {}
    forced: dict[float, str] = {}  # events that end the regime whatever the states around them
    complex_events: list[tuple[complex, str]] = []
    for b in breakpoints:
        difference = float(_polyval(table[piece_of(b, 1)].primitive, b)) - F0
        if abs(difference) > 1e-14 * max(abs(F0), 1.0) and abs(b - u0) > tolerance:
            events.setdefault((E0 - 0.5 * omega2 * b * b) / difference, f"the orbit's turning point reaches the breakpoint u = {b:.6g}")
    for piece in table:
        law, primitive = piece.law, piece.primitive
        if len(law) > 1 and law[1] != 0 and not np.any(law[2:]):
            events.setdefault(-omega2 / law[1], f"the stiffness omega0**2 + eps*{law[1]:.6g} of the piece vanishes")
        # ω0² u (G(u) − F0) − g(u)(ω0² u²/2 − E0)
        shifted = primitive.copy()
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
            level = float(primitive[0]) - F0
            if abs(level) > 1e-14 * max(abs(F0), 1.0):
                events.setdefault(E0 / level, "the orbit reaches the equilibrium u = 0 of a piece")
            continue
        for root in _clustered(np.roots(trimmed[::-1])):
            force = complex(np.polynomial.polynomial.polyval(root, law))
            if abs(force) > 1e-10 * (1 + abs(root)) ** (len(law) - 1) * np.max(np.abs(law)):
                value = -omega2 * root / force
            else:
                level = complex(np.polynomial.polynomial.polyval(root, primitive)) - F0
                if abs(level) <= 1e-14:
                    continue
                value = (E0 - 0.5 * omega2 * root * root) / level
            if not np.isfinite(value) or abs(value) <= 1e-12:
                continue
            if abs(value.imag) <= 1e-6 * abs(value):
                location = f"u = {root.real:.6g}"
                events.setdefault(float(value.real), f"a turning point meets the critical point {location} of the potential")
                curvature = omega2 + value.real * float(np.polynomial.polynomial.polyval(root.real, np.polynomial.polynomial.polyder(law)))
                if abs(root.real - u0) <= 1e-7 * scale and v0 == 0.0 and curvature < 0:
                    forced[float(value.real)] = (
                        f"the release point u = {u0:.6g} is an unstable equilibrium (a separatrix: the period is infinite)")
            else:
                complex_events.append((value, f"the orbit meets a critical point of the potential at complex eps = {value:.4g}"))
    merged: list[float] = []
    for value in sorted(value for value in events if abs(value) > 1e-12):
        if merged and value - merged[-1] <= 1e-9 * max(1.0, abs(value)):
            if value in forced:
                forced[merged[-1]] = forced[value]
            continue
        merged.append(value)
    edges = np.array(merged)
    points = np.concatenate([edges[:1] - 1.0 - abs(edges[:1]), (edges[1:] + edges[:-1]) / 2, edges[-1:] + 1.0 + abs(edges[-1:])]) \
        if edges.size else np.array([1.0])
    # the interval holding 0: probe each side of it where 0 splits it
    states = tuple(state(float(point)) for point in points)
    split = int(np.searchsorted(edges, 0.0))
    below_edge = edges[split - 1] if split > 0 else -math.inf
    above_edge = edges[split] if split < len(edges) else math.inf
    probe_plus = 0.5 * above_edge if math.isfinite(above_edge) else 1.0
    probe_minus = 0.5 * below_edge if math.isfinite(below_edge) else -1.0
    reference_plus = state(probe_plus) if gauge == 2 else state(0.0)
    reference_minus = state(0.0)

    def sweep(direction: int, reference: Any) -> tuple[float, str]:
        indices = range(split, len(edges)) if direction > 0 else range(split - 1, -1, -1)
        near = state(probe_plus if direction > 0 else probe_minus)
        if near != reference:
            return 0.0, _describe_change(reference, near, breakpoints, "at eps = 0 already")
        previous = reference
        for index in indices:
            after = states[index + 1] if direction > 0 else states[index]
            if float(edges[index]) in forced and not isinstance(after, str):
                return float(edges[index]), forced[float(edges[index])] + "; beyond it the orbit leaves it the other way: another orbit"
            if after != previous:
                return float(edges[index]), _describe_change(previous, after, breakpoints, events[float(edges[index])])
        return (math.inf if direction > 0 else -math.inf), ""

    upper, upper_reason = sweep(1, reference_plus)
    lower, lower_reason = sweep(-1, reference_minus)
    radius, radius_reason = math.inf, ""
    for index, edge in enumerate(edges):  # real singularities: where the orbit changes
        if gauge == 2 and edge < 0:  # the series in eps^(1/2) continues the crossing orbit, not the real one at eps < 0
            continue
        if float(edge) in forced and abs(edge) < radius:
            radius, radius_reason = abs(float(edge)), f"at eps = {edge:.6g} {forced[float(edge)]}"
        elif states[index] != states[index + 1] and abs(edge) < radius:
            radius = abs(float(edge))
            radius_reason = f"at eps = {edge:.6g} {_describe_change(states[index] if edge > 0 else states[index + 1], states[index + 1] if edge > 0 else states[index], breakpoints, events[float(edge)])}"
    for value, text in complex_events:
        if abs(value) < radius:
            radius, radius_reason = abs(value), text
    exact = {float(edge): None for edge in edges}

    def at_edge(epsilon: float) -> Any:
        if exact.get(epsilon) is None:
            exact[epsilon] = state(epsilon)
        return exact[epsilon]

    return OrbitRange(lower, upper, lower_reason, upper_reason, radius, radius_reason, edges, states,
                      (reference_minus, reference_plus), at_edge, breakpoints)
