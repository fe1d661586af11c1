"""The period map of a forced, damped oscillator by DOP853 and its variational equations, for any law.

One degree of freedom (:class:`~lindstedt.problems.forced.ForcedOscillator`)::

    u'' + 2 ζ ω0 u' + ω0² u + ε f(u) = ε s F cos(Ω t)

with any f the package parses (smooth such as ``u**3``, or non-smooth such as ``Max(0, u - b)``,
``Heaviside(u)``, ``Max(0, u)**(3/2)``), and N degrees of freedom
(:class:`~lindstedt.problems.forced.ForcedSystem`)::

    M X'' + C X' + K X + ε W (A X − b)_+ = ε s P cos(Ω t).

:class:`SmoothForcedFlow` implements :class:`~lindstedt.numerics._period_map.PeriodMap`: it integrates
``z = (X, X')`` together with the variational equations ``Y' = J(t, z) Y + ∂F/∂p`` for the
2N + 2 columns ``∂z/∂z0`` (the monodromy), ``∂z/∂Ω`` and ``∂z/∂s`` with
``scipy.integrate.solve_ivp(method="DOP853")``; ``∂Π/∂Ω`` adds the moving end ``kT = 2πk/Ω``
(``F(kT) · (−kT/Ω)``).  A non-smooth law is integrated piecewise: between two breakpoints
(``u = b`` of f, a gap ``A_i X − b_i = 0`` of a spring) the vector field is the analytic piece
of that interval, a directional terminal event stops the integration at the crossing and the next
piece starts there, so no step samples the kink.  Where f jumps (``Heaviside``, ``sign``) the
sensitivities cross the switch through the saltation matrix ``S = I + Δ nᵀ/(nᵀ F⁻)``.
f and f' come from the parsed sympy expression (``problem.nonlinearity``) by ``sympy.lambdify``.

Both problems are one form, ``ε Σ_i w_i f_i(a_iᵀ X − b_i)`` (:class:`_Elements`): one oscillator is N = 1 with the
element ``(f, 1, 0, 1)``, a system has the elements ``(laws_i, A_i, b_i, W_i)`` (unilateral springs ``Max(0, u)``
by default, any law of the 1-dof library per element); the regions, events and saltation matrices are the
elements'.  One oscillator runs a scalar kernel of the same field; regions where every piece is affine fold the
forces into one matrix.

Examples
--------
>>> from lindstedt.problems.forced import ForcedOscillator
>>> flow = SmoothForcedFlow(ForcedOscillator("u", omega0=1, zeta="1/20", forcing=1), 0.5)
>>> value = flow.period_map([0.0, 0.0], 1.2)
>>> value.state.shape, value.d_state.shape, value.d_frequency.shape
((2,), (2, 2), (2,))
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np
import sympy

from .._errors import ConvergenceError, ProblemError, UnsupportedNonlinearityError
from ..limits import checkpoint
from .._precision import locked
from ..problems.forced import ForcedOscillator, ForcedSystem, check_forcing_frequency
from ..problems.system import LAW_VARIABLE, UnilateralSystem
from ._period_map import PeriodMapValue, linear_frequency_bounds, real_argument

__all__ = ["SmoothForcedFlow"]

#: switches at one instant (no time advancing) before the run is declared stuck on a breakpoint (sliding)
_MAX_INSTANT_SWITCHES = 50
#: right-hand-side evaluations allowed per natural period the run spans (a regular period takes ~35 DOP853 steps,
#: ~420 evaluations): beyond, the motion is stiff or diverging (e.g. a steep law driven past its breakpoint) and the
#: run fails instead of creeping on
_MAX_EVALUATIONS_PER_NATURAL_PERIOD = 100_000
#: evaluations between two checkpoints of lindstedt.limits (budget, cancellation) inside one integration
_CHECKPOINT_EVERY = 5_000
_SWITCHING = (sympy.Max, sympy.Min, sympy.Abs, sympy.Heaviside, sympy.sign, sympy.Piecewise)
#: math-module stand-ins for functions lambdify's math printer does not know
_MODULES = [{"Heaviside": lambda x, h=0.5: 1.0 if x > 0 else (0.0 if x < 0 else h),
             "sign": lambda x: float((x > 0) - (x < 0))}, "math"]


# --------------------------------------------------------------------------- #
# the scalar law f(u): breakpoints and analytic pieces
# --------------------------------------------------------------------------- #
def _switch_arguments(atom: sympy.Basic) -> list[sympy.Expr]:
    if isinstance(atom, (sympy.Max, sympy.Min)):
        args = atom.args
        return [a - b for i, a in enumerate(args) for b in args[i + 1:]]
    if isinstance(atom, sympy.Piecewise):
        out = []
        for _, condition in atom.args:
            if condition in (sympy.true, sympy.false):
                continue
            if not isinstance(condition, sympy.core.relational.Relational):
                raise UnsupportedNonlinearityError(
                    f"the Piecewise condition {condition} is not one comparison; write one comparison per piece")
            out.append(condition.lhs - condition.rhs)
        return out
    return [atom.args[0]]


def _choose(atom: sympy.Basic, u: sympy.Symbol, point: float) -> sympy.Expr:
    """The branch of the switching ``atom`` that holds at ``u = point`` (an interior point of an interval)."""
    def value(expr: sympy.Expr) -> float:
        return float(sympy.N(expr.subs(u, point), 30))

    if isinstance(atom, (sympy.Max, sympy.Min)):
        values = [value(a) for a in atom.args]
        pick = max if isinstance(atom, sympy.Max) else min
        return atom.args[values.index(pick(values))]
    if isinstance(atom, sympy.Abs):
        return atom.args[0] if value(atom.args[0]) > 0 else -atom.args[0]
    if isinstance(atom, sympy.Heaviside):
        return sympy.S.One if value(atom.args[0]) > 0 else sympy.S.Zero
    if isinstance(atom, sympy.sign):
        return sympy.S.One if value(atom.args[0]) > 0 else -sympy.S.One
    for expr, condition in atom.args:  # Piecewise
        if condition is sympy.true or bool(condition.subs(u, point)):
            return expr
    raise UnsupportedNonlinearityError(f"{atom} is undefined at u = {point:g}; add a last piece (..., True)")


class _ScalarLaw:
    """f(u) with its breakpoints ``β_1 < … < β_m`` and on each interval the analytic piece and its derivative."""

    def __init__(self, f: sympy.Expr, u: sympy.Symbol) -> None:
        atoms = [a for a in sympy.preorder_traversal(f) if isinstance(a, _SWITCHING)]
        points: set[float] = set()
        for atom in atoms:
            for argument in _switch_arguments(atom):
                if argument.has(*_SWITCHING):
                    raise UnsupportedNonlinearityError(f"f = {f}: nested switching functions are not supported")
                if not argument.has(u):
                    continue
                try:
                    roots = sympy.solve(argument, u)
                except NotImplementedError:
                    raise UnsupportedNonlinearityError(f"f = {f}: cannot find where {argument} changes sign") from None
                for root in roots:
                    number = complex(sympy.N(root, 30))
                    if abs(number.imag) <= 1e-14 * (1 + abs(number.real)):
                        points.add(float(number.real))
        self.breakpoints = sorted(points)
        edges = [-math.inf, *self.breakpoints, math.inf]
        self.pieces: list[tuple[Callable[[float], float], Callable[[float], float], float]] = []
        #: per interval (slope, intercept) when the piece is affine in u (its force is then a matrix product)
        self.linear: list[tuple[float, float] | None] = []
        full = sympy.lambdify(u, f, modules=_MODULES)
        for lower, upper in zip(edges[:-1], edges[1:]):
            point = (lower + upper) / 2 if math.isfinite(lower) and math.isfinite(upper) else (
                0.0 if not self.breakpoints else (upper - 1.0 if math.isinf(lower) else lower + 1.0))
            piece = f.replace(lambda e: isinstance(e, _SWITCHING), lambda e, p=point: _choose(e, u, p)) if atoms else f
            value = sympy.lambdify(u, piece, modules=_MODULES)
            slope = sympy.lambdify(u, sympy.diff(piece, u), modules=_MODULES)
            self.pieces.append((_real(value, full), _real(slope, None), point))
            polynomial = sympy.Poly(piece, u) if piece.is_polynomial(u) else None
            self.linear.append((float(polynomial.coeff_monomial(u)), float(polynomial.coeff_monomial(1)))
                               if polynomial is not None and polynomial.degree() <= 1 else None)

    def jumps_at(self, index: int) -> bool:
        """Whether f jumps at breakpoint ``index`` (its two pieces differ there: a Heaviside, a sign)."""
        point = self.breakpoints[index]
        left, right = self.pieces[index][0](point), self.pieces[index + 1][0](point)
        return not abs(left - right) <= 1e-12 * (1.0 + abs(left) + abs(right))

    def region(self, u: float, v: float) -> int:
        """Index of the interval holding u (on a breakpoint: the one v moves into)."""
        index = int(np.searchsorted(self.breakpoints, u, side="right"))
        if index > 0 and u == self.breakpoints[index - 1] and v < 0:
            index -= 1
        return index


class _Elements:
    """The nonlinear force ``ε Σ_i w_i f_i(a_iᵀ X − b_i)`` of N degrees of freedom, premultiplied by M⁻¹.

    Element i has its law ``f_i`` (a :class:`_ScalarLaw`: breakpoints, analytic pieces), the row ``a_i`` of
    ``A``, the offset ``b_i`` and the column ``M⁻¹ w_i`` of ``MW``.  A region of the state space is the tuple of
    the intervals of the laws that hold ``u_i = a_iᵀ X − b_i``; there the force is analytic, and the events that
    leave it are the breakpoints adjacent to each ``u_i``.  One oscillator is N = 1 with the one element
    ``(f, a = 1, b = 0, w = 1)``; a unilateral system has the elements ``((·)_+, A_i, b_i, W_i)``.
    """

    def __init__(self, laws: list[_ScalarLaw], A: np.ndarray, b: np.ndarray, MW: np.ndarray) -> None:
        self.laws, self.A, self.b, self.MW = laws, A, b, MW

    def region(self, x: np.ndarray, v: np.ndarray) -> tuple[int, ...]:
        """The interval of every law at (X, X') (on a breakpoint: the one the motion moves into)."""
        gaps, rates = self.A @ x - self.b, self.A @ v
        return tuple(law.region(float(g), float(r)) for law, g, r in zip(self.laws, gaps, rates))

    def affine(self, region: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray] | None:
        """``(Σ_i s_i M⁻¹w_i a_iᵀ, M⁻¹ Σ_i w_i (s_i b_i − c_i))`` where every piece is ``s_i u + c_i``, else None:
        the force is then ``ε (first X − second)`` without a call of the laws."""
        lines = [law.linear[r] for law, r in zip(self.laws, region)]
        if any(line is None for line in lines):
            return None
        slopes = np.array([line[0] for line in lines])
        intercepts = np.array([line[1] for line in lines])
        return (self.MW * slopes) @ self.A, self.MW @ (slopes * self.b - intercepts)

    def events(self, region: tuple[int, ...], n: int) -> list[tuple[Callable, tuple[int, ...]]]:
        """Terminal directional events leaving ``region`` through a breakpoint of one law, with the region entered."""
        events: list[tuple[Callable, tuple[int, ...]]] = []
        for i, (law, r) in enumerate(zip(self.laws, region)):
            row, offset = self.A[i], self.b[i]
            for neighbour, point, direction in ((r - 1, r - 1, -1), (r + 1, r, +1)):
                if 0 <= point < len(law.breakpoints) and 0 <= neighbour <= len(law.breakpoints):
                    entered = region[:i] + (neighbour,) + region[i + 1:]
                    level = offset + law.breakpoints[point]
                    events.append((_event(lambda t, y, row=row, level=level: float(row @ y[:n]) - level, direction),
                                   entered))
        return events


class _Metered:
    """Counts the right-hand-side evaluations of one run: a checkpoint of :mod:`lindstedt.limits` every
    :data:`_CHECKPOINT_EVERY`, a :class:`ConvergenceError` past ``limit`` (a stiff or diverging motion)."""

    def __init__(self, limit: int) -> None:
        self.count, self.limit = 0, limit

    def wrap(self, field: Callable[[float, np.ndarray], np.ndarray]) -> Callable[[float, np.ndarray], np.ndarray]:
        def metered(time: float, y: np.ndarray) -> np.ndarray:
            self.count += 1
            if self.count % _CHECKPOINT_EVERY == 0:
                checkpoint("DOP853 evaluation", self.count)
                if self.count > self.limit:
                    raise ConvergenceError(
                        f"DOP853 needed more than {self.limit} evaluations at t = {time:.6g} "
                        f"({_MAX_EVALUATIONS_PER_NATURAL_PERIOD} per natural period spanned): the motion is stiff or "
                        "diverging (e.g. a steep law driven far past its breakpoint)")
            return field(time, y)

        return metered


def _real(function: Callable[[float], Any], fallback: Callable[[float], Any] | None) -> Callable[[float], float]:
    """``function`` as a real-valued float function; outside its interval (a fractional power of a negative
    distance, met by a Runge–Kutta stage beyond the breakpoint) the whole law (or 0 for a derivative)."""
    def call(u: float) -> float:
        u = float(u)
        try:
            value = function(u)
        except (ValueError, ZeroDivisionError):
            value = complex("nan")
        except OverflowError:  # the state left the float range: the flow fails (a failed orbit, not a crash)
            raise ConvergenceError(f"f(u) overflows a float at u = {u:.3g}: the motion diverges (or the problem needs "
                                   "rescaling)") from None
        if isinstance(value, complex) or not math.isfinite(value):
            return float(fallback(u)) if fallback is not None else 0.0
        return float(value)

    return call


# --------------------------------------------------------------------------- #
# the flow
# --------------------------------------------------------------------------- #
class SmoothForcedFlow:
    """DOP853 period map (with monodromy, ∂/∂Ω, ∂/∂s) of a forced oscillator or forced unilateral system.

    Parameters
    ----------
    problem : ForcedOscillator or ForcedSystem
        With numeric coefficients (ω0, ζ, F and the parameters of f).
    epsilon : float
        The small parameter ε (any finite real).
    rtol, atol : float
        Tolerances of ``solve_ivp`` for the state and the sensitivities.

    Attributes
    ----------
    dimension : int
        2N.
    n_dof : int
        N.
    breakpoints : tuple of float
        The kinks of f (one degree of freedom); empty for a system (its switches are the gaps).
    steps, evaluations : int
        Accepted DOP853 steps and right-hand-side evaluations of every call so far.

    Examples
    --------
    The linear oscillator ``u'' + 0.1 u' + u + ε u = ε cos(Ω t)`` has the monodromy ``exp(A T)``:

    >>> import scipy.linalg
    >>> from lindstedt.problems.forced import ForcedOscillator
    >>> flow = SmoothForcedFlow(ForcedOscillator("u", omega0=1, zeta="1/20"), 0.5)
    >>> value = flow.period_map([0.1, 0.0], 2.0)
    >>> A = [[0, 1], [-1.5, -0.1]]
    >>> bool(np.allclose(value.d_state, scipy.linalg.expm(np.array(A) * np.pi), atol=1e-11))
    True
    >>> SmoothForcedFlow(ForcedOscillator("Max(0, u - b)", omega0=1, params={"b": "1/5"}), 1.0).breakpoints
    (0.2,)
    """

    @locked  # the problem's sympy numbers to floats, f lambdified
    def __init__(self, problem: ForcedOscillator | ForcedSystem, epsilon: float, *, rtol: float = 1e-12,
                 atol: float = 1e-14) -> None:
        eps = real_argument(epsilon, "epsilon")
        if not (isinstance(rtol, (int, float)) and isinstance(atol, (int, float)) and rtol > 0 and atol > 0):
            raise ProblemError(f"rtol and atol must be positive numbers, got rtol={rtol!r}, atol={atol!r}")
        self.problem, self.epsilon, self.rtol, self.atol = problem, eps, float(rtol), float(atol)
        self.steps = 0
        self.evaluations = 0
        self._build()

    def _build(self) -> None:
        problem = self.problem
        if isinstance(problem, ForcedOscillator):
            omega0, zeta, forcing = problem.numeric_coefficients()
            self.n_dof = 1
            law = _ScalarLaw(problem.nonlinearity, problem.oscillator.variable)
            self._elements = _Elements([law], np.ones((1, 1)), np.zeros(1), np.ones((1, 1)))
            self._Km, self._Cm, self._Pm = np.array([[omega0 * omega0]]), np.array([[2.0 * zeta * omega0]]), \
                np.array([forcing])
            self.breakpoints = tuple(law.breakpoints)
            slopes = [float(slope(point)) for _, slope, point in law.pieces]
        elif isinstance(problem, (ForcedSystem, UnilateralSystem)):
            system = problem.system if isinstance(problem, ForcedSystem) else problem
            self.n_dof = system.n_dof
            M_inv = np.linalg.inv(system.M)
            self._Km = M_inv @ system.K
            if isinstance(problem, ForcedSystem):
                self._Cm, self._Pm = M_inv @ problem.C, M_inv @ problem.P
            else:  # free: no damping, no load (the flow of the NNMs)
                self._Cm, self._Pm = np.zeros((self.n_dof, self.n_dof)), np.zeros(self.n_dof)
            A = np.array(system.A, dtype=float).reshape(-1, self.n_dof)
            laws = {law: _ScalarLaw(law, LAW_VARIABLE) for law in set(system.laws)}  # lambdified once per distinct law
            elements = [laws[law] for law in system.laws]
            self._elements = _Elements(elements, A, np.array(system.b, dtype=float).reshape(-1),
                                       M_inv @ np.array(system.W, dtype=float).reshape(self.n_dof, -1))
            self.breakpoints = ()
            slopes = [max(abs(float(slope(point))) for _, slope, point in law.pieces) for law in elements]
        else:
            raise ProblemError(
                f"problem must be a ForcedOscillator, a ForcedSystem (lindstedt.problems.forced) or a free UnilateralSystem, "
                f"got {type(problem).__name__}")
        # one oscillator runs a scalar kernel of the same field: 2-4x fewer Python operations per step (measured
        # against the N-dof kernel at N = 1), the form of every benchmark of one degree of freedom
        self._scalar = self.n_dof == 1 and len(self._elements.laws) == 1 and isinstance(problem, ForcedOscillator)
        self.dimension = 2 * self.n_dof
        self._bounds = linear_frequency_bounds(problem, self.epsilon, slopes)
        self._frequencies = self._bounds or (1.0, 1.0)
        self._load_size = float(np.max(np.abs(self._Pm))) if self._Pm.size else 0.0

    def linear_frequencies(self) -> tuple[float, float] | None:
        """(lowest, highest) frequency of the linear pieces (ω² of each piece: ω0² + ε·slope, or M⁻¹(K + ε W A))."""
        return self._bounds

    def _absolute_tolerances(self, z: np.ndarray, frequency: float, scale: float, sensitivity: bool) -> np.ndarray:
        """``atol`` per component: ``min(atol, rtol·size)`` with the size of the displacements
        ``D = max(|X0|, |X0'|/W, ε|s F|/max(Ω², ω_min²))`` and of the velocities ``D·W``, ``W = max(Ω, ω_max)``, so a
        tiny response (far above resonance, ~εF/Ω²) is integrated to ``rtol`` and not to a fixed ``atol`` larger
        than itself (the sensitivities keep ``atol``)."""
        n = self.n_dof
        low, high = self._frequencies
        rate = max(frequency, high)
        size = max(float(np.max(np.abs(z[:n]))), float(np.max(np.abs(z[n:]))) / rate,
                   abs(self.epsilon * scale) * self._load_size / max(frequency, low) ** 2, 1e-300)
        tolerances = np.full(self.dimension * (self.dimension + 3) if sensitivity else self.dimension, self.atol)
        tolerances[:n] = min(self.atol, self.rtol * size)
        tolerances[n:2 * n] = min(self.atol, self.rtol * size * rate)
        return tolerances

    def __getstate__(self) -> dict[str, Any]:  # picklable for process pools: the lambdified law is rebuilt
        return {key: value for key, value in self.__dict__.items() if key in ("problem", "epsilon", "rtol", "atol",
                                                                                 "steps", "evaluations")}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._build()

    def __repr__(self) -> str:
        return f"SmoothForcedFlow({type(self.problem).__name__}, epsilon={self.epsilon:g}, rtol={self.rtol:g})"

    # ------------------------------------------------------------------ regions and vector fields
    def _region(self, z: np.ndarray) -> tuple[int, ...]:
        n = self.n_dof
        return self._elements.region(z[:n], z[n:])

    def _fields(self, region: tuple[int, ...], frequency: float, scale: float, sensitivity: bool,
                epsilon_column: bool = False) -> Callable:
        """The right-hand side of (z, Y) on one region (Y the 2N × (2N + 2) sensitivity block: ∂z/∂z0, ∂z/∂Ω and
        ∂z/∂s, or with ``epsilon_column`` ∂z/∂ε in place of ∂z/∂s — its forcing ``s P cos(Ω t) − M⁻¹ Σ_i w_i f_i``)."""
        eps, n = self.epsilon, self.n_dof
        if self._scalar:
            value, slope, _ = self._elements.laws[0].pieces[region[0]]
            k, c, load = float(self._Km[0, 0]), float(self._Cm[0, 0]), eps * scale * float(self._Pm[0])
            amplitude = eps * float(self._Pm[0])

            def scalar(t: float, y: np.ndarray) -> np.ndarray:
                u, v = y[0], y[1]
                phase = frequency * t
                cosine = math.cos(phase)
                a = load * cosine - k * u - c * v - eps * value(u)
                if not sensitivity:
                    return np.array((v, a))
                stiff = k + eps * slope(u)
                out = np.empty(10)
                out[0], out[1] = v, a
                Y = y[2:]
                # Y laid out row-major: rows (u, v), 4 columns (z0_u, z0_v, Ω, s)
                out[2:6] = Y[4:8]
                out[6:10] = -stiff * Y[0:4] - c * Y[4:8]
                out[8] -= load * t * math.sin(phase)
                out[9] += amplitude * cosine
                return out

            return scalar
        Cm, Pm, width = self._Cm, self._Pm, 2 * n + 2
        elements = self._elements
        affine = elements.affine(region)
        if affine is not None:  # every piece affine (unilateral springs): one matrix for the whole region
            Km, offset = self._Km + eps * affine[0], eps * affine[1]

            def restoring(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
                return Km @ x - offset, Km, None

            def nonlinear(x: np.ndarray) -> np.ndarray:  # only for the ∂/∂ε column
                return affine[0] @ x - affine[1]
        else:  # the laws' analytic pieces: M⁻¹(K X + ε Σ_i w_i f_i(u_i)) and its Jacobian K + ε Σ_i w_i f_i'(u_i) a_iᵀ
            pieces = [law.pieces[r] for law, r in zip(elements.laws, region)]
            A, b, MW, K = elements.A, elements.b, elements.MW, self._Km

            def restoring(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
                """(M⁻¹ × the restoring force, its Jacobian, M⁻¹ Σ_i w_i f_i — the laws evaluated once)."""
                u = A @ x - b
                forces = MW @ np.array([value(ui) for (value, _, _), ui in zip(pieces, u)])
                slopes = np.array([slope(ui) for (_, slope, _), ui in zip(pieces, u)])
                return K @ x + eps * forces, K + eps * (MW * slopes) @ A, forces

            nonlinear = None

        def system(t: float, y: np.ndarray) -> np.ndarray:
            x, v = y[:n], y[n:2 * n]
            phase = frequency * t
            force, tangent, laws = restoring(x)
            a = eps * scale * math.cos(phase) * Pm - force - Cm @ v
            if not sensitivity:
                return np.concatenate((v, a))
            Y = y[2 * n:].reshape(2 * n, width)
            dY = np.empty_like(Y)
            dY[:n] = Y[n:]
            dY[n:] = -tangent @ Y[:n] - Cm @ Y[n:]
            dY[n:, 2 * n] -= eps * scale * t * math.sin(phase) * Pm
            if epsilon_column:
                dY[n:, 2 * n + 1] += scale * math.cos(phase) * Pm - (laws if laws is not None else nonlinear(x))
            else:
                dY[n:, 2 * n + 1] += eps * math.cos(phase) * Pm
            return np.concatenate((v, a, dY.reshape(-1)))

        return system

    def _events(self, region: tuple[int, ...]) -> list[tuple[Callable, tuple[int, ...]]]:
        """Terminal directional events leaving ``region``, each with the region entered."""
        return self._elements.events(region, self.n_dof)

    def _acceleration(self, region: Any, t: float, z: np.ndarray, frequency: float, scale: float) -> np.ndarray:
        return self._fields(region, frequency, scale, False)(t, z)[self.n_dof:]

    def _saltation(self, old: Any, new: Any, t: float, z: np.ndarray, frequency: float, scale: float,
                   event_index: int) -> np.ndarray | None:
        """``S = I + Δ nᵀ/(nᵀ F⁻)`` where the field jumps across the switch (None where it is continuous)."""
        n = self.n_dof
        jump = self._acceleration(new, t, z, frequency, scale) - self._acceleration(old, t, z, frequency, scale)
        if np.max(np.abs(jump)) <= 1e-15 * (1.0 + np.max(np.abs(z))):
            return None
        normal = np.zeros(2 * n)
        element = [i for i, (a, b) in enumerate(zip(old, new)) if a != b][0]
        normal[:n] = self._elements.A[element]
        rate = float(normal[:n] @ z[n:])
        if rate == 0.0:
            return None  # grazing: the saltation is singular; the crossing is tangential
        S = np.eye(2 * n)
        S[n:, :] += np.outer(jump, normal) / rate
        return S

    # ------------------------------------------------------------------ integration
    def _state(self, state0: Any) -> np.ndarray:
        z = np.array(state0, dtype=float).reshape(-1)
        if z.shape != (self.dimension,) or not np.all(np.isfinite(z)):
            raise ProblemError(f"state0 must be {self.dimension} finite numbers (X, X'), got {state0!r}")
        return z

    def _forcing(self, frequency: float, periods: int, forcing_scale: float) -> tuple[float, float, float]:
        """(Ω, s, kT) of a period map, checked."""
        frequency = check_forcing_frequency(frequency, "frequency")
        if isinstance(periods, bool) or not isinstance(periods, (int, np.integer)) or periods < 1:
            raise ProblemError(f"periods must be a positive integer, got {periods!r}")
        scale = float(forcing_scale)
        if not math.isfinite(scale):
            raise ProblemError(f"forcing_scale must be finite, got {forcing_scale!r}")
        return frequency, scale, 2.0 * math.pi * int(periods) / frequency

    def _integrate(self, z: np.ndarray, end: float, frequency: float, scale: float, sensitivity: bool,
                   times: np.ndarray | None = None, epsilon_column: bool = False
                   ) -> tuple[np.ndarray, np.ndarray | None, dict[str, int], Any]:
        """z(end) from z(0) = z (checked), its sensitivity block Y(end), the counters and (the final region, the
        samples at ``times`` in [0, end), the elements whose breakpoints were crossed)."""
        from scipy.integrate import solve_ivp  # here, not at module level: import lindstedt stays light

        n2 = self.dimension
        Y = np.hstack([np.eye(n2), np.zeros((n2, 2))]) if sensitivity else None
        region = self._region(z)
        t, counters = 0.0, {"steps": 0, "evaluations": 0, "arcs": 0, "switches": 0}
        stalled = 0
        samples: list[np.ndarray] = []
        crossed: set[int] = set()
        atol = self._absolute_tolerances(z, frequency, scale, sensitivity)
        natural = max(1.0, end * self._frequencies[1] / (2.0 * math.pi), end * frequency / (2.0 * math.pi))
        evaluations = _Metered(int(_MAX_EVALUATIONS_PER_NATURAL_PERIOD * natural))
        while True:
            rhs = evaluations.wrap(self._fields(region, frequency, scale, sensitivity, epsilon_column))
            events = self._events(region)
            y0 = np.concatenate((z, Y.reshape(-1))) if sensitivity else z
            window = None if times is None else times[(times >= t) & (times < end)]
            solution = solve_ivp(rhs, (t, end), y0, method="DOP853", rtol=self.rtol, atol=atol,
                                 events=[e for e, _ in events] or None, dense_output=times is not None)
            counters["arcs"] += 1
            counters["steps"] += len(solution.t) - 1
            counters["evaluations"] += int(solution.nfev)
            if solution.status == -1:
                raise ConvergenceError(f"DOP853 failed at t = {t:g}: {solution.message}")
            hit = [(float(te[0]), k) for k, te in enumerate(solution.t_events or []) if len(te)]
            if hit and min(hit)[0] <= t:
                stalled += 1
                if stalled > _MAX_INSTANT_SWITCHES:
                    raise ConvergenceError(
                        f"the motion sticks on a breakpoint at t = {t:g} ({stalled} switches without time advancing: "
                        "a sliding motion, which this flow does not follow)"
                    )
            else:
                stalled = 0
            t_next = min(hit)[0] if hit else end
            if window is not None and window.size:
                inside = window[window < t_next] if hit else window
                if inside.size:
                    samples.append(solution.sol(inside)[:n2].T)
            if not hit:
                y = solution.y[:, -1]
                z = y[:n2]
                Y = y[n2:].reshape(n2, n2 + 2) if sensitivity else None
                break
            t, k = min(hit)
            y = solution.y_events[k][0]
            z = y[:n2].copy()
            Y = y[n2:].reshape(n2, n2 + 2).copy() if sensitivity else None
            old, region = region, events[k][1]
            counters["switches"] += 1
            crossed.update(i for i, (a, b) in enumerate(zip(old, region)) if a != b)
            if self._scalar:
                z[0] = self._elements.laws[0].breakpoints[min(old[0], region[0])]  # exactly on the breakpoint
            if sensitivity:
                S = self._saltation(old, region, t, z, frequency, scale, k)
                if S is not None:
                    Y = S @ Y
        self.steps += counters["steps"]
        self.evaluations += counters["evaluations"]
        sampled = np.vstack(samples) if samples else np.empty((0, n2))
        return z, Y, counters, (region, sampled, tuple(sorted(crossed)))

    def period_map(self, state0: Any, frequency: float, *, periods: int = 1, forcing_scale: float = 1.0,
                   sensitivity: bool = True) -> PeriodMapValue:
        """``Π(z0; Ω, s) = z(2πk/Ω)`` and, when ``sensitivity``, ``∂Π/∂z0``, ``∂Π/∂Ω`` and ``∂Π/∂s``.

        Examples
        --------
        >>> from lindstedt.problems.forced import ForcedOscillator
        >>> flow = SmoothForcedFlow(ForcedOscillator("u**3", omega0=1, zeta="1/20"), 0.5)
        >>> value = flow.period_map([0.2, 0.0], 1.1, periods=2)
        >>> sorted(value.counters), value.counters["switches"]
        (['arcs', 'evaluations', 'steps', 'switches'], 0)
        """
        frequency, scale, end = self._forcing(frequency, periods, forcing_scale)
        z, Y, counters, (region, _, _) = self._integrate(self._state(state0), end, frequency, scale, sensitivity)
        if not sensitivity:
            return PeriodMapValue(z, counters=counters)
        n2 = self.dimension
        moving_end = self._fields(region, frequency, scale, False)(end, z) * (-end / frequency)  # kT = 2πk/Ω
        return PeriodMapValue(z, Y[:, :n2].copy(), Y[:, n2] + moving_end, Y[:, n2 + 1].copy(), counters)

    def sample(self, state0: Any, frequency: float, *, periods: int = 1, forcing_scale: float = 1.0,
               samples: int = 256) -> tuple[np.ndarray, np.ndarray]:
        """``(t, z(t))`` at ``samples`` equally spaced times of ``[0, kT)`` (dense output of each arc).

        Examples
        --------
        >>> from lindstedt.problems.forced import ForcedOscillator
        >>> flow = SmoothForcedFlow(ForcedOscillator("Max(0, u)", omega0=1), 3.0)
        >>> t, z = flow.sample([1.0, 0.0], 1.0, samples=8)
        >>> t.shape, z.shape, float(z[0, 0])
        ((8,), (8, 2), 1.0)
        """
        if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
            raise ProblemError(f"samples must be a positive integer, got {samples!r}")
        frequency, scale, end = self._forcing(frequency, periods, forcing_scale)
        times = np.arange(int(samples)) * (end / int(samples))
        _, _, _, (_, sampled, _) = self._integrate(self._state(state0), end, frequency, scale, False, times)
        return times, sampled

    def run(self, state0: Any, t: float, times: Any) -> tuple[PeriodMapValue, np.ndarray, tuple[int, ...]]:
        """:meth:`advance` with ``∂z(t)/∂z0`` and, in the same integration, the states at ``times`` (ascending, in
        ``[0, t)``; shape (len(times), 2N)) and the elements whose breakpoints the motion crossed: what the
        verification of a periodic orbit reads from one run over its period.

        Examples
        --------
        >>> from lindstedt import UnilateralSystem
        >>> flow = SmoothForcedFlow(UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], laws=["Max(0, u)"]), 3.0)
        >>> value, states, crossed = flow.run([1.0, 0.0], 3 * np.pi / 2, [0.0, np.pi / 4])   # the bilinear orbit
        >>> bool(np.allclose(value.state, [1.0, 0.0], atol=1e-10)), states.shape, crossed
        (True, (2, 2), (0,))
        """
        if not isinstance(self.problem, UnilateralSystem):
            raise ProblemError("run is the free flow of a UnilateralSystem; a forced problem has period_map")
        end = real_argument(t, "t")
        grid = np.asarray(times, dtype=float).reshape(-1)
        if not (end >= 0 and np.all(np.diff(grid) > 0) and np.all((grid >= 0) & (grid < end))):
            raise ProblemError(f"run needs t ≥ 0 and ascending times in [0, t), got t = {t!r}, times = {times!r}")
        z, Y, counters, (_, sampled, crossed) = self._integrate(self._state(state0), end, self._frequencies[0], 0.0,
                                                                True, grid, epsilon_column=True)
        return PeriodMapValue(z, Y[:, :self.dimension].copy(), counters=counters), sampled, crossed

    def steepest_slopes(self, lower: Any, upper: Any) -> np.ndarray:
        """``max |f_i'(u)|`` of every element's law over ``u ∈ [lower_i, upper_i]`` (the analytic pieces' slopes on
        a 129-point grid and at both sides of every breakpoint inside): the local stiffness of a motion whose
        element deformations stay in those ranges.  A law that jumps in its range has none: ``inf``.

        Examples
        --------
        >>> from lindstedt import UnilateralSystem
        >>> flow = SmoothForcedFlow(UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], laws=["u**3"]), 1.0)
        >>> flow.steepest_slopes([-1.0], [2.0]).tolist()       # 3 u² at u = 2
        [12.0]
        """
        out = []
        for law, low, high in zip(self._elements.laws, np.atleast_1d(lower), np.atleast_1d(upper)):
            low, high = float(low), float(high)
            inside = [p for p in law.breakpoints if low <= p <= high]
            if any(law.jumps_at(k) for k, p in enumerate(law.breakpoints) if low <= p <= high):
                out.append(math.inf)
                continue
            width = max(high - low, 0.0)
            points = np.unique(np.r_[np.linspace(low, high, 129), [p - 1e-9 * (1 + width) for p in inside],
                                     [p + 1e-9 * (1 + width) for p in inside]])
            steepest = 0.0
            for u in points:
                _, slope, _ = law.pieces[law.region(float(u), 0.0)]
                steepest = max(steepest, abs(slope(float(u))))
            out.append(steepest)
        return np.array(out)

    def static_equilibrium(self) -> np.ndarray:
        """The rest state ``X*`` of the free system, ``K X* + ε Σ_i w_i f_i(a_iᵀ X* − b_i) = 0``, nearest to X = 0.

        X = 0 when every element's force vanishes there; else the core's damped Newton from X = 0 on the elements'
        analytic pieces, to rounding (a :class:`ConvergenceError` where it finds none — e.g. a jump of a law at the
        equilibrium).

        Examples
        --------
        A prestressed cubic spring, ``x + ε (x − 1)³ = 0`` at ε = 1: ``x*`` is the real root of ``x³ − 3x² + 4x − 1``:

        >>> from lindstedt import UnilateralSystem
        >>> flow = SmoothForcedFlow(UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], b=[1], laws=["u**3"]), 1.0)
        >>> x = float(flow.static_equilibrium()[0])
        >>> abs(x**3 - 3 * x**2 + 4 * x - 1) < 1e-15
        True
        """
        from .newton import Evaluation, newton  # the core Newton (numerics.newton imports nothing of this module)

        n, eps, elements = self.n_dof, self.epsilon, self._elements
        zero = np.zeros(n)

        def pieces(x: np.ndarray) -> list[tuple[Callable, Callable, float]]:
            return [law.pieces[r] for law, r in zip(elements.laws, elements.region(x, zero))]

        def forces(x: np.ndarray) -> np.ndarray:
            return np.array([value(u) for (value, _, _), u in zip(pieces(x), elements.A @ x - elements.b)])

        if eps == 0.0 or not np.any(forces(zero)):
            return zero
        size = max(1.0, float(np.max(np.abs(elements.b))))
        row_scale = float(np.linalg.norm(self._Km, 2)) * size

        def evaluate(x: np.ndarray) -> Evaluation:
            u = elements.A @ x - elements.b
            chosen = pieces(x)
            residual = self._Km @ x + eps * (elements.MW @ np.array([value(ui) for (value, _, _), ui in zip(chosen, u)]))
            slopes = np.array([slope(ui) for (_, slope, _), ui in zip(chosen, u)])
            jacobian = self._Km + eps * (elements.MW * slopes) @ elements.A
            return Evaluation(True, "", residual / row_scale, jacobian / row_scale,
                              singular="a singular tangent stiffness K + ε Σ w_i f_i' a_iᵀ at the iterate")

        outcome = newton(evaluate, zero, np.full(n, size), tol=1e-14, max_iterations=60, step_tol=1e-15)
        if not outcome.success:
            raise ConvergenceError(f"no static equilibrium near X = 0 at ε = {eps:g}: {outcome.message}")
        return outcome.unknowns

    def advance(self, state0: Any, t: float, *, sensitivity: bool = True, d_epsilon: bool = False) -> PeriodMapValue:
        """The free flow ``z(t)`` of a :class:`~lindstedt.UnilateralSystem` (no load, no damping) from ``z(0) = z0``:
        ``∂z(t)/∂z0`` with ``sensitivity``, ``∂z(t)/∂ε`` with ``d_epsilon`` (the variational equation forced by
        ``−M⁻¹ Σ_i w_i f_i(a_iᵀ X − b_i)``, through the saltation matrices where a law jumps).

        The autonomous form of :meth:`period_map`, as :meth:`lindstedt.numerics.ExactFlow.advance`: the shooting
        of NNMs of systems with any law flows through it.

        Examples
        --------
        ``u'' + u + ε u³ = 0`` at ε = 0 from (1, 0): ``u = cos t``, and ``∂u/∂ε = (cos 3t − cos t)/32 − (3/8) t sin t``:

        >>> from lindstedt import UnilateralSystem
        >>> flow = SmoothForcedFlow(UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], laws=["u**3"]), 0.0)
        >>> value = flow.advance([1.0, 0.0], np.pi / 2, d_epsilon=True)
        >>> round(float(value.state[0]), 12) + 0.0, round(float(value.d_epsilon[0]), 10) == round(-3 * np.pi / 16, 10)
        (0.0, True)
        """
        if not isinstance(self.problem, UnilateralSystem):
            raise ProblemError("advance is the free flow of a UnilateralSystem; a forced problem has period_map")
        end = real_argument(t, "t")
        if not end >= 0:
            raise ProblemError(f"t must be a non-negative time, got {t!r}")
        z, Y, counters, _ = self._integrate(self._state(state0), end, self._frequencies[0], 0.0,
                                            bool(sensitivity or d_epsilon), epsilon_column=True)
        n2 = self.dimension
        return PeriodMapValue(z, Y[:, :n2].copy() if sensitivity else None, counters=counters,
                              d_epsilon=Y[:, n2 + 1].copy() if d_epsilon else None)


def _event(function: Callable[[float, np.ndarray], float], direction: int) -> Callable[[float, np.ndarray], float]:
    function.terminal = True  # type: ignore[attr-defined]
    function.direction = direction  # type: ignore[attr-defined]
    return function
