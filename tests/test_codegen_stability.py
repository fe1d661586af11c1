"""Generated ω_k(κ) and ω(ε; κ) of a gap are accurate to 1e-13 relative for EVERY κ in (−1, 1).

The closed form of ω_k(κ) cancels catastrophically near κ = ±1 (ω_2 ∝ (1 − κ)^(5/2) from O(1) terms);
``generate_code`` prints piecewise exact series instead.  The reference here is independent of the
generated code: the exact sympy expression ``expansion.omega_correction(k)`` evaluated at the exact
binary value of the double κ with mpmath at 160 digits (the closed form cancels at most ~70 digits at
κ = 1 − 1e-14 for ω_4, so ≥ 90 digits survive), cross-checked against sympy's adaptive ``evalf(60)``.

Tolerance 1e-13: each generated value is a Horner sum of ≤ 50 decreasing terms (or a Taylor series at an
interior root) in an argument computed with a few roundings (sqrt, asin, one subtraction), i.e. a handful
of roundings of 1.1e-16 amplified by a condition number ≤ ~30; measured ≤ 1.4e-14.  Order 4 (the brief's
target) is used: the symbolic expansion takes ~2 s and is built once per module.
"""

import functools
import shutil

import mpmath
import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

import lindstedt

LANGUAGES = ["numpy", pytest.param("c", marks=pytest.mark.skipif(
    not (shutil.which("cc") or shutil.which("gcc")), reason="no C compiler (cc or gcc) on PATH"))]
ORDERS = [1, 2, 3, 4]
TOLERANCE = 1e-13
ENDPOINTS = [s * (1 - 10.0**-p) for p in range(1, 15) for s in (1, -1)]
GRID = list(np.linspace(-0.99, 0.99, 67)) + [-0.8458763825631793, -0.6963907541017692, 0.3153223623952687,
                                              -0.5403023058681398, 0.0, 0.5, -0.5]


@pytest.fixture(scope="module")
def gap():
    return lindstedt.expand("Max(0, u - kappa)", order=4, a0=1, omega0=1, params={"kappa": None})


@pytest.fixture(scope="module")
def references(gap):
    """(k, κ) -> exact ω_k(κ) at 160 digits, one mpmath function per k (independent of generate_code)."""
    kappa = gap.arguments[0]
    functions = {k: sympy.lambdify(kappa, gap.omega_correction(k), "mpmath") for k in ORDERS}

    @functools.lru_cache(maxsize=None)
    def reference(k, value):
        with mpmath.workdps(160):
            return float(functions[k](mpmath.mpf(float(value))))  # mpf(double) is the double's exact value

    return reference


@pytest.fixture(scope="module")
def compiled(gap):
    cache = {}

    def get(k, language):
        if (k, language) not in cache:
            cache[k, language] = lindstedt.generate_code(gap, f"omega{k}", language)
        return cache[k, language]

    return get


def _relative_errors(function, reference, k, kappas):
    got = np.asarray(function(np.array(kappas)), dtype=float)
    exact = np.array([reference(k, x) for x in kappas])
    return np.abs(got - exact) / np.abs(exact)


def test_reference_agrees_with_sympy_evalf(gap, references):
    kappa = gap.arguments[0]
    for k, value in [(2, 1 - 1e-12), (4, 1 - 1e-9), (4, -(1 - 1e-6)), (3, 0.25)]:
        exact = sympy.Float(sympy.Rational(value), 60)  # the double, exactly, as a 60-digit Float
        by_evalf = gap.omega_correction(k).xreplace({kappa: exact}).evalf(60, maxn=2000)
        assert float(by_evalf) == pytest.approx(references(k, value), rel=1e-15)


@pytest.mark.parametrize("language", LANGUAGES)
@pytest.mark.parametrize("k", ORDERS)
def test_omega_k_near_both_ends_and_on_a_grid(gap, references, compiled, k, language):
    code = compiled(k, language)
    assert "relative error <= 1e-13" in code.accuracy
    function = code.compile()
    errors = _relative_errors(function, references, k, ENDPOINTS + GRID)
    assert errors.max() <= TOLERANCE, (k, language, (ENDPOINTS + GRID)[int(errors.argmax())], errors.max())


@pytest.mark.parametrize("language", LANGUAGES)
def test_outside_the_contact_range_is_nan(compiled, language):
    function = compiled(2, language).compile()
    with np.errstate(invalid="ignore"):
        assert np.isnan(function(np.array([1.5, -1.5, np.nan]))).all()
    assert function(np.array([1.0]))[0] == 0.0  # grazing: the series gives the limit ω_2(1) = 0


@settings(max_examples=40, deadline=None)
@given(st.floats(min_value=-1.0, max_value=1.0, exclude_min=True, exclude_max=True), st.sampled_from(ORDERS))
def test_random_kappa(gap, references, compiled, kappa, k):
    errors = _relative_errors(compiled(k, "numpy").compile(), references, k, [kappa])
    assert errors.max() <= TOLERANCE, (kappa, k, errors.max())


@pytest.mark.parametrize("language", LANGUAGES)
def test_frequency_at_fixed_epsilon(gap, references, language):
    code = lindstedt.generate_code(gap, "frequency", language)
    assert code.arguments == ("epsilon", "kappa") and "relative error <= 1e-13" in code.accuracy
    function = code.compile()
    epsilons = np.array([0.0, 0.01, 0.05, 0.1])
    for kappa in ENDPOINTS + GRID[::4]:
        got = function(epsilons, kappa)
        with mpmath.workdps(160):
            omegas = [mpmath.mpf(1)] + [mpmath.mpf(references(k, kappa)) for k in ORDERS]
            exact = np.array([float(mpmath.polyval(omegas[::-1], mpmath.mpf(float(e)))) for e in epsilons])
        assert np.max(np.abs(got - exact) / np.abs(exact)) <= TOLERANCE, kappa


def test_other_expansions_say_no_bound_is_claimed():
    duffing = lindstedt.expand("u**3 + c*u**5", order=2, params={"c": None})
    code = lindstedt.generate_code(duffing, "frequency", "numpy")
    assert code.accuracy.startswith("not analysed")
    gap_with_amplitude = lindstedt.expand("Max(0, u - 1/3)", order=2, omega0=1)  # free a0: not of the form acos(κ)
    assert lindstedt.generate_code(gap_with_amplitude, "omega2", "numpy").accuracy.startswith("not analysed")
