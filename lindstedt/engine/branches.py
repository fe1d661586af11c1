"""The branch hierarchy: strained coordinates for piecewise-linear systems with moving contact boundaries.

One engine for every piecewise-linear case — the 1-dof unilateral spring is its
N = 1 instance, the NNM of an N-dof system with unilateral springs the general
one.  In normalised variables (strained time ``s = ω t``, ``Ω = ω/λ``,
``ε̂ = ε/λ²``, ``W = U/a0``) the problem is

    Ω² W'' + R² W + ε̂ (L_p W + m_p) = 0,   W_0 = e_j cos s,   R = diag(r_k), r_j = 1,

where the contact state p — and with it the stiffness ``L_p`` and the load
``m_p`` — changes where a contact function ``Σ_k c_ik W_k(s) − κ_i`` changes
sign.  At ε = 0 that happens at the contact angle ``β_i = arccos κ_i`` (a
simple root); for ε > 0 at ``s_i*(ε) = β_i + Σ_n σ_{i,n} ε̂^n``.

On the piece p of [0, π] between consecutive crossings the equations are linear
with constant coefficients, so every correction is an analytic quasi-
trigonometric branch (:mod:`lindstedt.algebra.branch`), continued past the
piece's ends.  With ``Ω² = Σ A_n ε̂^n`` order n reads, component by component,

    W_{n,k}'' + r_k² W_{n,k} = A_n δ_kj cos s − Σ_{i<n} A_i W_{n−i,k}'' − (L_p W_{n−1})_k − δ_{n1} (m_p)_k
                                − Σ_e g_{e,k} Σ_m c_{e,m} [(c_e · W)^m]_{n−1}      (polynomial element laws)

(``[y^m]_n`` is the ε̂ⁿ coefficient of (Σ ε̂^i y_i)^m for an element's deformation ``y = c_e · W``
(the 1-dof law acts on W itself, N-dof elements on a projection of the modal coordinates):
products of branches of lower orders on the same piece, still quasi-trigonometric, so a
polynomial law on a piece keeps every branch analytic and continued past the piece's ends).

Unknowns of order n: ``A_n``, the homogeneous parts ``c cos(r_k s) + d sin(r_k s)``
of every component on every piece, and the boundary shifts ``σ_{i,n}``.
Conditions: ``W_k'(0) = 0`` and ``W_k'(π) = 0`` (even, 2π-periodic); C¹
matching of every component at every moving boundary and the contact condition
``Σ_k c_ik W_k(s_i*) = κ_i`` — Taylor-expanded about β_i, so values and
integrals with moving limits are closed forms; and one normalisation of the
mode component: ``W_{n,j}(0) = w_n`` ("initial", the release series) or zero
first harmonic of the exact ``W_j`` including the moving-boundary terms
("harmonic").  ``W_j'(π) = 0`` is the secular (Fredholm) condition that fixes
``A_n``; for k ≠ j it fixes the periodic solution, which exists iff r_k ∉ ℤ.

A fractional power law (Hertz contact, p = 3/2) or an analytic law on a piece that holds a turning
point makes that piece's solution non-analytic at its moving end; the piece is then a
:class:`~lindstedt.engine.stretched.VectorArc` (the one arc implementation, any N), solved on a fixed
interval (``BranchSystem.arcs``).  The first piece [0, s_1*): τ = s/s_1*, released at Y_j(0) = 1 + Σ w_n ε̂^n;
the order's unknowns become ``A_n``, ``σ_{1,n}`` (the arc's length ℓ_n), the release values h_k (k ≠ j) and μ_n
(instead of the first piece's c), fixed by the contact condition χ·Y_n(1) = 0, ``A_n = [μ s_1*²]_n`` and the
next piece matched to the arc's end (value Y_k(1), slope Y_k'(1)/s_1*).  The last piece (s_L*, π]:
τ = (π − s)/(π − s_L*), W = −Y; its turning values h_k = Y_{n,k}(0) at π and its μ_n are unknowns, and the
conditions are the value and slope match at s_L* and ``A_n = [μ (π − s_L*)²]_n`` (instead of ``W'(π) = 0``).

Coefficients live in any sympy field: exact (``QQ``, ``QQ(π, κ, β, …)``) or a
``RealField`` of the working precision (always, with a stretched arc).

In an N-dof float field the laws reach the components only through shared parts of the right-hand side — the
rank-one projections ``c · W`` and the element forces, each O(N) terms: a component k ≠ j receives them with its
weight −g_k, and their particular solutions ``Σ_ν u_ν/(r_k² − ν²)`` are evaluated at the few points the matching
needs (:class:`~lindstedt.engine.particular.SharedForcing`), not formed as one O(N)-term branch per component; an order solved with every
component coupled (a stretched arc) forms its branches only when a higher order or a waveform asks for them.
"""

from __future__ import annotations

import math
from typing import Any

from sympy import QQ

from ..algebra.branch import Branch, EvaluationPoint, domain_constant
from .._precision import locked
from .orders import LazyOrders, shift_powers, sum_of_products
from .affine import _Affine, solve_linear
from .branch_system import BranchSystem, ContactState, MovingBoundary
from .float_branches import FloatBranches
from .particular import Particular, SharedForcing, add_scaled, combination, subtract_into

