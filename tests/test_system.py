"""UnilateralSystem: validation, exact storage, JSON round trip, chain builder, modes."""

from __future__ import annotations

import json
import math
from fractions import Fraction

import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from lindstedt import ProblemError, UnilateralSystem


def test_exact_and_float_copies_from_mixed_input():
    system = UnilateralSystem(
        M=np.array([[2.0, 0.0], [0.0, 1.0]]),
        K=[["3", "-1/3"], [Fraction(-1, 3), 1]],
        A=[[0, sympy.Rational(1, 2)]],
        b=[0.1],
    )
    assert system.K_exact[0, 1] == sympy.Rational(-1, 3) == system.K_exact[1, 0]
    assert system.b_exact[0] == sympy.Rational(*Fraction(0.1).as_integer_ratio())  # a float is its exact binary value
    assert system.b[0] == 0.1
    assert system.K[0, 1] == -1 / 3
    assert system.W_exact == system.A_exact.T and system.symmetric_coupling
    assert system.n_dof == 2 and system.n_springs == 1
    with pytest.raises(ValueError):
        system.K[0, 0] = 5.0  # float copies are read-only


def test_irrational_exact_entries_keep_their_value():
    system = UnilateralSystem(M=[[1]], K=[["2"]], A=[["sqrt(2)"]], b=["pi/4"])
    assert system.A_exact[0, 0] == sympy.sqrt(2)
    assert system.A[0, 0] == math.sqrt(2)
    assert system.b[0] == math.pi / 4


def test_no_unilateral_spring_is_allowed():
    system = UnilateralSystem(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]])
    assert system.A.shape == (0, 2) and system.b.shape == (0,) and system.W.shape == (2, 0)


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"M": [[1, 2], [0, 1]], "K": [[1, 0], [0, 1]]}, "M (mass matrix) must be symmetric"),
        ({"M": [[1, 0], [0, 1]], "K": [[1, 0.5], [0.4, 1]]}, "pass (K + K.T)/2"),
        ({"M": [[1, 0], [0, -1]], "K": [[1, 0], [0, 1]]}, "M (mass matrix) must be positive definite"),
        ({"M": [[1, 0], [0, 1]], "K": [[1, 2], [2, 1]]}, "K (stiffness matrix) must be positive definite"),
        ({"M": [[1, 0], [0, 1]], "K": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}, "K must have the shape of M"),
        ({"M": [[1, 0, 0], [0, 1, 0]], "K": [[1, 0], [0, 1]]}, "square"),
        ({"M": [[1, 0], [0, 1]], "K": [[1, 0], [0, float("nan")]]}, "finite"),
        ({"M": [[1, 0], [0, float("inf")]], "K": [[1, 0], [0, 1]]}, "finite"),
        ({"M": [[1, 0], [0, 1]], "K": [[1, 0], [0, 1]], "A": [[1, 0, 0]], "b": [0]}, "one column per degree of freedom"),
        ({"M": [[1, 0], [0, 1]], "K": [[1, 0], [0, 1]], "A": [[1, 0]], "b": [0, 1]}, "one gap per row of A"),
        ({"M": [[1, 0], [0, 1]], "K": [[1, 0], [0, 1]], "A": [[1, 0]], "b": [float("nan")]}, "finite"),
        ({"M": [[1, 0], [0, 1]], "K": [[1, 0], [0, 1]], "A": [[0, 0]], "b": [0]}, "row 0 of A is zero"),
        ({"M": [[1, 0], [0, 1]], "K": [[1, 0], [0, 1]], "A": [[1, 0]], "b": [0], "W": [[1, 0]]}, "W must be N×m"),
        ({"M": [[1, 0], [0, 1]], "K": [[1, 0], [0, 1]], "A": [[1, 0], [0]], "b": [0, 0]}, "different lengths"),
        ({"M": [[1]], "K": [["x"]]}, "must be a finite real number"),
        ({"M": [[1]], "K": [["nan"]]}, "finite"),
        ({"M": [[1]], "K": [[sympy.Symbol("k")]]}, "must be a finite real number"),
        ({"M": [[1]], "K": [[1j]]}, "is complex"),
        ({"M": [[1]], "K": [[True]]}, "boolean"),
        ({"M": [1, 2], "K": [[1]]}, "list of rows"),
        ({"M": [[1]], "K": [[1]], "A": [[1]], "b": [["1"]]}, "has type list"),
    ],
)
def test_bad_input_raises_problem_error_naming_the_fix(kwargs, fragment):
    with pytest.raises(ProblemError) as info:
        UnilateralSystem(**kwargs)
    assert fragment in str(info.value)


def test_json_round_trip_is_exact():
    system = UnilateralSystem(
        M=[["1/3", 0], [0, 2]], K=[[3, -1], [-1, "5/2"]], A=[[1, 0], [0, -1]], b=["1/7", "-0.2"], W=[[2, 0], [0, -1]]
    )
    data = json.loads(json.dumps(system.to_json_dict()))
    assert data["b"] == ["1/7", "-1/5"]
    assert data["W"] == [["2", "0"], ["0", "-1"]]
    again = UnilateralSystem.from_json_dict(data)
    assert again == system and hash(again) == hash(system)
    symmetric = UnilateralSystem.chain(2, [(1, "1/4")])
    assert "W" not in symmetric.to_json_dict()
    assert UnilateralSystem.from_json_dict(symmetric.to_json_dict()) == symmetric


def test_from_json_dict_rejects_unknown_or_missing_keys():
    with pytest.raises(ProblemError, match="unknown keys"):
        UnilateralSystem.from_json_dict({"M": [[1]], "K": [[1]], "A": [], "b": [], "eps": 1})
    with pytest.raises(ProblemError, match="lacks the keys"):
        UnilateralSystem.from_json_dict({"M": [[1]], "K": [[1]]})


