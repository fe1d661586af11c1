"""NNMs by shooting for systems whose elements carry any law (issue 25, item 3: numerics for every law).

``M X'' + K X + ε Σ_i w_i f_i(a_iᵀ X − b_i) = 0`` with cubic springs (at a dof and on a relative displacement),
Hertz contacts ``Max(0, u)**(3/2)``, a law that jumps (``Heaviside``) and a prestressed element.  The shooting
flows through DOP853 with its variational equations.  References, none of them the code under test:

* the exact period of the Duffing oscillator ``x'' + w² x + c x³ = 0`` released at rest from ``a``:
  ``ω = π √(w² + c a²) / (2 K(m))``, ``m = c a² / (2 (w² + c a²))`` (complete elliptic integral, mpmath);
* the energy integral ``T = 2 ∫ dx / √(2 (V(x_r) − V(x)))`` between the turning points, by mpmath's tanh-sinh
  quadrature at 30 digits (Hertz, prestressed cubic);
* the closed-form period of the piecewise-constant law (``ε H(x − b)``: two circular arcs);
* an integration of the ODE written out here by scipy's DOP853 (a system with no reduction to one dof);
* symmetric chains whose in-phase and anti-phase modes reduce exactly to one degree of freedom.

The shooting's own tolerance: DOP853 at rtol 1e-12 over one period, Newton to 1e-10 on the scaled residual; the
periods below agree with the references to 1e-15…1e-13 (measured), asserted at 1e-10.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from lindstedt import UnilateralSystem
from lindstedt.numerics import continue_nnm, nnm_energy, nnm_point

#: relative agreement asserted between a shot period and its reference (measured 1e-15…1e-13, see the docstring)
RTOL = 1e-10


def _duffing_frequency(w2: float, c: float, amplitude: float) -> float:
    """The exact ω of x'' + w² x + c x³ = 0 from rest at x = amplitude (hardening, c ≥ 0)."""
    with mpmath.workdps(30):
        k = mpmath.mpf(w2) + mpmath.mpf(c) * mpmath.mpf(amplitude) ** 2
        m = mpmath.mpf(c) * mpmath.mpf(amplitude) ** 2 / (2 * k)
        return float(mpmath.pi * mpmath.sqrt(k) / (2 * mpmath.ellipk(m)))


def _energy_integral_period(potential, release: float, other_side: float, kinks: tuple[float, ...] = ()) -> float:
    """T = 2 ∫ dx / √(2 (V(release) − V(x))) between the turning points (the other one found from ``other_side``),
    by tanh-sinh at 30 digits, split at the kinks of V'' (|·| guards the rounding at the turning points)."""
    with mpmath.workdps(30):
        level = potential(mpmath.mpf(release))
        lower = mpmath.findroot(lambda x: potential(x) - level, mpmath.mpf(other_side))
        nodes = [lower, *(mpmath.mpf(k) for k in kinks if lower < k < release), mpmath.mpf(release)]
        return float(2 * mpmath.quad(lambda x: 1 / mpmath.sqrt(abs(2 * (level - potential(x)))), nodes))


@pytest.mark.parametrize("epsilon", [0.01, 0.3, pytest.param(3.0, marks=pytest.mark.slow)])  # 3.0: by continuation
def test_the_nnm_of_a_cubic_spring_is_the_elliptic_closed_form(epsilon):
    system = UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], laws=["u**3"])
    orbit = nnm_point(system, epsilon, 1, modal_amplitude=1.0)
    assert orbit.success, orbit.message
    assert orbit.frequency == pytest.approx(_duffing_frequency(1.0, epsilon, 1.0), rel=RTOL)
    assert orbit.energy == pytest.approx(0.5 + epsilon / 4, rel=1e-14)  # ½ x² + ε x⁴/4 at the release point
    assert orbit.n_switches == 0 and orbit.contact_springs == ()
    assert "it is the linear mode" not in orbit.message  # a cubic spring acts without contact: no such claim


def test_an_energy_amplitude_uses_the_potential_of_the_law():
    epsilon, energy = 0.8, 0.6
    system = UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], laws=["u**3"])
    orbit = nnm_point(system, epsilon, 1, energy=energy)
    assert orbit.success, orbit.message
    amplitude = math.sqrt((-1 + math.sqrt(1 + 4 * epsilon * energy)) / epsilon)  # ½ a² + ε a⁴/4 = E
    assert float(orbit.release_position[0]) == pytest.approx(amplitude, rel=RTOL)
    assert orbit.frequency == pytest.approx(_duffing_frequency(1.0, epsilon, amplitude), rel=RTOL)
    assert nnm_energy(system, [amplitude], [0.0], epsilon) == pytest.approx(energy, rel=1e-14)


def test_cubic_springs_at_the_dofs_and_between_them_act_on_the_modes_they_deform():
    """Ground–mass–mass–ground chain of unit springs with cubic springs x1³, x2³ and (x1 − x2)³: the in-phase mode
    x1 = x2 = x is x'' + x + ε x³ = 0 (the relative element is idle), the anti-phase mode x1 = −x2 = x is
    x'' + 3x + 9ε x³ = 0 (the relative element sees 2x: (2x)³ = 8x³ more).  Modal amplitude 1 is x = 1/√2."""
    system = UnilateralSystem(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], A=[[1, 0], [0, 1], [1, -1]],
                              laws=["u**3", "u**3", "u**3"])
    x = 1 / math.sqrt(2)
    in_phase = nnm_point(system, 0.3, 1, modal_amplitude=1.0)
    assert in_phase.success, in_phase.message
    assert in_phase.frequency == pytest.approx(_duffing_frequency(1.0, 0.3, x), rel=RTOL)
    np.testing.assert_allclose(in_phase.release_position, [x, x], rtol=1e-12)
    branch = continue_nnm(system, 2, modal_amplitude=1.0, start=0.0, stop=3.0)
    assert branch.success and len(branch.points) > 5, branch
    for point in branch.points:
        assert point.frequency == pytest.approx(_duffing_frequency(3.0, 9 * point.epsilon, x), rel=RTOL)
        # conservative and reversible: the non-trivial pair is on the unit circle
        assert np.max(np.abs(np.abs(point.floquet_multipliers) - 1.0)) < 1e-6
    assert branch.points[-1].epsilon == 3.0


@pytest.mark.parametrize("epsilon", [0.01, 0.5, 3.0])
def test_the_nnm_of_a_hertz_contact_is_the_energy_integral(epsilon):
    """x'' + x + ε x_+^(3/2) = 0 from rest at x = 1; V = x²/2 + (2/5) ε x_+^(5/2)."""
    system = UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], laws=["Max(0, u)**(3/2)"])
    orbit = nnm_point(system, epsilon, 1, modal_amplitude=1.0)
    assert orbit.success, orbit.message

    def potential(x):
        return x**2 / 2 + (mpmath.mpf(2) / 5 * epsilon * x ** mpmath.mpf(2.5) if x > 0 else 0)

    assert orbit.period == pytest.approx(_energy_integral_period(potential, 1.0, -1.0, (0.0,)), rel=RTOL)
    assert orbit.n_switches == 2 and orbit.contact_springs == (0,)


def test_hertz_contacts_on_both_masses_of_a_symmetric_chain_reduce_to_one_dof():
    system = UnilateralSystem(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], A=[[1, 0], [0, 1]],
                              laws=["Max(0, u)**(3/2)", "Max(0, u)**(3/2)"])
    orbit = nnm_point(system, 0.5, 1, modal_amplitude=1.0)
    assert orbit.success, orbit.message
    x = 1 / math.sqrt(2)

    def potential(y):
        return y**2 / 2 + (mpmath.mpf(2) / 5 * mpmath.mpf(0.5) * y ** mpmath.mpf(2.5) if y > 0 else 0)

    assert orbit.period == pytest.approx(_energy_integral_period(potential, x, -x, (0.0,)), rel=RTOL)


@pytest.mark.parametrize("epsilon", [0.01, 0.1, 0.5])
def test_a_law_that_jumps_crosses_its_breakpoint_through_the_saltation(epsilon):
    """x'' + x + ε H(x − 1/5) = 0 from rest at x = 1: a circle about −ε while x > 1/5, about 0 below."""
    system = UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], b=["1/5"], laws=["Heaviside(u)"])
    orbit = nnm_point(system, epsilon, 1, modal_amplitude=1.0)
    assert orbit.success, orbit.message
    a, b = 1.0, 0.2
    above = math.acos((b + epsilon) / (a + epsilon))  # time from the release to x = b
    radius = math.hypot(b, (a + epsilon) * math.sin(above))
    period = 2 * above + 2 * math.pi - 2 * math.acos(b / radius)
    assert orbit.period == pytest.approx(period, rel=RTOL)
    assert orbit.n_switches == 2
    # one dof: only the trivial pair, both at 1 (the monodromy through two saltation matrices)
    np.testing.assert_allclose(orbit.floquet_multipliers, [1.0, 1.0], atol=1e-6)


def test_a_prestressed_element_oscillates_about_its_static_equilibrium():
    """x'' + x + ε (x − 1)³ = 0: the rest state is the real root of x + ε(x − 1)³; released at rest from 0.8."""
    epsilon, release = 1.0, 0.8
    system = UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], b=[1], laws=["u**3"])
    orbit = nnm_point(system, epsilon, 1, modal_amplitude=release)
    assert orbit.success, orbit.message

    def potential(x):
        return x**2 / 2 + epsilon * (x - 1) ** 4 / 4

    assert orbit.period == pytest.approx(_energy_integral_period(potential, release, 0.0), rel=RTOL)


@pytest.mark.slow  # a continuation and two long DOP853 runs (3 s)
def test_an_orbit_of_a_system_without_reduction_closes_under_an_independent_integration():
    """Three masses, a cubic spring between masses 1 and 2 and a Hertz contact at mass 3 with a gap."""
    M = np.diag([1.0, 2.0, 1.0])
    K = np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.5]])
    system = UnilateralSystem(M=M.tolist(), K=K.tolist(), A=[[1, -1, 0], [0, 0, 1]], b=[0, "1/10"],
                              laws=["u**3", "Max(0, u)**(3/2)"])
    epsilon = 0.7
    branch = continue_nnm(system, 1, modal_amplitude=1.0, start=0.0, stop=epsilon)
    assert branch.success, branch
    orbit = branch.points[-1]
    assert orbit.epsilon == epsilon and orbit.success

    def rhs(t, y):
        x, v = y[:3], y[3:]
        stretch, contact = x[0] - x[1], max(x[2] - 0.1, 0.0)
        force = K @ x + epsilon * (stretch**3 * np.array([1.0, -1.0, 0.0]) + contact**1.5 * np.array([0, 0, 1.0]))
        return np.r_[v, -np.linalg.solve(M, force)]

    start = np.r_[orbit.release_position, orbit.release_velocity]
    ends = [solve_ivp(rhs, (0.0, orbit.period), start, method="DOP853", rtol=rtol, atol=rtol * 1e-2).y[:, -1]
            for rtol in (1e-12, 1e-10)]
    integrator_error = float(np.max(np.abs(ends[0] - ends[1])))  # the coarser run's error bounds the finer one's
    assert integrator_error < 1e-8
    assert np.max(np.abs(ends[0] - start)) <= 10 * integrator_error + 1e-11
    assert orbit.contact_springs == (1,)  # the Hertz contact opens and closes; the cubic spring has no breakpoint


def test_the_cli_shoots_the_nnm_of_a_system_file_with_laws(tmp_path, capsys):
    import json

    from lindstedt.cli import main

    path = tmp_path / "system.json"
    path.write_text(json.dumps({"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]], "A": [[1, 0], [0, 1], [1, -1]],
                                "laws": ["u**3", "u**3", "u**3"]}))
    code = main(["nnm", str(path), "--mode", "2", "--a0", "1", "--numeric", "--eps", "3/10", "--format", "json"])
    assert code == 0
    result = json.loads(capsys.readouterr().out)
    assert result["success"]
    assert result["frequency"] == pytest.approx(_duffing_frequency(3.0, 9 * 0.3, 1 / math.sqrt(2)), rel=RTOL)


@pytest.mark.parametrize("laws", [["Max(0, u - 1/5) - Max(0, -u - 1/5)"], ["2*Max(0, u - 1/10) + 3*Max(0, u - 1/2)"],
                                  ["u/2 + Max(0, u)/2"], ["Min(0, u)"], ["u + 1"]])
def test_continuous_piecewise_linear_laws_are_sums_of_unilateral_springs(laws):
    """ramp_equivalent: the same forces with unilateral springs only (checked at random states, both written out)."""
    system = UnilateralSystem(M=[[1, 0], [0, 2]], K=[[3, -1], [-1, 2]], A=[[1, -1]], b=["1/10"], W=[[2], [-1]],
                              laws=laws)
    equivalent, elements = system.ramp_equivalent
    assert equivalent.unilateral and set(elements) == {0}
    positions = np.random.default_rng(7).normal(size=(40, 2))
    np.testing.assert_allclose(equivalent.acceleration(positions, 0.7), system.acceleration(positions, 0.7),
                               rtol=0, atol=1e-14)


@pytest.mark.parametrize("laws", [["Heaviside(u)"], ["Max(0, u)**2"], ["u**3"], ["Max(0, u) + 1"]])
def test_laws_that_are_not_sums_of_springs_have_no_ramp_form(laws):
    system = UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], laws=laws)  # a jump, a curve, a constant load
    assert system.ramp_equivalent is None


@pytest.mark.parametrize("epsilon", [0.3, 2.0])
def test_a_dead_zone_is_shot_on_the_exact_flow_to_its_closed_form_period(epsilon):
    """x'' + x + ε [(x − g)_+ − (−x − g)_+] = 0 from rest at a > g: about x* = εg/(1 + ε) at ω = √(1 + ε) until
    x = g (time t1), then free to x = 0 (time t2): T = 4 (t1 + t2) (the law is odd)."""
    g, a = 0.2, 1.0
    system = UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], laws=["Max(0, u - 1/5) - Max(0, -u - 1/5)"])
    orbit = nnm_point(system, epsilon, 1, modal_amplitude=a)
    assert orbit.success, orbit.message
    omega, centre = math.sqrt(1 + epsilon), epsilon * g / (1 + epsilon)
    t1 = math.acos((g - centre) / (a - centre)) / omega
    speed = (a - centre) * omega * math.sin(omega * t1)
    period = 4 * (t1 + math.atan(g / speed))
    assert orbit.period == pytest.approx(period, rel=1e-13)  # the exact flow: rounding only (DOP853: ~1e-13)
    assert orbit.n_switches == 4 and orbit.contact_springs == (0,)


def test_a_forced_system_with_a_dead_zone_runs_on_the_exact_flow():
    from lindstedt import ForcedSystem
    from lindstedt.numerics import forced_flow

    system = UnilateralSystem(M=[[1, 0], [0, 2]], K=[[3, -1], [-1, 2]], A=[[1, -1]],
                              laws=["Max(0, u - 1/5) - Max(0, -u - 1/5)"])
    assert type(forced_flow(ForcedSystem(system, [1, 0], rayleigh=(0, "1/50")), 0.5)).__name__ == "ForcedFlow"
    assert type(forced_flow(ForcedSystem(UnilateralSystem(M=[[1]], K=[[1]], A=[[1]], laws=["u**3"]), [1]), 0.5)
                ).__name__ == "SmoothForcedFlow"
