"""Non-polynomial contact laws on the branch engine's stretched contact arcs (issue 12): fractional powers
(Hertz contact c (u − b)_+^{3/2}) and analytic laws (c (u − b)_+ e^u) on an arc that holds a turning point.

References, none of them the code under test:

* ω1 from the first-order averaging integral, in closed form for u_+^{3/2}, a0 = ω0 = 1:
  ω1 = (1/2π) ∫_{−π/2}^{π/2} cos^{5/2} s ds = Γ(7/4) / (2 √π Γ(9/4));
* the exact scaling of u_+^{3/2}: with u = a0 w the problem is the a0 = 1 one with ε a0^{1/2},
  so ω_k(a0) = ω_k(1) a0^{k/2};
* the Taylor coefficients of the exact period by quadrature (``lindstedt.references``), each
  with its own error estimate;
* the exact flow (DOP853 with events, through ``lindstedt.validate``): waveform error slope N + 1.
"""

import mpmath
import numpy as np
import pytest

import lindstedt
from lindstedt.references import frequency_taylor_coefficients
from lindstedt.validate import fitted_convergence_order

DIGITS = 30
SLOPE_BAND = 0.3


def test_first_order_is_the_averaging_integral():
    omega = lindstedt.expand("Max(0, u)**(3/2)", order=1, a0=1, omega0=1, precision=DIGITS).omega
    with mpmath.workdps(40):
        expected = mpmath.gamma(mpmath.mpf(7) / 4) / (2 * mpmath.sqrt(mpmath.pi) * mpmath.gamma(mpmath.mpf(9) / 4))
        assert abs(mpmath.mpf(omega[1]) - expected) < mpmath.mpf(10) ** -(DIGITS - 2)


def test_amplitude_scaling_is_exact():
    unit = lindstedt.expand("Max(0, u)**(3/2)", order=4, a0=1, omega0=1, precision=DIGITS).omega
    doubled = lindstedt.expand("Max(0, u)**(3/2)", order=4, a0=4, omega0=1, precision=DIGITS).omega
    with mpmath.workdps(40):
        for k, (one, four) in enumerate(zip(unit, doubled)):
            assert abs(mpmath.mpf(four) - mpmath.mpf(one) * 2**k) < mpmath.mpf(10) ** -(DIGITS - 3) * 2**k


@pytest.mark.parametrize(
    "f, a0",
    [
        ("Max(0, u)**(3/2)", 1),
        ("Max(0, u - 1/5)**(3/2)", 1),
        pytest.param("Max(0, u + 1/2)**(3/2)", 1, marks=pytest.mark.slow),
        pytest.param("2*Max(0, u - 1/5)**(3/2) + u**3", "0.8", marks=pytest.mark.slow),
        ("Max(0, u)**(3/2)", -1),  # the contact holds the far turning point
        pytest.param("Max(0, u - 1/5)**(3/2) + Max(0, -u - 1/5)**(3/2)", 1, marks=pytest.mark.slow),  # two-sided, clearance
        pytest.param("Max(0, u - 1/5)**(3/2) + 2*Max(0, -u - 1/3)**(5/2) + u**2", "0.9", marks=pytest.mark.slow),
        ("Max(0, u - 1/5)*exp(u)", 1),  # an analytic contact law
        pytest.param("exp(Max(0, u)) - 1", 1, marks=pytest.mark.slow),
        pytest.param("Max(0, u)**(3/2) + Heaviside(u)*sin(u)**2", 1, marks=pytest.mark.slow),  # both on one arc
        pytest.param("Max(0, u)*exp(u)", -1, marks=pytest.mark.slow),  # analytic, on the far side
    ],
)
def test_omega_1_to_4_match_the_taylor_coefficients_of_the_exact_period(f, a0):
    expansion = lindstedt.expand(f, order=4, a0=a0, omega0=1, precision=DIGITS)
    reference = frequency_taylor_coefficients(expansion.problem.nonlinearity, 4, a0=a0, omega0=1, precision=DIGITS)
    with mpmath.workdps(40):
        for value, (exact, error) in zip(expansion.omega, reference):
            assert abs(mpmath.mpf(value) - exact) <= error + mpmath.mpf(10) ** -(DIGITS - 3)


def test_float_mode_is_accurate_to_1e_12():
    low = lindstedt.expand("Max(0, u - 1/5)**(3/2)", order=4, a0=1, omega0=1, numeric=True, precision=16).omega
    high = lindstedt.expand("Max(0, u - 1/5)**(3/2)", order=4, a0=1, omega0=1, precision=DIGITS).omega
    for value, reference in zip(low, high):
        assert float(value) == pytest.approx(float(reference), rel=1e-12)


@pytest.mark.parametrize(
    "f, a0, order",
    [("Max(0, u)**(3/2)", 1, 1), ("Max(0, u)**(3/2)", 1, 3), ("Max(0, u - 1/5)**(3/2)", 1, 2), ("Max(0, u)**(3/2)", -1, 2),
     ("Max(0, u - 1/5)**(3/2) + Max(0, -u - 1/5)**(3/2)", 1, 3), ("Max(0, u - 1/5)*exp(u)", 1, 2)],
)
def test_waveform_error_over_one_over_eps_has_slope_order_plus_one(f, a0, order):
    expansion = lindstedt.expand(f, order=order, a0=a0, omega0=1, precision=20)
    fit = fitted_convergence_order(expansion, np.geomspace(0.02, 0.08, 4))
    assert fit.success, fit.message
    assert fit.slope == pytest.approx(order + 1, abs=SLOPE_BAND)


