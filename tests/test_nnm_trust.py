"""A success means the right orbit (issue 22): the NNMs of the code_aster SDND123 two-mass stop system.

``M X'' + K X + ε Aᵀ (A X − b)_+ = 0`` with ``M = I``, ``K = [[2, −1], [−1, 1]]``, stops ``x1 = ±1``
(``A = [[1, 0], [−1, 0]]``, ``b = [1, 1]``) and ε = 30: mode 2's NNM, energies 2.5 … 50.

References, none of them the code under test:

* the continuation of the branch from the linear mode (``continue_nnm`` in energy from E = 1, where the
  NNM is the linear mode exactly), solved at exactly each energy — ``nnm_point``'s default route must reach
  the same orbit (ω to 1e-10) or fail with a reason;
* an independent integration of the ODE by scipy's DOP853 (no code of the package): from the returned
  release state, the state returns after the returned period (to the integrator's own error, estimated by
  the difference of two tolerances) and stays away from the release state over (0.05 T, 0.95 T) (no
  sub-period closes: the period is minimal); the energy is the requested one;
* closed forms: the contact-onset energy ``E_g = ½ λ₂² (b₁ / |φ₂₁|)²`` (the linear mode 2 touches the stop
  at that amplitude; ``φ₂`` from numpy's ``eigh``), the linear frequency ``sqrt(1 + ε)`` of a permanently
  engaged spring, and ``μ + 1/μ = tr Φ − 2`` for the non-trivial Floquet pair of a two-degree-of-freedom
  Hamiltonian orbit (the trivial pair is 1, 1), Φ by central differences of the DOP853 flow.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import lindstedt

M = np.eye(2)
K = np.array([[2.0, -1.0], [-1.0, 1.0]])
A = np.array([[1.0, 0.0], [-1.0, 0.0]])
B = np.array([1.0, 1.0])
EPSILON = 30.0
ENERGIES = [2.5, 3, 4, 5, 10, 15, 20, 27.5, 35, 42, 50]
SYSTEM = lindstedt.UnilateralSystem(M=M.tolist(), K=K.tolist(), A=A.tolist(), b=B.tolist())


def _rhs(t: float, y: np.ndarray) -> np.ndarray:
    x, v = y[:2], y[2:]
    return np.r_[v, -(K @ x + EPSILON * A.T @ np.maximum(A @ x - B, 0.0))]


def _energy(x: np.ndarray, v: np.ndarray) -> float:
    return 0.5 * v @ v + 0.5 * x @ K @ x + 0.5 * EPSILON * float(np.sum(np.maximum(A @ x - B, 0.0) ** 2))


def _integrate(y0: np.ndarray, period: float, rtol: float):
    return solve_ivp(_rhs, (0.0, period), y0, method="DOP853", rtol=rtol, atol=1e-2 * rtol, dense_output=True)


def _distance(y: np.ndarray, y0: np.ndarray, omega: float) -> np.ndarray:
    """max(|X − X0|, |X' − X0'|/ω) / |X0|, column-wise."""
    y = y.reshape(4, -1)
    scale = float(np.max(np.abs(y0[:2])))
    return np.maximum(np.max(np.abs(y[:2] - y0[:2, None]), axis=0),
                      np.max(np.abs(y[2:] - y0[2:, None]), axis=0) / omega) / scale


@pytest.fixture(scope="module")
def continued() -> dict[float, lindstedt.NNMResult]:
    """The continuation's orbit at exactly each energy (from E = 1: the linear mode, below the contact onset)."""
    points = {}
    for energy in ENERGIES:
        branch = lindstedt.continue_nnm(SYSTEM, 2, start=1.0, stop=energy, parameter="energy", epsilon=EPSILON)
        assert branch.success, branch.stop_reason
        points[energy] = branch.points[-1]
    return points


@pytest.fixture(scope="module")
def branch() -> lindstedt.NNMBranch:
    return lindstedt.continue_nnm(SYSTEM, 2, start=1.0, stop=50.0, parameter="energy", epsilon=EPSILON)


def test_default_route_reaches_the_continued_nnm_at_every_energy(continued):
    for energy in ENERGIES:
        result = lindstedt.nnm_point(SYSTEM, EPSILON, 2, energy=energy)
        if not result.success:  # allowed, with a reason — but never a wrong orbit as a success
            assert result.message
            continue
        reference = continued[energy]
        assert result.minimal_periods == 1 and result.minimal_period == result.period
        assert result.frequency == pytest.approx(reference.frequency, rel=1e-10, abs=0), (energy, result.message)
        # independent: DOP853 on the ODE closes the orbit after T, and not before
        y0 = np.r_[result.release_position, result.release_velocity]
        fine, coarse = _integrate(y0, result.period, 1e-12), _integrate(y0, result.period, 1e-10)
        integrator_error = float(_distance(fine.y[:, -1], coarse.y[:, -1], result.frequency)[0])
        closure = float(_distance(fine.y[:, -1], y0, result.frequency)[0])
        assert closure <= max(integrator_error, 1e-11), (energy, closure, integrator_error)
        inside = fine.sol(np.linspace(0.05, 0.95, 2001) * result.period)
        assert float(np.min(_distance(inside, y0, result.frequency))) > 0.1, energy  # no sub-period closes
        assert _energy(result.release_position, result.release_velocity) == pytest.approx(energy, rel=1e-10)
        assert "it is the linear mode" not in result.message  # every one of them touches the stops
        assert result.n_switches == 4


