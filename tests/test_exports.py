"""Exports: JSON schema, LaTeX through sympy's printer, lambdify round trip, CLI."""

import json

import numpy as np
import pytest
import sympy

import lindstedt
from lindstedt.cli import main


def test_json_schema_and_round_trip_of_exact_values():
    expansion = lindstedt.expand("u**3 + c*u**5", order=3, params={"c": None})
    data = json.loads(expansion.to_json())
    assert data["schema"] == "lindstedt.expansion/1"
    assert data["order"] == 3 and data["normalization"] == "initial"
    assert len(data["omega"]) == len(data["alpha"]) == len(data["omega_float"]) == 4
    assert data["omega_float"][1] is None  # symbolic
    locals_ = {"a0": sympy.Symbol("a0", positive=True), "omega0": sympy.Symbol("omega0", positive=True), "c": sympy.Symbol("c", real=True)}
    for text, exact in zip(data["omega"], expansion.omega):
        assert sympy.simplify(sympy.sympify(text, locals=locals_) - exact) == 0
    assert [w["order"] for w in data["waveforms"]] == [0, 1, 2, 3]


def test_json_float_values_for_numeric_problem():
    data = lindstedt.expand("u**3", order=2, a0=1, omega0=1).to_dict(waveforms=False)
    assert data["omega_float"] == [1.0, 0.375, -21 / 256]
    assert data["alpha_float"][1] == pytest.approx(0.75, rel=1e-15)
    assert "waveforms" not in data


def test_latex_uses_sympy_printer_and_builds_waveforms_only_on_request():
    expansion = lindstedt.expand("u**3", order=2)
    brief = expansion.to_latex()
    assert r"\frac{21 a_{0}^{4}}{256 \omega_{0}^{3}}" in brief
    assert "v_{1}(s)" not in brief
    assert "v_{1}(s)" in expansion.to_latex(waveforms=True)


def test_lambdify_round_trip_against_evaluators():
    expansion = lindstedt.expand("u**3", order=3, normalization="harmonic")
    displacement = expansion.lambdify("displacement")
    frequency = expansion.lambdify("frequency")
    assert [s.name for s in expansion.arguments] == ["a0", "omega0"]
    t = np.linspace(0, 40, 500)
    values = {"a0": 0.7, "omega0": 1.3}
    assert np.allclose(displacement(t, 0.05, 0.7, 1.3), expansion.displacement(t, 0.05, values), rtol=0, atol=1e-13)
    assert frequency(0.05, 0.7, 1.3) == pytest.approx(expansion.frequency(0.05, values), rel=1e-14)


def test_laziness_omega_does_not_build_waveform_of_same_order():
    expansion = lindstedt.expand("u**3 + u**4", order=5, a0=1, omega0=1)
    _ = expansion.omega_correction(3)
    hierarchy = expansion._hierarchy
    assert len(hierarchy._waveforms) == 3  # w_0, w_1, w_2 only
    assert 2 not in hierarchy._forcing  # only the secular part of F_2 was computed


def test_cli_expand_json(capsys):
    assert main(["expand", "u**3", "--order", "2", "--a0", "1", "--omega0", "1", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["omega"] == ["1", "3/8", "-21/256"]
    assert data["omega_float"] == [1.0, 0.375, -0.08203125]


def test_cli_params_symbolic_and_numeric(capsys):
    assert main(["expand", "u**3 + c*u**5", "--order", "1", "--param", "c=1/2", "--a0", "1", "--omega0", "1", "--format", "json"]) == 0
    assert json.loads(capsys.readouterr().out)["omega"][1] == "17/32"
    assert main(["expand", "u**3 + c*u**5", "--order", "1", "--param", "c"]) == 0
    assert "c" in capsys.readouterr().out


def test_cli_latex_and_text(capsys):
    assert main(["expand", "u**2", "--order", "2", "--format", "latex", "--waveforms"]) == 0
    assert r"\begin{align*}" in capsys.readouterr().out
    assert main(["expand", "u**3", "--order", "1", "--normalization", "harmonic", "--waveforms", "--format", "plain"]) == 0
    assert "v_1(s)" in capsys.readouterr().out


@pytest.mark.parametrize(
    "arguments, fragment",
    [
        (["expand", "u**3 + d*u", "--order", "2"], "declare it"),
        (["expand", "u**3", "--order", "2", "--param", "c=2"], "not used"),
        (["expand", "u**3", "--a0", "0"], "a0 = 0"),
        (["expand", "u**3", "--omega0", "-1"], "positive"),
        (["expand", "u**3", "--order", "-1"], "order"),
        (["expand", "u**3 +", "--order", "2"], "parse"),
    ],
)
def test_cli_errors_are_clear_and_exit_2(capsys, arguments, fragment):
    assert main(arguments) == 2
    assert fragment in capsys.readouterr().err


def test_piecewise_exports_latex_and_json():
    expansion = lindstedt.expand("Max(0, u - 1/3)", order=2, a0=1, omega0=1)
    latex = expansion.to_latex(waveforms=True)
    assert r"\begin{cases}" in latex and "v_{2}(s)" in latex
    data = json.loads(expansion.to_json())
    assert data["regime"] == "contact" and data["validity_exponent"] == "-1"
    assert data["contact_angles"] == ["acos(1/3)"]
    first = data["waveforms"][1]
    assert first["breakpoints"] == ["acos(1/3)"] and len(first["pieces"]) == 2
    s = sympy.Symbol("s")
    piece = sympy.sympify(first["pieces"][0], locals={"s": s})
    reference = expansion.waveforms[1].branches[0].subs(sympy.Symbol("s", real=True), s)
    assert sympy.simplify(piece - reference) == 0
