"""Generated NumPy and C code agree with the exact evaluators to 1e-13 (round trip)."""

import shutil

import numpy as np
import pytest

import lindstedt

VALUES = {"a0": 0.8, "omega0": 1.2, "c": 0.5}
CASES = [
    ("u**3 + c*u**5", {"params": {"c": None}}),
    ("u**3", {"normalization": "harmonic"}),
    ("Max(0, u - 1/3)", {"a0": 1}),
    ("Max(0, u) - 2*Max(0, -u - 1/2)", {"a0": "4/5"}),
    ("sin(u)", {"a0": "4/5", "omega0": "6/5"}),
]
LANGUAGES = ["numpy"] + (["c"] if shutil.which("cc") or shutil.which("gcc") else [])


@pytest.mark.parametrize("language", LANGUAGES)
@pytest.mark.parametrize("text, options", CASES)
def test_round_trip_against_exact_evaluators(text, options, language):
    expansion = lindstedt.expand(text, order=2, **options)
    values = {name: VALUES[name] for name in (str(a) for a in expansion.arguments)}
    frequency = lindstedt.generate_code(expansion, "frequency", language)
    displacement = lindstedt.generate_code(expansion, "displacement", language)
    assert frequency.arguments[0] == "epsilon" and displacement.arguments[:2] == ("t", "epsilon")
    epsilons = np.linspace(0.0, 0.1, 11)
    times = np.linspace(0.0, 60.0, 1201)
    assert np.max(np.abs(frequency.compile()(epsilons, *values.values()) - expansion.frequency(epsilons, values))) < 1e-13
    generated = displacement.compile()(times, 0.05, *values.values())
    assert np.max(np.abs(generated - expansion.displacement(times, 0.05, values))) < 1e-13


def test_sources_are_readable_code():
    expansion = lindstedt.expand("u**3", order=1)
    numpy_source = lindstedt.generate_code(expansion, "frequency", "numpy").source
    c_source = lindstedt.generate_code(expansion, "displacement", "c").source
    assert numpy_source.startswith("def lindstedt_frequency(epsilon, a0, omega0):")
    assert "#include <math.h>" in c_source and "void lindstedt_displacement(" in c_source


def test_bad_arguments():
    expansion = lindstedt.expand("u**3", order=1)
    with pytest.raises(ValueError, match="quantity"):
        lindstedt.generate_code(expansion, "energy")
    with pytest.raises(ValueError, match="language"):
        lindstedt.generate_code(expansion, "frequency", "cobol")


@pytest.mark.parametrize("language", LANGUAGES)
def test_nnm_frequency_code_round_trip(language):
    chain = lindstedt.UnilateralSystem.chain(3, unilateral=[(0, 0.1)])
    result = lindstedt.nnm(chain, mode=2, a0=1.0, order=3)
    code = lindstedt.generate_code(result, "frequency", language)
    epsilons = np.linspace(0, 0.05, 11)
    assert np.max(np.abs(code.compile()(epsilons) - result.frequency(epsilons))) < 1e-13
    with pytest.raises(ValueError, match="vector valued"):
        lindstedt.generate_code(result, "displacement", language)