__all__ = ["BranchHierarchy"]


class BranchHierarchy(LazyOrders):
    """Order-by-order solution of a :class:`BranchSystem` (see the module docstring).

    Examples
    --------
    >>> from lindstedt.engine.contact import contact_normal_form
    >>> from lindstedt.problems.oscillator import Oscillator
    >>> form = contact_normal_form(Oscillator("Max(0, u)", a0=1, omega0=1))
    >>> hierarchy = BranchHierarchy(form.system, "initial")
    >>> form.to_expr(hierarchy.squared_frequency(2))
    -3/16
    """

    def __init__(self, system: BranchSystem, normalization: str = "initial"):
        self.system = system
        self.normalization = normalization
        domain = system.domain
        self._domain = domain
        self._branches: list[list[list[Branch]]] = [
            [[Branch.cosine(domain) if k == system.mode else Branch(domain) for k in range(system.size)] for _ in system.states]
        ]
        self._squared: list[Any] = [domain.one]
        self._frequencies: list[Any] = [domain.one]
        # per boundary: [β, σ_1, σ_2, …] as far as known (a grazing boundary starts with its σ_1
        # and learns σ_{n−1} at order n, from the contact condition where σ_{n−1} first appears)
        self._shifts: list[list[Any]] = [
            [boundary.point.value] + ([boundary.first_shift] if boundary.grazing else []) for boundary in system.boundaries
        ]
        self._lag = int(any(boundary.grazing for boundary in system.boundaries))
        self._derivatives: dict[tuple[int, int, int, int], Branch] = {}
        self._power_tables: list[tuple | None] = [None] * len(system.boundaries)  # per boundary: the last shift_powers
        self._law_powers: dict[tuple, Branch] = {}
        # per stretched arc (first, last piece): its length ℓ_n (ℓ = s_1* or π − s_L*), μ_n = [Ω²/ℓ²]_n and
        # per component Q_{n,k} = [Y_k'(1)/ℓ]_n, the slope it hands to its neighbour (Q_{0,j} = −sin β)
        self._arc_data: list[dict[str, list[Any]] | None] = []
        for which, arc in enumerate(system.arcs):
            if arc is None:
                self._arc_data.append(None)
                continue
            boundary = system.boundaries[-which]  # the first boundary for the first piece, the last for the last
            length = boundary.point.value if which == 0 else system.pi_point.value - boundary.point.value
            self._arc_data.append({"mu": [domain.one / (length * length)], "length": [length],
                                   "quotients": [[-boundary.sine if k == system.mode else domain.zero
                                                  for k in range(system.size)]]})
        self._resonant = Branch(domain, {(1, 1, 1): domain.one / domain.convert(2)})  # s sin s / 2 solves v'' + v = cos s
        self._resonant_slope = self._resonant.derivative()
        # r_k as domain elements (the mode component's frequency is 1)
        self._ratio_elements = [domain.one if ratio is None else ratio for ratio in system.ratios]
        self._inverses: dict[Any, dict] = {}  # per r_k: the particular solutions of forcing terms, one order's
        self.counters = {"orders": 0}
        # orders whose components k ≠ j wait to be solved (see _solve_order), and their gaps' known part
        self._pending: dict[int, list[int]] = {}
        self._gap_parts: dict[int, list[Any]] = {}
        self._projection_cache: dict[tuple[int, int], list[Branch]] = {}
        self._shared_cache: dict[tuple[int, int], list] = {}
        self._unbuilt: dict[int, Any] = {}  # per order solved (coupled) but not yet formed: its build()
        self._inverse_factorials: list[Any] = [domain.one, domain.one]

    # -- read access ---------------------------------------------------------------------------------
    @locked
    def branches(self, order: int) -> list[list[Branch]]:
        """W_order: ``branches(order)[piece][component]``."""
        self._ensure(order)
        self._complete(order)
        self._build(order)
        return self._branches[order]

    @locked
    def boundary_shift(self, order: int) -> list[Any]:
        """σ_{i,order} for every boundary (order 0: the contact angles β_i)."""
        self._ensure(order + self._lag)
        self._complete(order + self._lag)
        return [shifts[order] for shifts in self._shifts]

    @locked
    def release(self, order: int, component: int) -> Any:
        """W_{order, component}(0) (on a first-piece arc: Y_{order, component}(0))."""
        branches = self.branches(order)
        if self.system.arcs[0] is not None:
            return self._domain.dtype(self.system.arcs[0].release(order, component))
        return branches[0][component].evaluate(self.system.zero_point)

    @locked
    def arc_length(self, which: int, order: int) -> Any:
        """ℓ_order of stretched arc ``which`` (0: first piece, ℓ = s_1*; 1: last piece, ℓ = π − s_L*)."""
        self._ensure(order)
        return self._arc_data[which]["length"][order]

    @locked
    def float_branches(self, highest: int, to_float: Any = float) -> FloatBranches:
        """:class:`FloatBranches` of W_0 … W_highest, coefficients converted by ``to_float``."""
        terms = tuple(
            tuple(
                tuple(
                    [
                        (frequency if isinstance(frequency, int) else float(frequency), parity, power, to_float(value))
                        for (frequency, parity, power), value in branch.terms.items()
                    ]
                    for branch in piece
                )
                for piece in self.branches(n)
            )
            for n in range(highest + 1)
        )
        self._ensure(highest + self._lag)
        shifts = tuple(tuple(to_float(value) for value in self.boundary_shift(n)) for n in range(highest + 1))
        arcs = tuple(None if arc is None else arc.float_arcs(highest) for arc in self.system.arcs)
        return FloatBranches(terms, shifts, arcs)

    def _law_power(self, piece: int, element: int, power: int, order: int) -> Branch:
        """[y^power]_order on ``piece`` for the deformation ``y = c · W`` of ``element``:
        Σ_i [y^{power−1}]_i y_{order−i}, memoised (y_n = W_{n,k} itself where c is the unit vector e_k)."""
        key = (piece, element, power, order)
        if key not in self._law_powers:
            if power == 1:
                coupling = self.system.states[piece].elements[element][1]
                nonzero = [k for k, weight in enumerate(coupling) if weight]
                branches = self._branches[order][piece]
                if len(nonzero) == 1 and coupling[nonzero[0]] == self._domain.one:
                    result = branches[nonzero[0]]
                else:
                    result = combination(self._domain, [branches[k] for k in nonzero], [coupling[k] for k in nonzero])
            else:
                result = Branch(self._domain)
                for i in range(order + 1):
                    result = result + self._law_power(piece, element, power - 1, i) * \
                        self._law_power(piece, element, 1, order - i)
            self._law_powers[key] = result
        return self._law_powers[key]

    def _analytic_force(self, piece: int, element: int, order: int) -> Branch:
        """[f(y)]_order of an analytic element on ``piece``: Σ_m g_m [δ^m]_order, δ = y − y_0, memoised."""
        key = ("force", piece, element, order)
        if key not in self._law_powers:
            law = self.system.states[piece].analytic[element][2]
            total = Branch(self._domain)
            for m in range(order + 1):
                deviation = self._deviation(piece, element, m, order)
                if deviation.terms:
                    total = total + law.branch(m) * deviation
            self._law_powers[key] = total
        return self._law_powers[key]

    def _deviation(self, piece: int, element: int, power: int, order: int) -> Branch:
        """[δ^power]_order on ``piece`` for an analytic element, δ = Σ_{n≥1} ε̂^n (c · W_n)."""
        key = ("deviation", piece, element, power, order)
        if key not in self._law_powers:
            domain = self._domain
            if power == 0:
                result = Branch.constant(domain, domain.one) if order == 0 else Branch(domain)
            elif order < power:
                result = Branch(domain)
            elif power == 1:
                coupling = self.system.states[piece].analytic[element][1]
                nonzero = [k for k, weight in enumerate(coupling) if weight]
                branches = self._branches[order][piece]
                result = combination(domain, [branches[k] for k in nonzero], [coupling[k] for k in nonzero])
            else:
                result = Branch(domain)
                for i in range(1, order - power + 2):
                    result = result + self._deviation(piece, element, 1, i) * self._deviation(piece, element, power - 1,
                                                                                               order - i)
            self._law_powers[key] = result
        return self._law_powers[key]

    # -- the expansion about a moving boundary -------------------------------------------------------
    def _derivative(self, order: int, piece: int, component: int, times: int) -> Branch:
        key = (order, piece, component, times)
        if key not in self._derivatives:
            if times == 0:
                self._derivatives[key] = self._branches[order][piece][component]
            else:
                self._derivatives[key] = self._derivative(order, piece, component, times - 1).derivative()
        return self._derivatives[key]

    def _shift_powers(self, boundary: int, order: int) -> list[list[Any]]:
        """[δσ^n]_j for n, j <= order, δσ = Σ_i σ_i η^i over the σ_i known before order ``order``."""
        shifts = self._shifts[boundary][:order]
        cached = self._power_tables[boundary]  # ((order, len(shifts)), table): asked twice per order, extended by a column
        if cached is None or cached[0] != (order, len(shifts)):
            previous = None if cached is None else (cached[0][1], cached[1])
            cached = self._power_tables[boundary] = ((order, len(shifts)), shift_powers(shifts, order, self._domain, previous))
        return cached[1]

    def _known(self, boundary: int, piece: int, component: int, order: int, derivative: int, powers: list[list[Any]]) -> Any:
        """ε̂^order coefficient of ∂^derivative W_component^piece at s*(ε̂), without W_order and σ_order."""
        point = self.system.boundaries[boundary].point
        domain = self._domain
        terms = []
        for times in range(1, order + 1):
            inverse = self._inverse_factorial(times)
            for j in range(0, order - times + 1):
                weight = powers[times][order - j]
                if weight:
                    terms.append((self._derivative(j, piece, component, times + derivative).evaluate(point), weight, inverse))
        return sum_of_products(domain, terms)

    def _inverse_factorial(self, n: int) -> Any:
        """1/n! in the domain (its one for n ≤ 1: a product with it is skipped by a fused sum of products)."""
        table = self._inverse_factorials
        while len(table) <= n:
            table.append(domain_constant(self._domain, QQ(1, math.factorial(len(table)))))
        return table[n]

    def _boundary_first_harmonic(self, boundary: int, order: int, powers: list[list[Any]]) -> Any:
        """ε̂^order coefficient of ∫_β^{s*} (W_j^p − W_j^{p+1}) cos s ds (known part)."""
        point = self.system.boundaries[boundary].point
        mode = self.system.mode
        domain = self._domain
        total = domain.zero
        for j in range(1, order):
            derivative = (self._branches[j][boundary][mode] - self._branches[j][boundary + 1][mode]).times_cosine(1)
            factorial = 1
            for times in range(0, order - j):
                factorial *= times + 1
                weight = powers[times + 1][order - j]
                if weight:
                    total = total + derivative.evaluate(point) * weight / domain_constant(domain, factorial)
                derivative = derivative.derivative()
        return total

    # -- one order -------------------------------------------------------------------------------------
    def _solve_order(self, order: int) -> None:
        """Order ``order``: every component when the system is coupled (N = 1, or a stretched arc); otherwise
        only the mode component j (A_n and W_{n,j}) — the components k ≠ j and the shifts σ_n are
        solved by :meth:`_complete` when something asks for them (order n + 1, branches, shifts)."""
        self._complete(order - 1)
        self._build(order - 1)
        system = self.system
        if system.size == 1 or system.arcs != (None, None):
            self._solve_components(order, list(range(system.size)), coupled=True)
        else:
            self._branches.append([[None] * system.size for _ in system.states])
            self._gap_parts[order] = [self._domain.zero] * len(system.boundaries)
            self._solve_components(order, [system.mode], coupled=False)
            self._pending[order] = [k for k in range(system.size) if k != system.mode]
        # one order's memos: 69 % of the lookups hit within an order, 70 % if kept for all (not worth their O(N³) numbers)
        self._inverses.clear()
        self.counters["orders"] += 1

    def _complete(self, order: int) -> None:
        """Solve the deferred components k ≠ j of ``order`` (each alone: for k ≠ j order n involves only
        c_k, given the lower orders) and then the boundary shifts σ_n from the whole gap Σ_k c_ik W_{n,k}."""
        pending = self._pending.pop(order, None)
        if pending is None:
            return
        for component in pending:
            self._solve_components(order, [component], coupled=False)
        self._inverses.clear()
        one, mode = self._domain.one, self.system.mode
        for index, (boundary, gap) in enumerate(zip(self.system.boundaries, self._gap_parts.pop(order))):
            if not boundary.grazing:
                self._shifts[index].append(gap * (one / (boundary.coupling[mode] * boundary.sine)))
            elif order >= 3:
                curvature = -boundary.point.cos_multiple(1)
                self._shifts[index].append(gap * (-one / (boundary.coupling[mode] * curvature * boundary.first_shift)))

    def _solve_components(self, order: int, components: list[int], coupled: bool) -> None:
        """Order ``order`` for ``components``: unknowns A_n (index 0) and c_k on the first piece (1 + position).

        ``coupled``: ``components`` is the whole system; the shifts σ_n are solved here (affine, as the
        stretched arcs need them among the unknowns).  Otherwise the components' share of every gap is
        added to ``_gap_parts[order]`` and A_n is the unknown only for the mode component (a group
        without it takes A_n as known: it does not enter the equations of k ≠ j at order n).
        """
        system, domain = self.system, self._domain
        zero, one = domain.zero, domain.one
        mode = system.mode
        size = len(components)
        resonant = self._resonant
        top, bottom = system.arcs
        # A_n, then c_k on the first piece for every component k; with a first-piece arc: A_n, σ_{1,n}, the
        # release values h_k (k ≠ j) and μ_n; a last-piece arc adds its far turning values h_k (every k) and μ_n
        # at bottom_base …
        bottom_base = size + 1 + (top is not None)
        unknown_count = bottom_base + (size + 1 if bottom is not None else 0)

        def constant(value: Any) -> _Affine:
            return _Affine(value, {})

        def unit(index: int) -> _Affine:
            return _Affine(zero, {index: one})

        last_piece = len(system.states) - 1
        ratios = self._ratio_elements
        particular: list[list[Particular]] = []
        for piece, state in enumerate(system.states):
            if (piece == 0 and top is not None) or (piece == last_piece and bottom is not None):
                particular.append([Particular(domain, Branch(domain), [])] * size)  # the stretched arc solves it
                continue
            previous = self._branches[order - system.gauge][piece] if order >= system.gauge else None
            # L W = Σ g (c · W): the projections c · W_{n−1} once per piece (memoised: the components
            # k ≠ j are solved one by one), then one rank-one update per component
            projections = self._projections(order, piece, state, previous) if state.rank_one and previous else []
            shared = self._shared_forcings(order, piece, state, projections)
            components_rhs = []
            for k in components:
                rhs: dict = {}  # the right-hand side's terms, each part subtracted in turn (zeros dropped at the end)
                for i in range(1, order):
                    subtract_into(rhs, self._derivative(order - i, piece, k, 2), self._squared[i])
                for l, entry in enumerate(state.stiffness[k] if state.stiffness and previous else ()):
                    if entry:
                        subtract_into(rhs, previous[l], entry)
                if shared is not None and k != mode:
                    # a component k ≠ j in a float field: the shared parts (projections, element forces) are
                    # solved term by term (SharedForcing); its own right-hand side keeps the rest
                    if order == system.gauge and state.load[k]:
                        subtract_into(rhs, Branch.constant(domain, state.load[k]))
                    parts = []
                    ratio = ratios[k]
                    close = abs(float(ratio)) * 1e-6
                    for forcing, part in shared:
                        if not forcing[k]:
                            continue
                        weight = -forcing[k]
                        near = part.near(float(ratio), close)
                        for group in near:  # (near) resonance: the general solution
                            add_scaled(rhs, part.groups[group], weight)
                        add_scaled(rhs, part.others, weight)
                        parts.append((weight, part, part.inverses(ratio, near)))
                    own = Branch(domain, rhs).oscillator_particular_solution(system.ratios[k], self._inverses)
                    components_rhs.append(Particular(domain, own, parts))
                    continue
                if projections:
                    subtract_into(rhs, combination(domain, projections, [forcing[k] for forcing, _ in state.rank_one]))
                if order == system.gauge and state.load[k]:
                    subtract_into(rhs, Branch.constant(domain, state.load[k]))
                if order >= system.gauge:
                    for element, (forcing, _, _) in enumerate(state.analytic):
                        if forcing[k]:
                            subtract_into(rhs, self._analytic_force(piece, element, order - system.gauge), forcing[k])
                    for element, (forcing, _, powers) in enumerate(state.elements):
                        if forcing[k]:
                            for power, coefficient in powers:
                                subtract_into(rhs, self._law_power(piece, element, power, order - system.gauge),
                                          coefficient * forcing[k])
                own = Branch(domain, rhs).oscillator_particular_solution(system.ratios[k], self._inverses)
                components_rhs.append(Particular(domain, own, []))
            particular.append(components_rhs)

        def value_of(piece: int, position: int, c: _Affine | None, d: _Affine | None, point: EvaluationPoint,
                     slope: bool) -> _Affine:
            """W_{n,k}^piece (or its slope) at point, for homogeneous parts c, d (k = components[position]; None: zero)."""
            k = components[position]
            result = _Affine(particular[piece][position].value(point, slope),
                             {0: (self._resonant_slope if slope else resonant).evaluate(point)} if k == mode else {})
            if c is None and d is None:
                return result
            frequency = system.frequency(k)
            cosine, sine = point.cos_multiple(frequency), point.sin_multiple(frequency)
            if slope:  # r_k = 1 (the mode component) multiplies nothing
                ratio = ratios[k]
                cosine, sine = (cosine, -sine) if ratio is one else (cosine * ratio, -sine * ratio)
                cosine, sine = sine, cosine  # c multiplies −r sin, d r cos
            if c is not None:
                result = result + c.scale(cosine)
            return result if d is None else result + d.scale(sine)

        def over_ratio(value: Any, k: int) -> Any:
            """value / r_k (r_k = 1: value itself)."""
            ratio = ratios[k]
            return value if ratio is one else value / ratio

        # First piece: c_k free, d_k from W_k'(0) = 0 (d_k r_k + slope without d = 0).
        c_values = [[unit(1 + p) for p in range(size)]]
        d_values = [[value_of(0, p, c_values[0][p], None, system.zero_point, True).scale(over_ratio(-one, k))
                     for p, k in enumerate(components)]]
        shift_values: list[_Affine | None] = []
        gaps: list[_Affine] = []
        for index, boundary in enumerate(system.boundaries):
            point = boundary.point
            powers = self._shift_powers(index, order)
            left, right = index, index + 1
            if index == 0 and top is not None:
                c_next, d_next, top_quotient, contact = self._match_first_arc(
                    order, point, boundary, powers, value_of, constant, unit)
                c_values.append(c_next)
                d_values.append(d_next)
                shift_values.append(unit(1))
                continue
            # W_{n,k} on the left piece at β, and its known Taylor terms there (W_order and σ_order excluded)
            values = [value_of(left, p, c_values[left][p], d_values[left][p], point, False) for p in range(size)]
            known = [self._known(index, left, k, order, 0, powers) for k in components]
            # Contact: Σ_k c_k W_k(s*) = κ  ->  order n: Σ_k c_k [W_{n,k}(β) + known_k] + c_j W_0'(β) σ_n = 0, W_0' = −sin β.
            gap = constant(zero)
            for p, k in enumerate(components):
                coupling = boundary.coupling[k]
                if coupling:
                    gap = gap + values[p].shift(known[p]).scale(coupling)
            gaps.append(gap)
            if not coupled:
                pass  # the shifts need every component: _complete
            elif not boundary.grazing:
                shift_values.append(gap.scale(one / (boundary.coupling[mode] * boundary.sine)))
            elif order >= 3:
                # σ_{n−1} first appears here, through c_j W_0''(β) σ_1 σ_{n−1} (W_0'' = −cos β = −κ_j);
                # σ_1 came from the order-2 quadratic, solved by the normal form.
                curvature = -point.cos_multiple(1)
                shift_values.append(gap.scale(-one / (boundary.coupling[mode] * curvature * boundary.first_shift)))
            else:
                shift_values.append(None)
            if right == last_piece and bottom is not None:
                break  # the last arc is matched below (slope and frequency conditions)
            # C¹ matching of every component: the homogeneous parts of the right piece.
            c_next, d_next = [], []
            for p, k in enumerate(components):
                slope = value_of(left, p, c_values[left][p], d_values[left][p], point, True)
                x = values[p].shift(known[p] - self._known(index, right, k, order, 0, powers))
                y = slope.shift(self._known(index, left, k, order, 1, powers) - self._known(index, right, k, order, 1, powers))
                x = x - value_of(right, p, None, None, point, False)
                y = y - value_of(right, p, None, None, point, True)
                frequency = system.frequency(k)
                cosine, sine = point.cos_multiple(frequency), point.sin_multiple(frequency)
                c_next.append(x.scale(cosine) - y.scale(over_ratio(sine, k)))
                d_next.append(x.scale(sine) + y.scale(over_ratio(cosine, k)))
            c_values.append(c_next)
            d_values.append(d_next)
        last = last_piece
        if bottom is None:
            equations = [value_of(last, p, c_values[last][p], d_values[last][p], system.pi_point, True) for p in range(size)]
        else:
            index = len(system.boundaries) - 1
            equations, bottom_mu, bottom_quotient = self._match_last_arc(
                order, index, shift_values[index], value_of, c_values[last - 1], d_values[last - 1], constant, unit,
                bottom_base)
        if mode not in components:
            equations.append(unit(0).shift(-self._squared[order]))  # A_n is known: solved with the mode component
        elif top is not None:  # the arc's end on its breakpoint, and A_n = [μ s_1*²]_n
            equations.append(contact)
            equations.append(self._arc_frequency_condition(0, order, unit(size + 1), unit(1), unit))
        elif self.normalization == "initial":
            position = components.index(mode)
            release = value_of(0, position, c_values[0][position], d_values[0][position], system.zero_point, False)
            prescribed = system.release_at(order)
            equations.append(release if prescribed is None else release.shift(-prescribed))
        else:
            equations.append(self._first_harmonic_condition(order, particular, c_values, d_values, unit(0), components.index(mode)))
        unknowns = solve_linear([e.dense(unknown_count, zero) for e in equations], [-e.base for e in equations], domain, order)
        branches = [[None] * system.size for _ in system.states] if coupled else self._branches[order]

        def build() -> None:
            """W_order's branches: particular solution + homogeneous part (+ the resonant term for j)."""
            for piece in range(len(system.states)):
                if (piece == 0 and top is not None) or (piece == last_piece and bottom is not None):
                    branches[piece] = [Branch(domain)] * system.size  # the arc's own representation stands here
                    continue
                for p, k in enumerate(components):
                    frequency = system.frequency(k)
                    homogeneous = Branch(domain, {(frequency, 0, 0): c_values[piece][p].value(unknowns),
                                                  (frequency, 1, 0): d_values[piece][p].value(unknowns)})
                    branch = particular[piece][p].branch() + homogeneous
                    if k == mode:
                        branch = branch + resonant.scale(unknowns[0])
                    branches[piece][k] = branch

        if coupled:
            self._unbuilt[order] = build  # formed when a higher order or the branches are asked for
        else:
            build()
        if not coupled:
            parts = self._gap_parts[order]
            for index, gap in enumerate(gaps):
                parts[index] = parts[index] + gap.value(unknowns)
            if mode in components:
                self._squared.append(unknowns[0])
            return
        self._branches.append(branches)
        self._squared.append(unknowns[0])
        for shifts, value in zip(self._shifts, shift_values):
            if value is not None:
                shifts.append(value.value(unknowns))
        if top is not None:
            data = self._arc_data[0]
            mu = unknowns[size + 1]
            data["mu"].append(mu)
            data["quotients"].append([q.value(unknowns) for q in top_quotient])
            data["length"].append(unknowns[1])
            release = system.release_at(order)
            heights = [self._arc_height(k, unit).value(unknowns) if k != mode else
                       (zero if release is None else release) for k in range(size)]
            top.fix(order, heights, mu)
        if bottom is not None:
            data = self._arc_data[1]
            data["mu"].append(bottom_mu.value(unknowns))
            data["quotients"].append([q.value(unknowns) for q in bottom_quotient])
            data["length"].append(-self._shifts[-1][order])
            bottom.fix(order, [unknowns[bottom_base + k] for k in range(size)], unknowns[bottom_base + size])

    def _projections(self, order: int, piece: int, state: ContactState, previous: list[Branch]) -> list[Branch]:
        """c · W_{n−gauge} on ``piece`` for every rank-one term (c, g) of the piece's law, formed once per order."""
        key = (order, piece)
        if key not in self._projection_cache:
            if any(cached != order for cached, _ in self._projection_cache):
                self._projection_cache.clear()
            self._projection_cache[key] = [combination(self._domain, previous, coupling) for _, coupling in state.rank_one]
        return self._projection_cache[key]

    def _shared_forcings(self, order: int, piece: int, state: ContactState,
                         projections: list[Branch]) -> list[tuple[tuple[Any, ...], SharedForcing]] | None:
        """The parts of order ``order``'s right-hand sides on ``piece`` that every component receives with its own
        weight (``(g, S)``: −g_k S for component k): the rank-one projections and the element forces, formed once per
        order and piece; None in an exact field (there every component's right-hand side is one branch)."""
        domain, gauge = self._domain, self.system.gauge
        if domain.is_Exact or self.system.size == 1 or not hasattr(domain, "from_raw"):
            return None
        key = (order, piece)
        if key not in self._shared_cache:
            if any(cached != order for cached, _ in self._shared_cache):
                self._shared_cache.clear()
            parts = [(forcing, SharedForcing(domain, projection))
                     for (forcing, _), projection in zip(state.rank_one, projections)]
            if order >= gauge:
                for element, (forcing, _, _) in enumerate(state.analytic):
                    if any(forcing):
                        parts.append((forcing, SharedForcing(domain, self._analytic_force(piece, element, order - gauge))))
                for element, (forcing, _, powers) in enumerate(state.elements):
                    if any(forcing):
                        laws = [self._law_power(piece, element, power, order - gauge) for power, _ in powers]
                        law = combination(domain, laws, [coefficient for _, coefficient in powers])
                        parts.append((forcing, SharedForcing(domain, law)))
            self._shared_cache[key] = parts
        return self._shared_cache[key]

    def _build(self, highest: int) -> None:
        """Form the branches of the orders up to ``highest`` that were solved without them (an order's matching
        evaluates its particular solutions at points only; the frequency of the highest order needs no branch)."""
        for order in sorted(order for order in self._unbuilt if order <= highest):
            self._unbuilt.pop(order)()

    def _arc_height(self, k: int, unit: Any) -> _Affine:
        """The release value h_k (k ≠ j) of a first-piece arc among the order's unknowns."""
        position = k if k < self.system.mode else k - 1
        return unit(2 + position)

    def _match_first_arc(self, order: int, point: EvaluationPoint, boundary: MovingBoundary, powers: list,
                         value_of: Any, constant: Any, unit: Any) -> tuple:
        """The next piece's homogeneous parts from the first arc's end (:class:`~lindstedt.engine.stretched.VectorArc`),
        at order n.

        Unknowns: A_n (0), σ_n = ℓ_n (1), h_k = Y_{n,k}(0) for k ≠ j (2 …), μ_n (N + 1).  Every component's
        end value ``Y_{n,k}(1)`` and slope ``Q_k = Y_k'(1)/s*`` are affine in them; the next piece matches
        ``W_k(s*) = Y_k(1)`` and ``W_k'(s*) = Q_k`` (with W_0 = e_j cos s: −sin β σ_n and −cos β σ_n for k = j),
        ``[Q_k]_n = (Y_{n,k}'(1) − Σ_{i=1}^{n−1} ℓ_i [Q_k]_{n−i} − ℓ_n [Q_k]_0)/β``; the contact condition is
        ``χ · Y_n(1) = 0`` (the element's deformation is on its breakpoint at the arc's end).
        """
        domain, system, arc, data = self._domain, self.system, self.system.arcs[0], self._arc_data[0]
        size, mode = system.size, system.mode
        release = system.release_at(order)
        ends = arc.response(order)
        sine, cosine, beta = boundary.sine, point.cos_multiple(1), point.value
        mu = unit(size + 1)
        c_next, d_next, quotients = [], [], []
        contact = constant(domain.zero)
        for k in range(size):
            end, end_slope = (domain.dtype(x) for x in ends[k])
            dh_value, dh_slope, dmu_value, dmu_slope = (domain.dtype(x) for x in arc.end_terms(k))
            height = constant(domain.zero if release is None else release) if k == mode else \
                self._arc_height(k, unit)
            value = constant(end) + height.scale(dh_value) + mu.scale(dmu_value)
            slope = constant(end_slope) + height.scale(dh_slope) + mu.scale(dmu_slope)
            if boundary.coupling[k]:
                contact = contact + value.scale(boundary.coupling[k])
            known = sum((data["length"][i] * data["quotients"][order - i][k] for i in range(1, order)), domain.zero)
            quotient = (slope.shift(-known) + unit(1).scale(-data["quotients"][0][k])).scale(domain.one / beta)
            quotients.append(quotient)
            target = value.shift(-self._known(0, 1, k, order, 0, powers))
            slope_target = quotient.shift(-self._known(0, 1, k, order, 1, powers))
            if k == mode:  # W_0'(β) σ_n = −sin β σ_n, W_0''(β) σ_n = −cos β σ_n move to the targets
                target = target + unit(1).scale(sine)
                slope_target = slope_target + unit(1).scale(cosine)
            x = target - value_of(1, k, None, None, point, False)
            y = slope_target - value_of(1, k, None, None, point, True)
            frequency, ratio = system.frequency(k), self._ratio_elements[k]
            cos_r, sin_r = point.cos_multiple(frequency), point.sin_multiple(frequency)
            c_next.append(x.scale(cos_r) - y.scale(sin_r / ratio))
            d_next.append(x.scale(sin_r) + y.scale(cos_r / ratio))
        return c_next, d_next, quotients, contact

    def _match_last_arc(self, order: int, index: int, shift: _Affine, value_of: Any, c_left: list, d_left: list,
                        constant: Any, unit: Any, base: int) -> tuple:
        """The matching of a last-piece arc (:class:`~lindstedt.engine.stretched.VectorArc`), at order n.

        On (s_L*, π] ``W_k(s) = −Y_k((π − s)/ℓ)``, ``ℓ = π − s_L*`` (``ℓ_n = −σ_{L,n}``, σ from the left piece's
        contact condition); unknowns ``h_k = Y_{n,k}(0)`` (``base + k``, the far turning values) and ``μ_n``
        (``base + N``).  Equations: ``W_k(s*) = −Y_k(1)`` and ``W_k'(s*) = Q_k = Y_k'(1)/ℓ`` for every k, and
        ``A_n = [μ ℓ²]_n``; returns them with μ_n and the Q_{n,k} (affine).
        """
        domain, system, arc, data = self._domain, self.system, self.system.arcs[1], self._arc_data[1]
        size, mode = system.size, system.mode
        boundary = system.boundaries[index]
        point, powers = boundary.point, self._shift_powers(index, order)
        left = len(system.states) - 2
        ends = arc.response(order)
        mu = unit(base + size)
        equations, quotients = [], []
        for k in range(size):
            end, end_slope = (domain.dtype(x) for x in ends[k])
            dh_value, dh_slope, dmu_value, dmu_slope = (domain.dtype(x) for x in arc.end_terms(k))
            height = unit(base + k)
            arc_value = constant(end) + height.scale(dh_value) + mu.scale(dmu_value)
            arc_slope = constant(end_slope) + height.scale(dh_slope) + mu.scale(dmu_slope)
            known = sum((data["length"][i] * data["quotients"][order - i][k] for i in range(1, order)), domain.zero)
            quotient = (arc_slope.shift(-known) + shift.scale(data["quotients"][0][k])).scale(domain.one / data["length"][0])
            quotients.append(quotient)
            value = value_of(left, k, c_left[k], d_left[k], point, False).shift(self._known(index, left, k, order, 0, powers))
            slope = value_of(left, k, c_left[k], d_left[k], point, True).shift(self._known(index, left, k, order, 1, powers))
            if k == mode:  # W_0'(β) σ_n = −sin β σ_n, W_0''(β) σ_n = −cos β σ_n
                value = value + shift.scale(-boundary.sine)
                slope = slope + shift.scale(-point.cos_multiple(1))
            equations.append(value + arc_value)
            equations.append(slope - quotient)
        equations.append(self._arc_frequency_condition(1, order, mu, shift.scale(-domain.one), unit))
        return equations, mu, quotients

    def _arc_frequency_condition(self, which: int, order: int, mu: _Affine, length_shift: _Affine, unit: Any) -> _Affine:
        """A_n − [μ ℓ²]_n = 0 for arc ``which`` (μ = Ω²/ℓ²), given μ_n and ℓ_n as affine values."""
        domain, data = self._domain, self._arc_data[which]
        lengths, mus = data["length"], data["mu"]

        def squared(j: int) -> Any:  # [ℓ²]_j for j < order
            return sum((lengths[i] * lengths[j - i] for i in range(j + 1)), domain.zero)

        known = sum((lengths[i] * lengths[order - i] for i in range(1, order)), domain.zero)
        total = length_shift.scale(2 * lengths[0] * mus[0]).shift(known * mus[0]) + mu.scale(squared(0))
        for i in range(1, order):
            total = total.shift(mus[i] * squared(order - i))
        return unit(0) - total

    def _first_harmonic_condition(self, order: int, particular: list, c_values: list, d_values: list, resonant_unit: _Affine,
                                  mode: int) -> _Affine:
        """ε̂^order coefficient of ∫_0^π W_j cos s ds (must vanish), affine in the unknowns (``mode``: W_j's position)."""
        system, domain = self.system, self._domain
        limits = [system.zero_point] + [b.point for b in system.boundaries] + [system.pi_point]
        cos_cos = Branch.cosine(domain).times_cosine(1)
        sin_cos = Branch.sine(domain).times_cosine(1)
        resonant_cos = self._resonant.times_cosine(1)
        total = resonant_unit.scale(domain.zero)
        for piece, components in enumerate(particular):
            lower, upper = limits[piece], limits[piece + 1]
            total = total.shift(components[mode].branch().times_cosine(1).integral(lower, upper))
            total = total + resonant_unit.scale(resonant_cos.integral(lower, upper))
            total = total + c_values[piece][mode].scale(cos_cos.integral(lower, upper))
            total = total + d_values[piece][mode].scale(sin_cos.integral(lower, upper))
        for index in range(len(system.boundaries)):
            total = total.shift(self._boundary_first_harmonic(index, order, self._shift_powers(index, order)))
        return total