def test_a_multiple_of_the_orbit_is_re_solved_at_its_minimal_period(continued):
    reference = continued[50]
    for guess in ((reference.release_position, 3.0 * reference.period), "linear"):
        result = lindstedt.nnm_point(SYSTEM, EPSILON, 2, energy=50, initial_guess=guess)
        assert result.success and result.minimal_periods == 1, result.message
        assert "run 3 times" in result.message and "T/3" in result.message
        assert result.frequency == pytest.approx(reference.frequency, rel=1e-10, abs=0)


def test_a_collapsed_period_is_a_failure():
    # Newton from the linear mode at E = 2.5 drove T to 3.8e-17 (ω = 1.7e17), once reported as "the linear mode"
    result = lindstedt.nnm_point(SYSTEM, EPSILON, 2, energy=2.5, initial_guess="linear")
    assert not result.success and "degenerate" in result.message and "collapsed" in result.message
    release = [1.3, 0.56]
    short = lindstedt.nnm_point(SYSTEM, EPSILON, 2, energy=2.5, initial_guess=(release, 1e-9), max_iterations=1)
    assert not short.success


def test_permanent_contact_is_not_called_the_linear_mode():
    # u'' + u + ε (u + 1)_+ = 0 near its equilibrium −ε/(1 + ε): engaged all the time, ω = sqrt(1 + ε) exactly
    system = lindstedt.UnilateralSystem.one_dof(1.0, b=-1.0)
    equilibrium = -0.5 / 1.5
    result = lindstedt.nnm_point(system, 0.5, 1, modal_amplitude=equilibrium + 0.2)
    assert result.success and result.n_switches == 0, result.message
    assert result.frequency == pytest.approx(1.5**0.5, rel=1e-12)
    assert "permanent contact" in result.message and "it is the linear mode" not in result.message


def test_the_branch_is_neutrally_stable_without_trivial_multipliers(branch):
    assert branch.success and branch.stability_changes == () and all(branch.stable), branch.stop_reason
    for point in branch.points:
        trivial, nontrivial = point.floquet_multipliers[:2], point.nontrivial_multipliers
        assert np.max(np.abs(trivial - 1.0)) < 1e-5 and len(nontrivial) == 2
        assert np.max(np.abs(np.abs(nontrivial) - 1.0)) < 1e-9  # on the unit circle: neutral, not "unstable"
        # the non-trivial pair from the trace of the whole monodromy (no deflation): μ + 1/μ = tr Φ − 2
        assert float(np.sum(nontrivial).real) == pytest.approx(np.trace(point.monodromy) - 2.0, abs=1e-6)
    # at energies once flagged unstable (31 … 49), the monodromy itself from central differences of DOP853
    checked = [point for point in branch.points if 31 <= point.energy <= 36]
    assert checked
    for point in checked:
        y0 = np.r_[point.release_position, point.release_velocity]
        h = 1e-6 * float(np.max(np.abs(y0)))
        columns = []
        for k in range(4):
            step = np.zeros(4)
            step[k] = h
            plus = _integrate(y0 + step, point.period, 1e-12).y[:, -1]
            minus = _integrate(y0 - step, point.period, 1e-12).y[:, -1]
            columns.append((plus - minus) / (2 * h))
        trace = float(np.trace(np.column_stack(columns)))
        assert abs(trace - 2.0) < 2.0  # μ + 1/μ real in (−2, 2): the non-trivial pair is on the unit circle
        assert trace == pytest.approx(np.trace(point.monodromy), abs=1e-4)


def test_the_contact_onset_is_resolved_and_named(branch):
    frequencies, shapes = np.linalg.eigh(K)  # M = I
    lam2, phi2 = float(np.sqrt(frequencies[1])), shapes[:, 1]
    onset = 0.5 * lam2**2 * (B[0] / abs(phi2[0])) ** 2  # the linear mode 2 touches x1 = ±1 at this energy
    assert onset == pytest.approx(1.809016994, rel=1e-9)
    energies = branch.parameter_values
    assert branch.jumps == () and "resonance" not in branch.stop_reason and "tongue" not in branch.stop_reason
    assert "contact change" in branch.stop_reason
    assert len(branch.contact_changes) == 1
    k = branch.contact_changes[0]
    assert energies[k] <= onset <= energies[k + 1] and energies[k + 1] - energies[k] < 0.02
    assert branch.points[k].n_switches == 0 and branch.points[k + 1].n_switches == 4
    # the steep part right after the onset (ω from λ₂ = 1.618 to 1.8 within ΔE ≈ 0.2) carries points
    steep = [(e, w) for e, w in zip(energies, branch.frequencies) if onset < e < 1.95]
    assert len(steep) >= 5
    assert max(np.diff([w for _, w in steep])) < 0.06


def test_the_steep_part_is_followed_in_the_modal_amplitude_too():
    # with u_2(0) fixed, the tangent after the contact onset is mostly mode 1 while the period changes fast: a steep
    # backbone, not a tongue (there the period is locked) — it was jumped, landing on an ω = 0.43 or 0.87 orbit
    for stop in (2.0, 3.0):
        branch = lindstedt.continue_nnm(SYSTEM, 2, start=0.5, stop=stop, parameter="modal_amplitude", epsilon=EPSILON)
        assert branch.success and branch.jumps == () and len(branch.contact_changes) == 1, branch.stop_reason
        end = branch.points[-1]
        assert end.frequency > 1.62 and end.n_switches == 4 and end.mode_share > 0.9
        alone = lindstedt.nnm_point(SYSTEM, EPSILON, 2, modal_amplitude=stop)
        assert alone.success and alone.frequency == pytest.approx(end.frequency, rel=1e-10, abs=0), alone.message
        y0 = np.r_[end.release_position, end.release_velocity]
        closure = float(_distance(_integrate(y0, end.period, 1e-12).y[:, -1], y0, end.frequency)[0])
        assert closure < 1e-9
