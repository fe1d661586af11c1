"""NLvib example 02 reproduced: a forced two-mass chain with two cubic springs (issue 25, item 6).

``M X'' + C X' + K X + k₁ (x₁)³ e₁ + k₂ (x₁ − x₂)³ (e₁ − e₂) = F cos(Ω t)`` with NLvib's chain data
(``benchmarks/peers/cases.json``, nothing retyped): masses (1, 0.05), springs (1, 0.0453, 0), dampers
(0.002, 0.013, 0), cubic springs k₁ = 1 (mass 1 to the ground) and k₂ = 0.0042 (between the masses),
F = (0.11, 0), Ω from 0.8 to 1.4.  In lindstedt's form ``… + ε Σ w_i f_i(a_i·X) = ε P cos(Ω t)`` it is
ε = 1, W = Aᵀ (NLvib's force acts along the element's direction), f₁ = u³, f₂ = 0.0042 u³, P = F: the same
equation, no scaling.

NLvib computes the branch by harmonic balance (H = 7, N = 4H + 1 samples) and by shooting, and marks its turning
points and Neimark–Sacker points from Floquet multipliers; its script prints no number.  The Python port's
comparison notebook prints the peaks of NLvib's (run under Octave) HB curve and its own (cases.json,
``peer_numbers``).  References here, none of them the code under test:

* the ODE written out by hand from the matrices and integrated by scipy's DOP853 (the orbits' closure, long runs,
  jumps past the folds, the Fourier coefficients the peer's amplitude is made of);
* its variational equations, written out by hand (the Jacobian of the cubic forces), for the Floquet multipliers.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lindstedt

CASE = json.loads((Path(__file__).resolve().parents[1] / "benchmarks" / "peers" / "cases.json").read_text())["cases"][
    "nlvib_02_cubic_spring"]
DATA, MODEL = CASE["peer_data"], CASE["system"]
PEER = {number["name"]: number for number in CASE["peer_numbers"]}

M = np.asarray(MODEL["M"], dtype=float)
K = np.asarray(MODEL["K"], dtype=float)
C = np.asarray(MODEL["C"], dtype=float)
F = np.asarray(MODEL["load"], dtype=float)
DIRECTIONS = np.asarray([element["a"] for element in MODEL["elements"]], dtype=float)
STIFFNESSES = np.asarray([element["coefficient"] for element in MODEL["elements"]], dtype=float)
M_INV = np.linalg.inv(M)


def _exact(matrix: list) -> list:
    """Decimal entries as strings, so that lindstedt reads them exactly (0.05 → 1/20)."""
    return [_exact(row) for row in matrix] if isinstance(matrix, list) else str(matrix)


SYSTEM = lindstedt.UnilateralSystem(
    M=_exact(MODEL["M"]), K=_exact(MODEL["K"]), A=[element["a"] for element in MODEL["elements"]],
    b=[element["b"] for element in MODEL["elements"]],
    laws=[f"{element['coefficient']}*u**3" for element in MODEL["elements"]])
FORCED = lindstedt.ForcedSystem(SYSTEM, load=_exact(MODEL["load"]), C=_exact(MODEL["C"]))
EPSILON = float(MODEL["epsilon"])


# ------------------------------------------------------------------------------------------- the reference ODE
def _rhs(t: float, y: np.ndarray, omega: float) -> np.ndarray:
    x, v = y[:2], y[2:]
    stretch = DIRECTIONS @ x
    return np.r_[v, M_INV @ (F * np.cos(omega * t) - K @ x - C @ v - DIRECTIONS.T @ (STIFFNESSES * stretch**3))]


def _rhs_variational(t: float, y: np.ndarray, omega: float) -> np.ndarray:
    stretch = DIRECTIONS @ y[:2]
    tangent = K + DIRECTIONS.T @ np.diag(3.0 * STIFFNESSES * stretch**2) @ DIRECTIONS
    jacobian = np.block([[np.zeros((2, 2)), np.eye(2)], [-M_INV @ tangent, -M_INV @ C]])
    return np.r_[_rhs(t, y[:4], omega), (jacobian @ y[4:].reshape(4, 4)).ravel()]


def _run(z0: np.ndarray, omega: float, periods: float, rtol: float = 1e-12, samples=None) -> np.ndarray:
    """DOP853 over ``periods`` forcing periods: the end state, or the states after the periods in ``samples``."""
    period = 2.0 * np.pi / omega
    times = None if samples is None else period * np.asarray(samples, dtype=float)
    run = solve_ivp(_rhs, (0.0, periods * period), np.asarray(z0, dtype=float), args=(omega,), method="DOP853",
                    rtol=rtol, atol=1e-2 * rtol, t_eval=times)
    assert run.success, run.message
    return run.y[:, -1] if samples is None else run.y


def _multipliers(z0: np.ndarray, omega: float) -> np.ndarray:
    """Floquet multipliers from the hand-written variational equations, by decreasing modulus."""
    run = solve_ivp(_rhs_variational, (0.0, 2.0 * np.pi / omega), np.r_[z0, np.eye(4).ravel()], args=(omega,),
                    method="DOP853", rtol=1e-12, atol=1e-14)
    multipliers = np.linalg.eigvals(run.y[4:, -1].reshape(4, 4))
    return multipliers[np.argsort(-np.abs(multipliers))]


def _closure(z0: np.ndarray, omega: float) -> tuple[float, float]:
    """(|z(T) − z0|, the integrator's own error: rtol 1e-12 against 1e-10) over one period."""
    fine, coarse = _run(z0, omega, 1), _run(z0, omega, 1, rtol=1e-10)
    return float(np.max(np.abs(fine - z0))), float(np.max(np.abs(fine - coarse)))


def _assert_closes(orbit) -> None:
    """The orbit's state comes back after one period of the independent integration, to what its Newton was asked
    (``|Π(z0) − z0| ≤ 1e-10 |z0|``, the default ``tol``) plus the integrator's own error; and the residual the
    package reports is the one measured here."""
    closure, error = _closure(orbit.state, orbit.frequency)
    size = float(np.max(np.abs(orbit.state)))
    assert closure <= 1e-10 * size + error, (orbit.frequency, closure, error)
    assert abs(closure - orbit.residual * size) <= error + 1e-13, (orbit.frequency, closure, orbit.residual)


def _a_rms(z0: np.ndarray, omega: float, harmonics: int = 7, samples: int = 256) -> tuple[np.ndarray, np.ndarray]:
    """NLvib's amplitude ``sqrt(Q0² + Σ_{k≤H} (Qc_k² + Qs_k²))/√2`` of each dof (its script: a_rms_HB) and the
    moduli |Q_k|, k = 1..H, from the Fourier coefficients of one DOP853 period sampled ``samples`` times."""
    period = 2.0 * np.pi / omega
    times = period * np.arange(samples) / samples
    run = solve_ivp(_rhs, (0.0, period), z0, args=(omega,), method="DOP853", rtol=1e-12, atol=1e-14, t_eval=times)
    coefficients = np.fft.rfft(run.y[:2], axis=1) / samples
    moduli = 2.0 * np.abs(coefficients[:, 1:harmonics + 1])
    return np.sqrt(np.abs(coefficients[:, 0]) ** 2 + np.sum(moduli**2, axis=1)) / np.sqrt(2.0), moduli


def _orbit(omega: float, guess=None) -> lindstedt.ForcedOrbit:
    orbit = lindstedt.forced_periodic_orbit(FORCED, omega, epsilon=EPSILON, initial_state=guess)
    assert orbit.success, orbit.message
    return orbit


# ------------------------------------------------------------------------------------------------ the model
def test_nlvib02_the_model_is_nlvib_s_chain():
    # NLvib's ChainOfOscillators (lines 41-45): M = diag(m), K and D tridiagonal from k, d with k(1) to the ground
    # at mass 1 and k(end) at the last mass; assembled here from the peer's own data
    m, k, d = (np.asarray(DATA[name]["value"], dtype=float) for name in ("mi", "ki", "di"))

    def tridiagonal(s: np.ndarray) -> np.ndarray:
        return np.array([[s[0] + s[1], -s[1]], [-s[1], s[1] + s[2]]])

    np.testing.assert_array_equal(M, np.diag(m))
    np.testing.assert_allclose(K, tridiagonal(k), rtol=0, atol=1e-16)
    np.testing.assert_allclose(C, tridiagonal(d), rtol=0, atol=1e-16)
    np.testing.assert_array_equal(F, np.asarray(DATA["Fex1"]["value"], dtype=float))
    # lindstedt's problem is the same equation: exact matrices, and the elements' forces at random positions
    assert SYSTEM.M_exact[1, 1] == lindstedt.UnilateralSystem(M=[["1/20"]], K=[[1]]).M_exact[0, 0]
    np.testing.assert_allclose(FORCED.C, C, rtol=1e-16)
    np.testing.assert_array_equal(FORCED.P, F)
    elements = DATA["nonlinear_elements"]["value"]
    rng = np.random.default_rng(2)
    for x in rng.normal(size=(5, 2)):
        force = sum(e["stiffness"] * np.dot(e["direction"], x) ** 3 * np.asarray(e["direction"], dtype=float)
                    for e in elements)
        np.testing.assert_allclose(SYSTEM.acceleration(x, EPSILON), -M_INV @ (K @ x + force), rtol=1e-13, atol=1e-15)


# ----------------------------------------------------------------------------------------- the peer numbers
def _bracket(omega: float) -> tuple[np.ndarray, np.ndarray]:
    """The exact a_rms of both dofs (shape (3, 2)) and |Q_k| (shape (3, 2, 7)) at ω − 5e-5, ω, ω + 5e-5 (the peer
    prints Ω to 4 decimals), each from an orbit that closes under the independent integration."""
    guess, a_rms, moduli = None, [], []
    for frequency in (omega - 5e-5, omega, omega + 5e-5):
        orbit = _orbit(frequency, guess)
        guess = orbit.state
        _assert_closes(orbit)
        values = _a_rms(orbit.state, frequency)
        a_rms.append(values[0])
        moduli.append(values[1])
    return np.array(a_rms), np.array(moduli)


def _assert_printed(peer: float, exact: np.ndarray) -> None:
    """The peer's number, printed to 5 decimals at an Ω printed to 4, is the exact value at an Ω within the rounding:
    between the exact values at ω ± 5e-5 (monotone there: the value at ω lies between them), give or take 5e-6."""
    low, value, high = min(exact[0], exact[2]), exact[1], max(exact[0], exact[2])
    assert low <= value <= high
    assert low - 5e-6 <= peer <= high + 5e-6, (peer, low, value, high)


def test_nlvib02_nlvib_s_peak_is_the_exact_response_to_the_digits_it_prints():
    # NLvib's (Octave) HB peak of dof 1: a_rms = 0.41849 at its continuation point Ω = 1.0278, and the harmonics
    # |Q1|, |Q3|, |Q5| there; printed to 5 decimals, Ω to 4. The exact periodic response at that Ω, within the
    # printed rounding: the HB truncation at H = 7 (the neglected |Q9| ≈ 1.4e-8) is below the printed digits.
    peak = PEER["a_rms x1 at NLvib's peak (NLvib HB, Octave)"]
    a_rms, moduli = _bracket(peak["Omega"])
    _assert_printed(peak["value"], a_rms[:, 0])
    for k in (1, 3, 5):
        _assert_printed(PEER[f"|Q{k}| of x1 at NLvib's peak (NLvib HB, Octave)"]["value"], moduli[:, 0, k - 1])
    assert moduli[1, 0, 6] < 1e-5 and np.max(moduli[1, 0, 1::2]) < 1e-12  # |Q7| below the digits; no even harmonic


@pytest.mark.slow  # ~1.5 s: the other peer numbers, each bracketed by three exact orbits
def test_nlvib02_the_other_peer_peaks_are_the_exact_response_to_the_digits_printed():
    for name, dof in (("a_rms x2 at NLvib's peak (NLvib HB, Octave)", 1),
                      ("a_rms x1 at the port's peak (NLvib-py HB)", 0),
                      ("a_rms x2 at the port's peak (NLvib-py HB)", 1)):
        _assert_printed(PEER[name]["value"], _bracket(PEER[name]["Omega"])[0][:, dof])


# ------------------------------------------------------------------------------------------- the branch
@pytest.fixture(scope="module")
def nlvib02() -> lindstedt.FrequencyResponse:
    response = lindstedt.frequency_response(FORCED, *MODEL["Omega"], epsilon=EPSILON)
    assert response.success, response.message
    return response


def _kinds(response: lindstedt.FrequencyResponse, kind: str) -> list:
    return [b for b in response.bifurcations if b.kind == kind]


@pytest.mark.slow  # ~5 s for the branch (shared by the tests below), ~1 s here
def test_nlvib02_the_folds_and_neimark_sacker_points_nlvib_shows(nlvib02):
    folds, ns = _kinds(nlvib02, "fold"), _kinds(nlvib02, "neimark-sacker")
    assert len(folds) == 2 and len(ns) == 2 and len(nlvib02.bifurcations) == 4  # no period doubling
    upper, lower = folds  # in branch order: the branch turns back at the upper fold, forward at the lower one
    assert lower.frequency < upper.frequency
    assert ns[0].frequency < ns[1].frequency < lower.frequency
    omegas = np.asarray(nlvib02.frequencies)
    assert omegas[: upper.index + 1].max() <= upper.frequency and omegas[upper.index + 1: lower.index + 1].min() >= lower.frequency
    # at each located point, independently: the state closes (to the corrector's 1e-10, relative), and the hand-written variational equations give a
    # multiplier +1 (fold) or a complex pair of modulus 1 (Neimark–Sacker); the others inside the unit circle
    for point in nlvib02.bifurcations:
        closure, error = _closure(point.state, point.frequency)
        assert closure <= 1e-10 * np.max(np.abs(point.state)) + error, (point.kind, closure, error)
        mu = _multipliers(point.state, point.frequency)
        if point.kind == "fold":
            assert abs(mu[0] - 1.0) < 1e-6 and abs(mu[1]) < 0.7, (point.frequency, mu)
        else:
            assert abs(abs(mu[0]) - 1.0) < 1e-6 and abs(mu[0].imag) > 0.4 and abs(mu[2]) < 0.5, (point.frequency, mu)


@pytest.mark.slow  # ~2 s: 40 orbits closed at two tolerances and their multipliers
def test_nlvib02_every_orbit_closes_and_its_stability_is_the_independent_one(nlvib02):
    unstable = []
    for point in nlvib02.points:
        _assert_closes(point)
        mu = _multipliers(point.state, point.frequency)
        np.testing.assert_allclose(np.sort_complex(point.multipliers), np.sort_complex(mu), atol=1e-8)
        assert point.stable is bool(abs(mu[0]) < 1.0), point.frequency
        if not point.stable:
            unstable.append(point.frequency)
    # unstable exactly between the Neimark–Sacker points and on the middle part between the folds
    (ns1, ns2), (upper, lower) = _kinds(nlvib02, "neimark-sacker"), _kinds(nlvib02, "fold")
    expected = [p.frequency for k, p in enumerate(nlvib02.points)
                if ns1.index < k <= ns2.index or upper.index < k <= lower.index]
    assert unstable == expected and len(expected) >= 5


@pytest.mark.slow  # ~7 s: 3 orbits, 2 long runs off the saddle, 100-period runs on the stable ones
def test_nlvib02_three_responses_coexist_between_the_folds_one_a_saddle(nlvib02):
    upper, lower = _kinds(nlvib02, "fold")
    omega = 0.5 * (upper.frequency + lower.frequency)
    guesses = [nlvib02.states[upper.index], nlvib02.states[(upper.index + lower.index + 1) // 2],
               nlvib02.states[lower.index + 1]]
    orbits = [_orbit(omega, guess) for guess in guesses]
    states = np.array([orbit.state for orbit in orbits])
    assert min(np.max(np.abs(states[i] - states[j])) for i, j in ((0, 1), (1, 2), (0, 2))) > 0.05  # three distinct
    multipliers = [_multipliers(state, omega) for state in states]
    assert [bool(abs(mu[0]) < 1) for mu in multipliers] == [True, False, True]
    saddle = multipliers[1]
    assert abs(saddle[0].imag) < 1e-12 and saddle[0].real > 1.05 and abs(saddle[1]) < 1  # one real multiplier > 1
    for state in states[[0, 2]]:  # the stable ones: 100 periods from the orbit come back to it
        # the error of one period (closure + integrator error ≲ 3e-11 here) contracts (|μ| ≤ 0.88): the sum
        # over the run stays ≪ 1e-9
        assert np.max(np.abs(_run(state, omega, 100) - state)) < 1e-9
    # off the saddle along its unstable direction (of the monodromy from the variational equations): one side
    # lands on the upper response, the other on the lower one — the jump the folds bound
    run = solve_ivp(_rhs_variational, (0.0, 2 * np.pi / omega), np.r_[states[1], np.eye(4).ravel()], args=(omega,),
                    method="DOP853", rtol=1e-12, atol=1e-14)
    values, vectors = np.linalg.eig(run.y[4:, -1].reshape(4, 4))
    direction = np.real(vectors[:, np.argmax(np.abs(values))])
    ends = [_run(states[1] + sign * 1e-6 * direction / np.max(np.abs(direction)), omega, 400, rtol=1e-10)
            for sign in (1, -1)]
    distances = sorted(min(np.max(np.abs(end - states[i])) for end in ends) for i in (0, 2))
    assert distances[1] < 1e-6, distances  # each stable response reached from one side
    assert np.max(np.abs(ends[0] - ends[1])) > 0.05


@pytest.mark.slow  # ~5 s: two 400-period runs
def test_nlvib02_past_each_fold_the_response_jumps(nlvib02):
    # 3e-3 past a fold the branch there no longer exists: from the orbit at the fold the motion goes to the one
    # response left (the lower one past the upper fold, the upper one past the lower fold)
    upper, lower = _kinds(nlvib02, "fold")
    for fold, step, target_guess in ((upper, 3e-3, nlvib02.states[-4]), (lower, -3e-3, nlvib02.states[upper.index])):
        omega = fold.frequency + step
        target = _orbit(omega, target_guess)
        assert target.stable and np.max(np.abs(target.state - fold.state)) > 0.05
        end = _run(fold.state, omega, 400, rtol=1e-10)
        assert np.max(np.abs(end - target.state)) < 1e-6, (omega, np.max(np.abs(end - target.state)))


@pytest.mark.slow  # ~2 s
def test_nlvib02_between_the_neimark_sacker_points_the_response_is_not_periodic(nlvib02):
    ns1, ns2 = _kinds(nlvib02, "neimark-sacker")
    omega = 0.5 * (ns1.frequency + ns2.frequency)
    orbit = _orbit(omega, nlvib02.states[ns1.index + 1])
    mu = _multipliers(orbit.state, omega)
    assert abs(mu[0]) > 1.02 and abs(mu[0].imag) > 0.1 and abs(mu[1]) == pytest.approx(abs(mu[0]), rel=1e-9)
    # independent: a run from the orbit perturbed by 1e-6 leaves it and never settles on a periodic response
    # (sampled once a period, the state keeps moving: a torus, not a fixed point of the period map)
    states = _run(orbit.state + 1e-6, omega, 300, rtol=1e-10, samples=np.arange(260, 301))
    assert np.min(np.max(np.abs(states - orbit.state[:, None]), axis=0)) > 1e-2
    assert np.min(np.max(np.abs(np.diff(states, axis=1)), axis=0)) > 1e-3