def test_chain_matrices_and_unilateral_springs():
    chain = UnilateralSystem.chain(4, [(0, "1/10"), (3, 0, -1)], mass=2, stiffness=3)
    expected_K = 3 * (2 * np.eye(4) - np.eye(4, k=1) - np.eye(4, k=-1))
    np.testing.assert_array_equal(chain.K, expected_K)
    np.testing.assert_array_equal(chain.M, 2 * np.eye(4))
    np.testing.assert_array_equal(chain.A, [[1, 0, 0, 0], [0, 0, 0, -1]])
    assert chain.b_exact[0] == sympy.Rational(1, 10)
    assert chain.symmetric_coupling
    for spec, fragment in [
        ([(4, 0)], "mass index"),
        ([(0, 0, 2)], "direction"),
        ([(0,)], "pair"),
        ([(0, "nan")], "finite"),
    ]:
        with pytest.raises(ProblemError, match=fragment):
            UnilateralSystem.chain(4, spec)
    with pytest.raises(ProblemError, match="mass must be positive"):
        UnilateralSystem.chain(3, mass=-1)
    with pytest.raises(ProblemError, match="stiffness must be positive"):
        UnilateralSystem.chain(3, stiffness=0)
    with pytest.raises(ProblemError, match="positive integer"):
        UnilateralSystem.chain(0)


def test_one_dof_factory():
    system = UnilateralSystem.one_dof("3/2", a=2, b="1/4")
    assert system.K_exact[0, 0] == sympy.Rational(9, 4)
    assert system.W_exact[0, 0] == 1 and not system.symmetric_coupling
    assert UnilateralSystem.one_dof(1) == UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], b=[0])
    with pytest.raises(ProblemError, match="omega0 must be positive"):
        UnilateralSystem.one_dof(-1)
    with pytest.raises(ProblemError, match="a must be non-zero"):
        UnilateralSystem.one_dof(1, a=0)


def test_chain_modes_match_the_known_closed_form():
    # unit chain with fixed ends: λ_k = 2 sin(kπ/(2(N+1))), φ_k(j) ∝ sin(jkπ/(N+1))
    n = 5
    frequencies, shapes = UnilateralSystem.chain(n).modes()
    k = np.arange(1, n + 1)
    np.testing.assert_allclose(frequencies, 2 * np.sin(k * np.pi / (2 * (n + 1))), rtol=1e-14)
    j = np.arange(1, n + 1)[:, None]
    expected = np.sqrt(2 / (n + 1)) * np.sin(j * k[None, :] * np.pi / (n + 1))
    for column in range(n):  # sign convention: first entry of largest magnitude positive
        magnitudes = np.abs(expected[:, column])
        first = int(np.flatnonzero(magnitudes >= magnitudes.max() * (1 - 1e-9))[0])
        expected[:, column] *= np.sign(expected[first, column])
    np.testing.assert_allclose(shapes, expected, rtol=0, atol=1e-14)


def test_sign_convention_breaks_ties_by_first_index():
    # two equal masses: the antisymmetric mode has entries ±1/√2 (a tie)
    _, shapes = UnilateralSystem.chain(2).modes()
    assert shapes[0, 1] > 0 and shapes[1, 1] < 0


@settings(max_examples=25, deadline=None)
@given(
    st.integers(min_value=1, max_value=5).flatmap(
        lambda n: st.tuples(
            st.just(n),
            st.lists(st.floats(-2, 2), min_size=n * n, max_size=n * n),
            st.lists(st.floats(-2, 2), min_size=n * n, max_size=n * n),
        )
    )
)
def test_modes_are_mass_normalised_and_signed(data):
    n, raw_m, raw_k = data
    B = np.array(raw_m).reshape(n, n)
    C = np.array(raw_k).reshape(n, n)
    M = B @ B.T + n * np.eye(n)
    K = C @ C.T + 0.5 * np.eye(n)
    system = UnilateralSystem(M=(M + M.T) / 2, K=(K + K.T) / 2)
    frequencies, shapes = system.modes()
    assert np.all(np.diff(frequencies) >= 0)
    np.testing.assert_allclose(shapes.T @ system.M @ shapes, np.eye(n), rtol=0, atol=1e-12)
    np.testing.assert_allclose(system.K @ shapes, system.M @ shapes * frequencies**2, rtol=0, atol=1e-11 * np.abs(K).max())
    for column in shapes.T:
        magnitudes = np.abs(column)
        first = int(np.flatnonzero(magnitudes >= magnitudes.max() * (1 - 1e-9))[0])
        assert column[first] > 0


def test_energy_and_acceleration_formulas():
    system = UnilateralSystem.chain(2, [(0, 0.5)])
    x, v, eps = np.array([1.5, -0.5]), np.array([1.0, 2.0]), 3.0
    # by hand: ½(1+4) + ½(2·2.25 − 2·1.5·(−0.5) + 2·0.25) + ½·3·1² = 2.5 + 3.25 + 1.5
    assert system.energy(x, v, eps) == pytest.approx(7.25, rel=1e-15)
    # K x = (3.5, −2.5); contact force 3·1 on mass 0
    np.testing.assert_allclose(system.acceleration(x, eps), [-6.5, 2.5], rtol=1e-15)
    batch = system.energy(np.stack([x, x]), np.stack([v, v]), eps)
    np.testing.assert_allclose(batch, [7.25, 7.25], rtol=1e-15)
    with pytest.raises(ProblemError, match="W = Aᵀ"):
        UnilateralSystem.one_dof(1, a=2).energy([1.0], [0.0], 1.0)
