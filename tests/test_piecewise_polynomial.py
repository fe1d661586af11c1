"""Piecewise-polynomial contact laws on the one branch engine (issue 12): (u − b)_+², u|u|, H(u − b) u², …

On each contact arc the hierarchy solves with that piece's polynomial (products of
branches of lower orders), so the frequencies come out in closed form in π, β = arccos κ,
√(1 − κ²) and rationals.  References, none of them the code under test:

* the first-order averaging integral ω1 = (1/(2π a0 ω0)) ∫_0^{2π} f(a0 cos s) cos s ds,
  evaluated by hand: for f = (u − b)_+², a0 = 1, κ = b, S = √(1 − κ²):
  ∫_{−β}^{β} (cos s − κ)² cos s ds = 2S − 2S³/3 − 2κβ;
* the exact period by quadrature of the energy integral (``lindstedt.references``);
* the exact flow (DOP853 with events, through ``lindstedt.validate``): waveform error slope N + 1.
"""

import mpmath
import numpy as np
import pytest
import sympy

import lindstedt
from lindstedt.references import frequency_taylor_coefficients
from lindstedt.validate import fitted_convergence_order

SLOPE_BAND = 0.3


def test_first_order_frequency_is_the_averaging_integral_in_closed_form():
    pi = sympy.pi
    assert lindstedt.expand("Max(0, u)**2", order=1, a0=1, omega0=1).omega[1] == 2 / (3 * pi)  # (1/2π)·4/3
    assert lindstedt.expand("u*Abs(u)", order=1, a0=1, omega0=1).omega[1] == 4 / (3 * pi)  # (1/2π)·8/3
    gap = lindstedt.expand("Max(0, u - 1/3)**2", order=1, a0=1, omega0=1).omega[1]
    assert sympy.simplify(gap - (38 * sympy.sqrt(2) - 27 * sympy.acos(sympy.Rational(1, 3))) / (81 * pi)) == 0


@pytest.mark.parametrize("kappa", ["-0.7", "-0.2", "0.1", "0.55", "0.9"])
def test_symbolic_gap_first_order_matches_the_averaging_integral(kappa):
    b = sympy.Symbol("b", real=True)
    omega1 = lindstedt.expand("Max(0, u - b)**2", order=1, a0=1, omega0=1, params={"b": None}).omega[1]
    with mpmath.workdps(40):
        k = mpmath.mpf(kappa)
        sine, angle = mpmath.sqrt(1 - k**2), mpmath.acos(k)
        expected = (2 * sine - 2 * sine**3 / 3 - 2 * k * angle) / (2 * mpmath.pi)
        value = mpmath.mpf(str(sympy.N(omega1.subs(b, sympy.Rational(kappa)), 45)))
        assert abs(value - expected) < mpmath.mpf(10) ** -35


def test_one_law_written_four_ways_gives_one_expansion():
    spellings = ["Max(0, u)**2", "Heaviside(u)*u**2", "Piecewise((u**2, u > 0), (0, True))", "(u + Abs(u))**2/4"]
    results = {lindstedt.expand(f, order=3, a0=1, omega0=1).omega for f in spellings}
    assert len(results) == 1


def test_an_odd_law_has_the_same_frequency_from_either_side():
    right = lindstedt.expand("u*Abs(u)", order=4, a0=1, omega0=1).omega
    left = lindstedt.expand("u*Abs(u)", order=4, a0=-1, omega0=1).omega
    assert right == left


def test_float_mode_agrees_with_the_exact_closed_forms():
    exact = lindstedt.expand("Max(0, u - 1/3)**2 + u**3", order=4, a0=1, omega0=1)
    numeric = lindstedt.expand("Max(0, u - 1/3)**2 + u**3", order=4, a0=1, omega0=1, numeric=True, precision=30)
    for exact_value, numeric_value in zip(exact.omega, numeric.omega):
        assert abs(sympy.N(exact_value - numeric_value, 40)) < 1e-26


@pytest.mark.parametrize("f, order", [("Max(0, u)**2", 2), ("u*Abs(u)", 3), ("Max(0, u - 1/3)**2", 2), ("Heaviside(u - 1/2)*u**2", 2)])
def test_waveform_error_over_one_over_eps_has_slope_order_plus_one(f, order):
    expansion = lindstedt.expand(f, order=order, a0=1, omega0=1)
    fit = fitted_convergence_order(expansion, np.geomspace(0.02, 0.08, 4))
    assert fit.success, fit.message
    assert fit.slope == pytest.approx(order + 1, abs=SLOPE_BAND)


def test_unsupported_pieces_name_what_is_supported():
    with pytest.raises(lindstedt.UnsupportedNonlinearityError, match="not analytic on the whole arc"):
        lindstedt.expand("Max(0, u)*log(u)", order=2, a0=1, omega0=1)


@pytest.mark.parametrize(
    "f",
    ["Max(0, u)**2", "Max(0, u - 1/3)**2", pytest.param("u*Abs(u)", marks=pytest.mark.slow),
     pytest.param("Heaviside(u - 1/2)*u**2", marks=pytest.mark.slow), pytest.param("Max(0, u + 1/2)**2 + u**3", marks=pytest.mark.slow)],
)
def test_omega_1_to_5_match_the_taylor_coefficients_of_the_exact_period(f):
    expansion = lindstedt.expand(f, order=5, a0=1, omega0=1)
    reference = frequency_taylor_coefficients(expansion.problem.nonlinearity, 5, a0=1, omega0=1, precision=30)
    with mpmath.workdps(40):
        for exact, (value, error) in zip(expansion.omega, reference):
            assert abs(mpmath.mpf(sympy.N(exact, 40)) - value) <= error + mpmath.mpf(10) ** -28
