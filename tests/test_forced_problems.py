"""The forced problems validate their inputs and name the fix (issue 15)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy

from lindstedt import LindstedtError, ParameterError, ProblemError, UnilateralSystem
from lindstedt.problems.forced import ForcedOscillator, ForcedSystem, check_forcing_frequency


def test_forced_oscillator_parses_like_the_free_problem():
    problem = ForcedOscillator("Max(0, u - b)", omega0=2, zeta="1/50", forcing="3/10", params={"b": "0.2"})
    assert problem.nonlinearity == sympy.Max(0, sympy.Symbol("u", real=True) - sympy.Rational(1, 5))
    assert (problem.omega0, problem.zeta, problem.forcing) == (2, sympy.Rational(1, 50), sympy.Rational(3, 10))
    assert problem.numeric_coefficients() == (2.0, 0.02, 0.3)
    assert problem.is_numeric
    assert problem.oscillator.f == problem.f  # the backbone's free problem


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"zeta": -0.1}, "zeta must be ≥ 0"),
        ({"zeta": "-1/100"}, "zeta must be ≥ 0"),
        ({"forcing": 0}, "forcing F = 0"),
        ({"omega0": -1}, "omega0"),
        ({"zeta": sympy.Symbol("z")}, "declared nonnegative"),
    ],
)
def test_forced_oscillator_rejects_bad_input(kwargs, match):
    with pytest.raises(ProblemError, match=match):
        ForcedOscillator("u**3", **{"omega0": 1, **kwargs})


def test_forced_oscillator_user_text_goes_through_the_parser():
    with pytest.raises(LindstedtError):
        ForcedOscillator("__import__('os').system('true')", omega0=1)


def test_symbolic_coefficients_are_kept_and_numerics_ask_for_values():
    zeta = sympy.Symbol("zeta", nonnegative=True)
    problem = ForcedOscillator("u**3", zeta=zeta, forcing=sympy.Symbol("F", positive=True))
    assert not problem.is_numeric
    with pytest.raises(ParameterError, match="omega0, zeta, forcing"):
        problem.numeric_coefficients()


@pytest.mark.parametrize("value", [0, -1.0, float("nan"), float("inf"), "abc", True])
def test_forcing_frequency_must_be_positive(value):
    with pytest.raises(ParameterError, match="Omega"):
        check_forcing_frequency(value)


def test_forced_system_damping_models():
    system = UnilateralSystem.chain(2, [(1, "1/10")])
    rayleigh = ForcedSystem(system, [1, 0], rayleigh=("1/10", "1/100"))
    np.testing.assert_allclose(rayleigh.C, 0.1 * system.M + 0.01 * system.K, rtol=1e-15)
    zetas = (0.02, 0.05)
    modal = ForcedSystem(system, [1, 0], modal_damping=zetas)
    frequencies, shapes = system.modes()
    # Φᵀ C Φ = diag(2 ζ_k ω_k): the definition of modal damping (ΦᵀMΦ = I)
    np.testing.assert_allclose(shapes.T @ modal.C @ shapes, np.diag([2 * z * w for z, w in zip(zetas, frequencies)]), atol=1e-15)
    given = ForcedSystem(system, [0, 1], C=[[1, 0], [0, 1]])
    assert given.damping == ("matrix", None)
    assert ForcedSystem.from_json_dict(rayleigh.to_json_dict()).C.tolist() == rayleigh.C.tolist()
    assert ForcedSystem.from_json_dict(given.to_json_dict()).C.tolist() == given.C.tolist()


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"load": [0, 0]}, "load P is zero"),
        ({"load": [1]}, "one entry per degree of freedom"),
        ({"load": [1, 0], "rayleigh": (-1, 0)}, "alpha must be ≥ 0"),
        ({"load": [1, 0], "rayleigh": (0, 0), "C": [[1, 0], [0, 1]]}, "one damping model"),
        ({"load": [1, 0], "C": [[1, 2], [0, 1]]}, "symmetric"),
        ({"load": [1, 0], "C": [[1, 0], [0, -1]]}, "negative eigenvalue"),
        ({"load": [1, 0], "modal_damping": [0.1]}, "one ratio per mode"),
    ],
)
def test_forced_system_rejects_bad_input(kwargs, match):
    with pytest.raises(ProblemError, match=match):
        ForcedSystem(UnilateralSystem.chain(2, [(1, "1/10")]), **kwargs)


@pytest.mark.parametrize("kwargs", [{"rayleigh": 0.01}, {"rayleigh": "0.01"}, {"modal_damping": 0.05},
                                    {"modal_damping": "0.05"}, {"rayleigh": {"alpha": 0}}])
def test_damping_given_as_a_scalar_or_text_names_the_form(kwargs):
    with pytest.raises(ProblemError, match="must be a sequence"):
        ForcedSystem(UnilateralSystem.chain(2, [(1, "1/10")]), [1, 0], **kwargs)


def test_a_negative_forcing_is_a_phase_shift_with_the_same_peak():
    import lindstedt

    positive = lindstedt.frequency_response_curve("u**3", omega0=1, zeta="1/100", forcing="1/2")
    negative = lindstedt.frequency_response_curve("u**3", omega0=1, zeta="1/100", forcing="-1/2")
    assert negative.peak_amplitude == positive.peak_amplitude and str(positive.peak_amplitude) == "25*epsilon"
    with pytest.raises(ProblemError, match="not both"):
        lindstedt.frequency_response_curve(lindstedt.ForcedOscillator("u**3", omega0=1), zeta="1/100")
