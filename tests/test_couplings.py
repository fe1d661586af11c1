"""Polynomial couplings ε g(X) of a UnilateralSystem (issue 25, item 1: smooth couplings such as x1²x2).

``M X'' + K X + ε g(X) = 0`` with one polynomial g_r per degree of freedom, turned exactly into elements
``ε w_i (a_iᵀ X)^d`` (law ``u**d``).  References, none of them the decomposition under test:

* the polynomials themselves: Σ_i w_i (a_iᵀ X)^d_i, formed from the public A_exact, W_exact and laws, expanded by
  sympy, equals g exactly; the acceleration equals −M⁻¹(K X + ε g(X)) evaluated by numpy from the monomials;
* closed forms: uncoupled masses with g = (x1³, x2³) are Duffing oscillators, and the in-phase / anti-phase modes
  of a symmetric two-mass chain with g = (x1 x2², x1² x2) reduce to the Duffing oscillators q'' + λ² q + ε q³ = 0
  (λ² = 1, 3); the exact frequency from rest at amplitude a is ω = π √(λ² + ε a²) / (2 K(m)),
  m = ε a² / (2 (λ² + ε a²)), evaluated with mpmath (shooting agrees to ~1e-15);
* shooting on the flow (:func:`lindstedt.nnm_point`) for the strained-coordinates expansion of a genuinely coupled
  system: at order 2 its error falls as ε³ (fitted slope over ε = 1e-2 … 1e-3, errors 3e-9 … 3e-12 at a0 = 2, well
  above the shooting's ~1e-14).
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy

from lindstedt import ForcedSystem, ProblemError, UnilateralSystem, UnsupportedNonlinearityError
from lindstedt.numerics import nnm_point

X = sympy.symbols("x1:4", real=True)
x1, x2, x3 = X

POLYNOMIALS = {
    "geometric x1²x2": [x1**2 * x2, 0],
    "x1 x2 x3": [x1 * x2 * x3, 0, x2**3],
    "x1³ − 2 x1 x2²": [x1**3 - 2 * x1 * x2**2, x2**3 / 7],
    "mixed degrees": [x1**2 + x1 * x2**3 - sympy.Rational(3, 2) * x2**4, x1**2 * x2 - x2**5 + 2 * x1 * x2],
    "irrational coefficient": [sympy.sqrt(2) * x1**2 * x2, x1**3],
}


def _diagonal(n, values):
    return [[values[i] if i == j else 0 for j in range(n)] for i in range(n)]


def _element_sum(system, symbols):
    """Σ_i W_i f_i(A_i X − b_i), exactly, from the public attributes."""
    total = sympy.zeros(system.n_dof, 1)
    for i, law in enumerate(system.laws):
        argument = sum(system.A_exact[i, j] * symbols[j] for j in range(system.n_dof)) - system.b_exact[i]
        value = law.xreplace({variable: argument for variable in law.free_symbols})
        total += system.W_exact[:, i] * value
    return total.applyfunc(sympy.expand)


@pytest.mark.parametrize("name", list(POLYNOMIALS))
@pytest.mark.parametrize("as_text", [True, False])
def test_the_elements_reproduce_the_polynomials_exactly(name, as_text):
    g = POLYNOMIALS[name]
    n = len(g)
    system = UnilateralSystem(M=np.eye(n), K=_diagonal(n, [1, 2, 3]), couplings=[str(p) if as_text else p for p in g])
    assert _element_sum(system, X[:n]) == sympy.Matrix(g).applyfunc(sympy.expand)
    assert all(entry == 0 for entry in system.b_exact)
    rows = [(tuple(system.A_exact.row(i)), system.laws[i]) for i in range(system.n_springs)]
    assert len(set(rows)) == len(rows)  # one element per (row, degree)


def test_given_elements_come_first_and_a_pure_power_is_one_element():
    system = UnilateralSystem(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], A=[[1, -1]], b=["1/10"],
                              couplings=["x1**3", "0"])
    u = sympy.Symbol("u", real=True)
    assert system.A_exact.tolist() == [[1, -1], [1, 0]]
    assert system.W_exact.tolist() == [[1, 1], [-1, 0]]
    assert [str(law) for law in system.laws] == ["Max(0, u)", "u**3"] and system.laws[1] == u**3
    assert system.b_exact.tolist() == [[sympy.Rational(1, 10)], [0]]
    assert system.symmetric_coupling  # x1³ = ∂/∂x1 (x1⁴/4): w = a


def test_the_acceleration_is_that_of_the_polynomial_force():
    M = np.array([[2.0, 0.5, 0.0], [0.5, 1.0, 0.0], [0.0, 0.0, 3.0]])
    K = np.array([[3.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 2.0]])
    system = UnilateralSystem(M=M, K=K, couplings=["x1**2*x2 - x3**3", "2*x1*x2*x3 + x2**4", "x1**3/3 - x1*x3**2"])
    epsilon = 0.7
    points = np.random.default_rng(7).uniform(-1.5, 1.5, size=(20, 3))
    batch = system.acceleration(points, epsilon)
    assert batch.shape == points.shape
    for x, acceleration in zip(points, batch):
        a, b, c = x
        g = np.array([a**2 * b - c**3, 2 * a * b * c + b**4, a**3 / 3 - a * c**2])
        expected = -np.linalg.solve(M, K @ x + epsilon * g)
        # rounding of the decomposed sum: ~10 ulps of Σ |w_i| |a_iᵀ x|^d, through M⁻¹
        scale = np.abs(system.W) @ (np.abs(system.A @ x) ** 4 + np.abs(system.A @ x) ** 3)
        bound = 1e-15 * np.linalg.norm(np.linalg.inv(M), np.inf) * (np.abs(K) @ np.abs(x) + epsilon * scale).max()
        assert np.max(np.abs(acceleration - expected)) <= bound
        assert np.max(np.abs(system.acceleration(x, epsilon) - expected)) <= bound


def _duffing_frequency(linear_squared, cubic, amplitude):
    """ω of q'' + λ² q + c q³ = 0 from rest at q = a (exact: q = a cn(Ω t, m))."""
    with mpmath.workdps(30):
        stiffness = linear_squared + cubic * mpmath.mpf(amplitude) ** 2
        m = cubic * mpmath.mpf(amplitude) ** 2 / (2 * stiffness)
        return float(mpmath.pi * mpmath.sqrt(stiffness) / (2 * mpmath.ellipk(m)))


@pytest.mark.parametrize(("mode", "linear_squared"), [(1, 1), (2, 4)])
def test_uncoupled_cubic_couplings_are_duffing_oscillators(mode, linear_squared):
    system = UnilateralSystem(M=[[1, 0], [0, 1]], K=[[1, 0], [0, 4]], couplings=["x1**3", "x2**3"])
    epsilon = 0.5
    orbit = nnm_point(system, epsilon, mode, modal_amplitude=1.0)
    assert orbit.success, orbit.message
    amplitude = orbit.release_position[mode - 1]
    assert orbit.release_position[2 - mode] == pytest.approx(0, abs=1e-12) and abs(amplitude) > 0.5
    assert orbit.frequency == pytest.approx(_duffing_frequency(linear_squared, epsilon, amplitude), rel=1e-13)


@pytest.mark.parametrize(("mode", "linear_squared", "sign"), [(1, 1, 1), (2, 3, -1)])
def test_symmetric_chain_modes_reduce_to_one_degree_of_freedom(mode, linear_squared, sign):
    """x1 = ±x2 = q: g1 = x1 x2² = q³ and g2 = x1² x2 = ±q³, so q'' + λ² q + ε q³ = 0 on either mode."""
    system = UnilateralSystem.chain(2, couplings=["x1*x2**2", "x1**2*x2"])
    epsilon = 0.3
    orbit = nnm_point(system, epsilon, mode, modal_amplitude=1.0)
    assert orbit.success, orbit.message
    q1, q2 = orbit.release_position
    assert q2 == pytest.approx(sign * q1, abs=1e-12)
    assert orbit.frequency == pytest.approx(_duffing_frequency(linear_squared, epsilon, q1), rel=1e-13)


@pytest.mark.parametrize("mode", [1, 2])
def test_the_expansion_of_a_coupled_system_approaches_shooting_at_its_order(mode, slope_against_shooting):
    """x1³ in the first equation, the geometric x1² x2 in the second (W ≠ Aᵀ): order 2 errs by O(ε³)."""
    system = UnilateralSystem(M=[[1, 0], [0, 2]], K=[[3, -1], [-1, 2]], couplings=["x1**3", "x1**2*x2"])
    slope, errors = slope_against_shooting(system, mode, 2)
    assert min(errors) > 1e-12  # far above the shooting's own error (~1e-14): the slope is the expansion's
    assert 2.8 <= slope <= 3.2, (mode, errors)


@pytest.mark.parametrize(("couplings", "error", "fragment"), [
    (["x1**3"], ProblemError, r"one polynomial per degree of freedom \(2; '0' where there is none\), got 1"),
    ("x1**3", ProblemError, "must be a list of one polynomial per degree of freedom"),
    (["sin(x1)", "0"], UnsupportedNonlinearityError, r"not a polynomial in x1, x2.*element.*laws"),
    (["x1**(3/2)", "0"], UnsupportedNonlinearityError, "not a polynomial"),
    (["0", "y*x1**2"], ProblemError, r"couplings\[1\] uses 'y'.*displacements x1, x2 only"),
    (["x0**3", "0"], ProblemError, r"'x0'.*1-based"),
    (["x1**3 + 1/2", "0"], ProblemError, "constant term 1/2: a constant force is a static load"),
    (["0", "x1**3 - 2*x2"], ProblemError, r"linear term -2\*x2: a linear force is a stiffness; put it in K"),
    (["__import__('os')", "0"], ProblemError, "cannot parse"),
])
def test_bad_couplings_name_the_fix(couplings, error, fragment):
    with pytest.raises(error, match=fragment):
        UnilateralSystem(M=[[1, 0], [0, 1]], K=[[1, 0], [0, 2]], couplings=couplings)


def test_a_symbolic_coupling_in_other_symbols_is_refused():
    with pytest.raises(ProblemError, match=r"uses \['q'\]"):
        UnilateralSystem(M=[[1]], K=[[1]], couplings=[sympy.Symbol("q") ** 3])


def test_json_round_trip_keeps_the_couplings_and_the_given_elements():
    system = UnilateralSystem(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], A=[[1, 0]], b=["1/10"], W=[[2], [0]],
                              laws=["u**2"], couplings=["x1**2*x2/3", "x2**3 - x1**3"])
    data = system.to_json_dict()
    assert data["A"] == [["1", "0"]] and data["b"] == ["1/10"] and data["W"] == [["2"], ["0"]]
    assert data["laws"] == ["u**2"] and data["couplings"] == ["x1**2*x2/3", "-x1**3 + x2**3"]
    again = UnilateralSystem.from_json_dict(data)
    assert again == system and hash(again) == hash(system)
    assert again.A_exact == system.A_exact and again.W_exact == system.W_exact and again.laws == system.laws
    forced = ForcedSystem(system, load=[1, 0], rayleigh=(0, "1/100"))
    assert ForcedSystem.from_json_dict(forced.to_json_dict()).system == system
    plain = UnilateralSystem(M=[[1]], K=[[1]], A=[[1]])
    assert "couplings" not in plain.to_json_dict() and plain.couplings is None
    assert UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], couplings=["x1**3"]) != plain


def test_repr_mentions_the_couplings():
    system = UnilateralSystem.chain(2, [(0, "1/2")], couplings=["x1*x2**2", "0"])
    assert repr(system) == "UnilateralSystem(N=2, m=5 (4 from couplings), W≠Aᵀ, couplings=[x1*x2**2, 0])"
