"""N-dof systems whose elements carry any law of the 1-dof library (issue 25, first slice: forced responses).

``M X'' + C X' + K X + ε Σ_i W_i f_i(A_i X − b_i) = ε P cos(Ω t)``, here with a cubic element.  References, none
of them the code under test:

* an independent integration of the ODE by scipy's DOP853 over many periods from rest, to the steady state:
  the damped transient decays as exp(−ζ_min ω_min t) (below 1e-12 here), the integrator's own error is estimated
  by the difference of two tolerances;
* the same oscillator written as one degree of freedom (:class:`lindstedt.ForcedOscillator`, the scalar kernel):
  N = 1 is the one-dof problem.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lindstedt
from lindstedt import ForcedOscillator, ForcedSystem, UnilateralSystem, UnsupportedNonlinearityError
from lindstedt.numerics import ExactFlow, SmoothForcedFlow, forced_flow, forced_periodic_orbit

M = np.eye(2)
K = np.array([[2.0, -1.0], [-1.0, 2.0]])
C = 0.05 * K + 0.02 * M  # Rayleigh damping: ζ ≥ 0.01 on both modes
EPSILON, OMEGA = 0.5, 1.3
LOAD = np.array([1.0, 0.0])


def _cubic_chain() -> ForcedSystem:
    """A two-mass chain with a cubic spring between mass 1 and the ground, forced on mass 1."""
    system = UnilateralSystem(M=M.tolist(), K=K.tolist(), A=[[1, 0]], b=[0], laws=["u**3"])
    return ForcedSystem(system, LOAD.tolist(), C=C.tolist())


def _steady_state(rtol: float, periods: int) -> np.ndarray:
    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        x, v = y[:2], y[2:]
        force = K @ x + C @ v + EPSILON * np.array([x[0] ** 3, 0.0]) - EPSILON * LOAD * math.cos(OMEGA * t)
        return np.r_[v, -force]

    end = 2 * math.pi * periods / OMEGA
    return solve_ivp(rhs, (0.0, end), np.zeros(4), method="DOP853", rtol=rtol, atol=rtol * 1e-2).y[:, -1]


@pytest.mark.slow  # two 600-period reference integrations (5 s)
def test_a_cubic_element_forced_orbit_is_the_steady_state_of_the_ode():
    orbit = forced_periodic_orbit(_cubic_chain(), OMEGA, epsilon=EPSILON)
    assert orbit.success and orbit.stable, orbit.message
    # ζ_min ω_min ≥ 0.01 · 1 → after 600 periods (t ≈ 2900) the transient is below exp(-29) ≈ 3e-13
    fine, coarse = _steady_state(1e-12, 600), _steady_state(1e-10, 600)
    error = float(np.max(np.abs(fine - coarse)))  # measured 1.7e-11; the orbit differs from `fine` by 2.9e-13
    assert error < 1e-9
    assert np.max(np.abs(orbit.state - fine)) <= 10 * error + 1e-12


def test_one_degree_of_freedom_as_a_system_is_the_oscillator():
    system = ForcedSystem(UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], b=[0], laws=["u**3"]), [1], C=[["1/10"]])
    oscillator = ForcedOscillator("u**3", omega0=1, zeta="1/20", forcing=1)
    as_system = SmoothForcedFlow(system, 0.5).period_map([0.3, -0.1], 1.2)
    as_oscillator = SmoothForcedFlow(oscillator, 0.5).period_map([0.3, -0.1], 1.2)
    for a, b in ((as_system.state, as_oscillator.state), (as_system.d_state, as_oscillator.d_state),
                 (as_system.d_frequency, as_oscillator.d_frequency), (as_system.d_forcing, as_oscillator.d_forcing)):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-11)  # two DOP853 runs at rtol 1e-12


def test_the_flow_of_a_system_with_other_laws_is_the_dop853_one():
    assert type(forced_flow(_cubic_chain(), EPSILON)).__name__ == "SmoothForcedFlow"
    unilateral = ForcedSystem(UnilateralSystem(M=M.tolist(), K=K.tolist(), A=[[1, 0]], b=[0]), LOAD.tolist(),
                              C=C.tolist())
    assert type(forced_flow(unilateral, EPSILON)).__name__ == "ForcedFlow"


def test_what_takes_unilateral_springs_only_refuses_other_laws_naming_the_way_out():
    system = _cubic_chain().system
    attempts = [
        lambda: ExactFlow(system, 0.5),
        lambda: lindstedt.all_modes_first_order(system, [1.0, 0.5]),
        lambda: lindstedt.numerics.ForcedFlow(_cubic_chain(), 0.5),
    ]
    for attempt in attempts:
        with pytest.raises(UnsupportedNonlinearityError, match=r"unilateral springs Max\(0, u\) only.*u\*\*3.*DOP853"):
            attempt()


def test_laws_are_read_by_the_one_parser_and_kept_in_json():
    system = UnilateralSystem(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], A=[[1, -1], [0, 1]], b=[0, "1/10"],
                              laws=["u**3", "Max(0, u)**(3/2)"])
    data = system.to_json_dict()
    assert data["laws"] == ["u**3", "Max(0, u)**(3/2)"]
    assert UnilateralSystem.from_json_dict(data) == system
    assert not system.unilateral and UnilateralSystem.chain(2, [(0, 0)]).unilateral
    assert "laws" not in UnilateralSystem.chain(2, [(0, 0)]).to_json_dict()  # old files and outputs unchanged


@pytest.mark.parametrize("laws, error, words", [
    (["u**3"], lindstedt.ProblemError, "one law per row of A"),
    ("u**3", lindstedt.ProblemError, "a list of one law"),
    (["u**3", "7"], lindstedt.ProblemError, "does not depend on u"),
    (["u**3", "k*u"], lindstedt.ParameterError, "k"),
    (["u**3", "__import__('os')"], lindstedt.ProblemError, "calling '__import__' is not allowed"),
])
def test_bad_laws_are_typed_errors(laws, error, words):
    with pytest.raises(error, match=words):
        UnilateralSystem(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], A=[[1, 0], [0, 1]], b=[0, 0], laws=laws)


def test_a_chain_takes_elements_of_any_law_between_any_two_masses():
    chain = UnilateralSystem.chain(3, unilateral=[(2, "1/10")],
                                   elements=[(0, 1, "u**3"), (1, None, "Max(0, u)**(3/2)", "1/5")])
    assert chain.A.tolist() == [[0, 0, 1], [1, -1, 0], [0, 1, 0]]
    assert chain.b.tolist() == [0.1, 0.0, 0.2]
    assert [str(law) for law in chain.laws] == ["Max(0, u)", "u**3", "Max(0, u)**(3/2)"]
    relative_gap = UnilateralSystem.chain(2, elements=[(0, 1, "Max(0, u)", "1/10")])
    assert relative_gap.unilateral and relative_gap.A.tolist() == [[1, -1]]  # the exact flow's problem
    for bad, words in (((0, 0, "u**3"), "two different masses"), ((0, 5, "u**3"), "0..2"),
                       ((0, "u**3"), r"\(i, j, law\)")):
        with pytest.raises(lindstedt.ProblemError, match=words):
            UnilateralSystem.chain(3, elements=[bad])


def test_energy_and_acceleration_of_any_law_along_the_ode():
    """E = ½ X'ᵀ M X' + ½ Xᵀ K X + ε Σ V_i(A_i X − b_i), V_i = ∫f_i, is conserved by the ODE integrated by scipy."""
    system = UnilateralSystem(M=[[1, 0], [0, 2]], K=[[2, -1], [-1, 2]], A=[[1, 0], [1, -1]], b=[0, "1/5"],
                              laws=["u**3", "Max(0, u)**(3/2)"])
    eps, A, b = 0.5, np.array([[1.0, 0.0], [1.0, -1.0]]), np.array([0.0, 0.2])
    mass, stiffness = np.diag([1.0, 2.0]), np.array([[2.0, -1.0], [-1.0, 2.0]])

    def force(x: np.ndarray) -> np.ndarray:  # written here: K X + ε Aᵀ (g1³, (g2)_+^(3/2))
        g = A @ x - b
        return stiffness @ x + eps * A.T @ np.array([g[0] ** 3, max(g[1], 0.0) ** 1.5])

    x = np.array([0.7, -0.3])
    np.testing.assert_allclose(system.acceleration(x, eps), -np.linalg.solve(mass, force(x)), rtol=1e-14)
    g = A @ x - b
    exact = 0.5 * x @ stiffness @ x + eps * (g[0] ** 4 / 4 + 0.4 * max(g[1], 0.0) ** 2.5)  # the release energy
    assert abs(system.energy(x, np.zeros(2), eps) - exact) <= 1e-14 * exact
    drifts = []
    for rtol in (1e-10, 1e-12):
        run = solve_ivp(lambda t, y: np.r_[y[2:], -np.linalg.solve(mass, force(y[:2]))], (0.0, 30.0),
                        np.r_[x, 0.0, 0.0], method="DOP853", rtol=rtol, atol=rtol * 1e-2, dense_output=True)
        states = run.sol(np.linspace(0.0, 30.0, 200)).T
        drifts.append(float(np.max(np.abs(system.energy(states[:, :2], states[:, 2:], eps) - exact))) / exact)
    # conserved up to the integrator's error: the drift falls with its tolerance (3e-8 → 5e-10 measured); a wrong
    # potential would leave an O(1) drift that no tolerance reduces
    assert drifts[0] < 1e-6 and drifts[1] < drifts[0] / 10


def test_a_system_file_may_list_its_elements():
    data = {"M": [[1, 0], [0, 2]], "K": [[3, -1], [-1, 2]],
            "elements": [{"law": "u**3", "a": [1, -1], "w": [2, -2]}, {"a": [0, 1], "b": "1/10"},
                         {"law": "Max(0, u)**(3/2)", "a": [1, 0], "b": "-1/5"}]}
    system = UnilateralSystem.from_json_dict(data)
    expected = UnilateralSystem(M=[[1, 0], [0, 2]], K=[[3, -1], [-1, 2]], A=[[1, -1], [0, 1], [1, 0]],
                                b=[0, "1/10", "-1/5"], W=[[2, 0, 1], [-2, 1, 0]],
                                laws=["u**3", "Max(0, u)", "Max(0, u)**(3/2)"])
    assert system == expected
    assert UnilateralSystem.from_json_dict(system.to_json_dict()) == system  # written back with A, b, W, laws


@pytest.mark.parametrize(("elements", "words"), [
    ([{"law": "u**3"}], r"at least 'a'"),
    ([{"a": [1, 0], "k": 2}], r"unknown keys \['k'\]"),
    ([{"a": [1, 0], "w": [1, 0, 0]}], r"W must be N×m"),
    ({"a": [1, 0]}, r"must be a list"),
    ([{"a": [0, 0]}], r"row 0 of A is zero"),
])
def test_bad_element_lists_are_typed_errors(elements, words):
    with pytest.raises(lindstedt.ProblemError, match=words):
        UnilateralSystem.from_json_dict({"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]], "elements": elements})


def test_elements_and_matrices_together_are_refused():
    with pytest.raises(lindstedt.ProblemError, match=r"both elements and \['A'\]"):
        UnilateralSystem.from_json_dict({"M": [[1]], "K": [[1]], "A": [[1]], "elements": [{"a": [1]}]})
