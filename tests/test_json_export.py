"""Every result class exports itself through the one JSON layer: strict JSON, its schema, its problem, NaN as null."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

import lindstedt
from lindstedt import validate

CHAIN = lindstedt.UnilateralSystem.chain(2, unilateral=[(0, 0)])
GAP_CHAIN = lindstedt.UnilateralSystem.chain(3, [(0, 0.1)])
CUBIC = lindstedt.Oscillator("u**3", a0=1, omega0=1)


@pytest.fixture(scope="module")
def results():
    """name -> (result, its problem or None, (field, value) compared exactly)."""
    simple = lindstedt.expand("Max(0, u)", order=1, a0=1, omega0=1)
    gap = lindstedt.expand("Max(0, u - 1/3)", order=1, a0=1, omega0=1)
    grazing = lindstedt.expand("Max(0, u - 1)", order=1, a0=1, omega0=1)
    t = np.linspace(0.0, 2 * np.pi, 2001)
    progress: list = []
    branch = lindstedt.continue_nnm(CHAIN, 1, start=0.05, stop=0.1, modal_amplitude=1.0, max_points=3, callback=progress.append)
    samples = np.cos(np.linspace(0.0, 2 * np.pi, 64, endpoint=False))
    found = {
        "ExpansionError": (validate.expansion_error(simple, 0.01, 20.0), simple.problem, "max_error"),
        "ConvergenceFit": (validate.fitted_convergence_order(gap, [0.04, 0.02]), gap.problem, "slope"),
        "ValidityFit": (validate.fitted_validity_exponent(grazing, [0.02, 0.01], a1=1.0), grazing.problem, "exponent"),
        "LogLogFit": (validate.loglog_fit([1.0, 2.0, 4.0], [3.0, 12.0, 48.0]), None, "slope"),
        "ContactMeasure": (validate.contact_measure(np.cos(t), t, 0.01), None, "measure"),
        "ContactMeasureFit": (
            validate.fitted_contact_measure_order(lindstedt.expand("Max(0, u - 1/3)", order=0, a0=1, omega0=1),
                                                  [0.04, 0.02], periods=2),
            gap.problem, "slope",
        ),
        "ReferenceSolution": (validate.reference_solution(CUBIC, 0.1, np.linspace(0.0, 5.0, 11)), CUBIC, "t_final"),
        "ExactPeriod": (validate.exact_period(CUBIC, 0.1), CUBIC, "period"),
        "Spectrum": (validate.exact_spectrum(CUBIC, 0.1, samples_per_period=64), CUBIC, "duration"),
        "SpectralPeak": (validate.spectrum(samples, 2 * np.pi, periods=1).peaks[0], None, "amplitude"),
        "AllModesFirstOrder": (lindstedt.all_modes_first_order(CHAIN, [1.0, 0.5]), CHAIN, "averaging_time"),
        "FlowResult": (lindstedt.ExactFlow(GAP_CHAIN, epsilon=0.5).solve([0.3, 0.0, 0.0], [0.0, 0.0, 0.0], 20.0),
                       GAP_CHAIN, "t_final"),
        "FlowMapResult": (lindstedt.ExactFlow(GAP_CHAIN, epsilon=0.5).flow_map([0.3, 0.0, 0.0], [0.0, 0.0, 0.0], 5.0),
                          GAP_CHAIN, "n_evaluations"),
        "ContinuationProgress": (progress[0], None, "parameter"),
        "NNMBranch": (branch, CHAIN, "wall_time"),
        "NNMResult": (branch.points[0], None, "frequency"),
    }
    # the spectrum of given samples has no problem; of a solution it has its problem
    assert validate.spectrum(samples, 2 * np.pi).problem is None
    return found


NAMES = [
    "ExpansionError", "ConvergenceFit", "ValidityFit", "LogLogFit", "ContactMeasure", "ContactMeasureFit",
    "ReferenceSolution", "ExactPeriod", "Spectrum", "SpectralPeak", "AllModesFirstOrder", "FlowResult",
    "FlowMapResult", "ContinuationProgress", "NNMBranch", "NNMResult",
]


def _problem_json(problem):
    if isinstance(problem, lindstedt.Oscillator):
        return {"description": problem.describe(), "f": "u**3" if problem is CUBIC else str(problem.f),
                "a0": str(problem.a0), "omega0": str(problem.omega0), "a1": str(problem.a1)}
    return problem.to_json_dict()


@pytest.mark.parametrize("name", NAMES)
def test_round_trip_schema_problem_and_value(results, name):
    result, problem, key = results[name]
    assert type(result).__name__ == name
    text = result.to_json()
    data = json.loads(text)
    assert json.dumps(data, allow_nan=False)  # strict: no NaN or infinity anywhere
    assert "NaN" not in text and "Infinity" not in text
    assert data == result.to_dict()
    assert data["schema"] == type(result).SCHEMA
    assert data["schema"].startswith("lindstedt.") and data["schema"].endswith("/1")
    value = getattr(result, key)
    assert data[key] == value and type(data[key]) is type(value)  # exact, through the JSON text
    if problem is not None:
        held = result.system if isinstance(problem, lindstedt.UnilateralSystem) else result.problem
        assert held is problem or held == problem
        exported = data["system"] if isinstance(problem, lindstedt.UnilateralSystem) else data["problem"]
        assert exported == _problem_json(problem)
    # private fields and dense output are not exported
    assert not any(k.startswith("_") for k in data)


def test_problem_descriptions(results):
    error = json.loads(results["ExpansionError"][0].to_json())
    assert error["problem"]["description"].startswith("u'' + u + eps*(Max(0, u))")
    assert error["problem"]["f"] == "Max(0, u)"
    flow = json.loads(results["FlowResult"][0].to_json())
    assert flow["system"] == GAP_CHAIN.to_json_dict() and flow["epsilon"] == 0.5
    assert results["FlowResult"][0].system is GAP_CHAIN


def test_nan_becomes_null(results):
    fit = results["ConvergenceFit"][0]  # two points: the standard error is NaN
    assert math.isnan(fit.standard_error)
    assert json.loads(fit.to_json())["standard_error"] is None
    error = results["ExpansionError"][0]
    broken = dataclasses.replace(error, max_error=math.nan, times=np.array([0.0, np.inf, -np.inf, np.nan]))
    data = json.loads(broken.to_json())
    assert data["max_error"] is None and data["times"] == [0.0, None, None, None]


def test_arrays_nested_results_and_complex(results):
    error = results["ExpansionError"][0]
    data = json.loads(error.to_json())
    assert data["times"] == error.times.tolist() and data["error"] == error.error.tolist()
    spectrum = results["Spectrum"][0]
    data = json.loads(spectrum.to_json())
    z = spectrum.coefficients[1]
    assert data["coefficients"][1] == [z.real, z.imag]
    assert data["peaks"][0] == spectrum.peaks[0].to_dict()
    branch = results["NNMBranch"][0]
    assert all(point.system is CHAIN for point in branch.points)  # each orbit keeps its system (not in nnm-numeric/1)
    data = json.loads(branch.to_json())
    assert data["points"] == [point.to_dict() for point in branch.points]
    assert data["parameter_values"] == branch.parameter_values.tolist()
    progress = json.loads(results["ContinuationProgress"][0].to_json())
    assert progress["result"]["schema"] == "lindstedt.nnm-numeric/1"
    flow = json.loads(results["FlowResult"][0].to_json())
    assert flow["events"] and set(flow["events"][0]) == {"schema", "time", "spring", "direction"}


def test_frozen_and_equality_unchanged(results):
    result = results["ExactPeriod"][0]
    with pytest.raises(dataclasses.FrozenInstanceError):
        result.period = 1.0
    # the problem is kept but neither compared nor shown
    assert dataclasses.replace(result, problem=None) == result
    assert "problem" not in repr(result)


def test_nnm_numeric_schema_unchanged(results):
    point = results["NNMResult"][0]
    data = point.to_dict()
    assert list(data) == [
        "schema", "success", "status", "message", "mode", "epsilon", "frequency", "period", "linear_frequency",
        "release_position", "release_velocity", "modal_coordinates", "energy", "floquet_multipliers", "stable",
        "residual", "n_switches", "formulation", "newton_iterations", "flow_evaluations",
    ]
    assert data["floquet_multipliers"] == [[float(z.real), float(z.imag)] for z in point.floquet_multipliers]


def test_expansion_json_writes_null_for_a_coefficient_beyond_a_float():
    """a0 = 10^200: ω_1 = 3 a0²/8 = 3.75e399 overflows a double; the exact value stays, its float is null."""
    expansion = lindstedt.expand("u**3", order=2, a0=10**200, omega0=1)
    data = json.loads(expansion.to_json())
    assert data["omega_float"] == [1.0, None, None]
    assert "Infinity" not in expansion.to_json() and "NaN" not in expansion.to_json()
    exact = lindstedt.expand("u**3", order=2, a0=1, omega0=1).to_dict()["omega_float"]
    assert exact == [1.0, 0.375, -21 / 256]