def test_waveform_is_released_at_a0_and_c1_across_the_moving_contact_angle():
    expansion = lindstedt.expand("Max(0, u - 1/5)**(3/2)", order=3, a0=1, omega0=1, precision=20)
    epsilon = 0.1
    assert expansion.displacement(0.0, epsilon) == pytest.approx(1.0, abs=1e-14)
    assert expansion.velocity(0.0, epsilon) == pytest.approx(0.0, abs=1e-14)
    # the contact ends where u = 1/5: u and u' continuous there (the branches meet)
    omega = float(expansion.frequency(epsilon))
    t = np.linspace(0.0, np.pi / omega, 200001)
    u = expansion.displacement(t, epsilon)
    crossing = np.argmin(np.abs(u - 0.2))
    window = slice(crossing - 50, crossing + 50)
    assert np.max(np.abs(np.diff(u[window]))) < 2 * np.abs(np.diff(u[window])).mean()
    velocity = expansion.velocity(t[window], epsilon)
    assert np.max(np.abs(np.diff(velocity))) < 1e-4


def test_what_the_stretched_arc_does_not_cover_is_refused_with_the_fix():
    with pytest.raises(lindstedt.UnsupportedNonlinearityError, match="holds a turning point"):
        lindstedt.expand("Max(0, u - 1/5)**(3/2)*Heaviside(1/2 - u)", order=2, a0=1, omega0=1)
    with pytest.raises(lindstedt.UnsupportedNonlinearityError, match="both sides of one breakpoint"):
        lindstedt.expand("Abs(u)**(3/2)", order=2, a0=1, omega0=1)
    with pytest.raises(lindstedt.UnsupportedNonlinearityError, match="normalization='initial'"):
        lindstedt.expand("Max(0, u)**(3/2)", order=2, a0=1, omega0=1, normalization="harmonic")
    with pytest.raises(lindstedt.UnsupportedNonlinearityError, match="unbounded"):
        lindstedt.expand("Max(0, u)**(-1/2)", order=2, a0=1, omega0=1)
    with pytest.raises(lindstedt.UnsupportedNonlinearityError, match="rational"):
        lindstedt.expand("Max(0, u)**pi", order=2, a0=1, omega0=1)
    with pytest.raises(lindstedt.UnsupportedNonlinearityError, match="holds a turning point"):  # analytic law mid-orbit
        lindstedt.expand("Max(0, u - 1/5)*exp(u)*Heaviside(1/2 - u)", order=2, a0=1, omega0=1)
    with pytest.raises(lindstedt.UnsupportedNonlinearityError, match="not linear in u"):  # infinitely many breakpoints
        lindstedt.expand("Heaviside(sin(1/u))", order=2, a0=1, omega0=1)


def test_the_stretched_arc_exports_itself_and_evaluates_like_the_expansion():
    import json

    expansion = lindstedt.expand("Max(0, u - 1/5)**(3/2)", order=2, a0=1, omega0=1, precision=20)
    (arc,) = expansion.stretched_arcs
    data = json.loads(expansion.to_json())
    assert data["stretched_arcs"][0]["schema"] == "lindstedt.stretched-arc/1"
    assert data["waveforms"][1]["stretched_pieces"] == [0]
    # the exported series reproduces the displacement on the arc: u = a0 Σ ε^n Y_n(s/ℓ(ε))
    epsilon = 0.05
    length = sum(float(value) * epsilon**n for n, value in enumerate(arc.length))
    omega = float(expansion.frequency(epsilon, order=expansion.order + 1))  # displacement's time scale: ω through ω_{N+1}
    for tau in (0.0, 0.3, 0.9):
        t = tau * length / omega
        assert arc.value(tau, epsilon) == pytest.approx(float(expansion.displacement(t, epsilon)), abs=1e-13)
    assert "Stretched contact arc" in expansion.to_latex(waveforms=True)
    with pytest.raises(lindstedt.UnsupportedNonlinearityError, match="Expansion.displacement"):
        expansion.displacement_expr()
    with pytest.raises(lindstedt.UnsupportedNonlinearityError, match="spectrum"):
        expansion.waveforms[1].cosine_coefficient(1)


@pytest.mark.parametrize("law, regime", [
    ("Max(0, u - 1/5)**(3/2)", "contact"),       # the orbit (|u| ≤ 1) enters the Hertz contact u > 1/5
    ("Max(0, u - 1/5)*exp(u)", "contact"),       # an analytic law on the contact arc
    ("Max(0, u - 2)**(3/2)", "no contact"),      # the contact at u = 2 is never reached
])
def test_the_regime_of_a_stretched_arc_law_says_whether_the_orbit_is_in_contact(law, regime):
    expansion = lindstedt.expand(law, order=1, a0=1, omega0=1, precision=20)
    assert expansion.regime == regime
    assert (expansion.omega[1] != 0) == (regime == "contact")  # ω1 = (1/π)∫ f(cos s) cos s ds vanishes only without contact
