"""The worked examples ``derivations/*.py`` (with their helper ``derivations/_common.py``) and ``lindstedt derive``.

Every script runs at a small order, writes LaTeX with balanced environments and
braces and parsable JSON with ``"omega"``, and its numbers — read back from the
JSON text — agree with an independent reference: the exact Duffing series
(elliptic K), the exact u_+ period series, the Cauchy-integral Taylor
coefficients of the exact piecewise-linear period (1e-20), analytic chain
frequencies and the zero-gap closed form of Theorem 4.3.  Every script also runs
as a subprocess, and ``lindstedt derive`` lists and runs them.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import re
import subprocess
import sys
from pathlib import Path

import mpmath
import pytest
import sympy

import lindstedt
from lindstedt import OrderError, ProblemError
from lindstedt.cli import main
from lindstedt.references import (
    duffing_frequency_taylor,
    piecewise_linear_frequency_taylor,
    piecewise_linear_frequency_taylor_symbolic,
)

REPOSITORY = Path(__file__).resolve().parent.parent
SCRIPTS = REPOSITORY / "derivations"
NAMES = ["duffing", "u_plus", "gap", "prestress", "negative_release", "grazing", "nnm_2dof", "nnm_5dof", "all_modes", "hertz"]
#: Small orders keep the suite fast; each still exercises the order-2 machinery where there is one.
SMALL_ORDER = {
    "duffing": 4, "u_plus": 3, "gap": 2, "prestress": 2, "negative_release": 2,
    "grazing": 2, "nnm_2dof": 2, "nnm_5dof": 1, "all_modes": 1, "hertz": 2,
}
PIECEWISE_TOLERANCE = 1e-20  # absolute, ω_k against the 40-digit Cauchy-integral reference
NNM_TOLERANCE = 1e-25  # absolute, 30-digit N-dof arithmetic against closed forms
FLOAT_TOLERANCE = 1e-13  # relative, float closed forms (Theorem 4.3)

A0 = sympy.Symbol("a0", positive=True)
OMEGA0 = sympy.Symbol("omega0", positive=True)
EPSILON = sympy.Symbol("epsilon")
A = sympy.Symbol("a", real=True)
KAPPA, BETA, SIGMA = sympy.Symbol("kappa", real=True), sympy.Symbol("beta", positive=True), sympy.Symbol("sigma", positive=True)
LOCALS = {"a0": A0, "omega0": OMEGA0, "a": A, "kappa": KAPPA, "beta": BETA, "sigma": SIGMA}


def _helper():
    """derivations/_common.py under the name the scripts and ``lindstedt derive`` load it with."""
    key = "lindstedt_derivations_common"
    if key not in sys.modules:
        spec = importlib.util.spec_from_file_location(key, SCRIPTS / "_common.py")
        sys.modules[key] = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(sys.modules[key])
    return sys.modules[key]


common = _helper()
derive = common.run_script


def parse(text: str) -> sympy.Expr:
    return sympy.sympify(text, locals=LOCALS)


@pytest.fixture(scope="module")
def results(tmp_path_factory) -> dict:
    """Each script's derivation at its small order, in this process, written into one temporary directory (computed once)."""
    directory = tmp_path_factory.mktemp("derivations")
    return {name: derive(name, order=SMALL_ORDER[name], output=directory) for name in NAMES}


# --------------------------------------------------------------------------- #
# registry and API
# --------------------------------------------------------------------------- #
def test_every_script_is_listed_by_name_with_its_docstring_first_line():
    assert [name for name, _ in common.list_derivations()] == sorted(NAMES)
    for name, description in common.list_derivations():
        assert description and "\n" not in description
        module = common.load(name)
        assert module.__doc__.strip().splitlines()[0] == description
        highest = getattr(module, "MAX_ORDER", None)
        assert 1 <= module.DEFAULT_ORDER and (highest is None or module.DEFAULT_ORDER <= highest)
        assert callable(module.derive)


def test_bad_requests_raise_typed_errors_naming_the_fix():
    with pytest.raises(ProblemError, match="duffing"):
        derive("no_such_case")
    for order in (0, 13, True, 1.5):
        with pytest.raises(OrderError):
            derive("nnm_2dof", order=order)
    with pytest.raises(OrderError, match="only order 1"):
        derive("all_modes", order=2)
    with pytest.raises(ProblemError, match="format"):
        derive("grazing", order=1, formats=("pdf",))


def test_without_output_directory_nothing_is_written_and_formats_select_files(tmp_path):
    quiet = derive("grazing", order=1)
    assert quiet.paths == () and quiet.order == 1 and quiet.name == "grazing"
    only_json = derive("grazing", order=1, output=tmp_path / "new" / "dir", formats=("json",))
    assert only_json.paths == (tmp_path / "new" / "dir" / "grazing.json",)
    assert [path.name for path in (tmp_path / "new" / "dir").iterdir()] == ["grazing.json"]
    with pytest.raises(dataclasses.FrozenInstanceError):
        quiet.order = 2


def test_default_order_comes_from_the_spec():
    assert derive("all_modes").order == common.load("all_modes").DEFAULT_ORDER == 1


def test_render(results):
    result = results["gap"]
    assert common.render(result, "latex") == result.latex.rstrip("\n")
    assert json.loads(common.render(result, "json")) == result.json
    text = common.render(result, "text")
    assert text.startswith("gap (order 2)")
    assert all(str(path) in text for path in result.paths)
    assert result.json["omega"]["kappa = 1/3"][1] in text  # the coefficients are printed
    with pytest.raises(ProblemError):
        common.render(result, "pdf")


# --------------------------------------------------------------------------- #
# every derivation: files, LaTeX, JSON
# --------------------------------------------------------------------------- #
def assert_valid_latex(text: str) -> None:
    assert text.isascii(), "the fragment must be pure ASCII (pdflatex)"
    stack: list[str] = []
    for kind, environment in re.findall(r"\\(begin|end)\{([^}]*)\}", text):
        if kind == "begin":
            stack.append(environment)
        else:
            assert stack and stack.pop() == environment, f"unbalanced \\end{{{environment}}}"
    assert not stack, f"unclosed environments {stack}"
    body = "\n".join(line for line in text.splitlines() if not line.lstrip().startswith("%"))
    body = body.replace(r"\{", "").replace(r"\}", "")
    depth = 0
    for character in body:
        depth += {"{": 1, "}": -1}.get(character, 0)
        assert depth >= 0, "a closing brace without its opening brace"
    assert depth == 0, "unbalanced braces"
    assert body.count("$") % 2 == 0, "unbalanced inline math"
    assert re.search(r"\\begin\{align\*\}", text) and "\\subsection*" in text


@pytest.mark.parametrize("name", NAMES)
def test_derivation_writes_valid_latex_and_json(results, name):
    result = results[name]
    assert [path.name for path in result.paths] == [f"{name}.tex", f"{name}.json"]
    tex, data_file = result.paths
    assert tex.read_text(encoding="utf-8") == result.latex
    assert_valid_latex(result.latex)
    assert "varepsilon^{-1" in result.latex  # the validity time scale is stated
    data = json.loads(data_file.read_text(encoding="utf-8"))
    assert data == json.loads(json.dumps(result.json))
    assert data["schema"] == "lindstedt.derivation/1" and data["name"] == name and data["order"] == result.order
    assert data["omega"] and data["omega"].keys() == data["omega_float"].keys()
    expected_length = 2 if name == "all_modes" else result.order + 1
    gauges = {variant["label"]: variant.get("expansion", {}).get("gauge") for variant in data.get("variants", [])}
    for label, values in data["omega"].items():
        # an expansion in powers of eps^(1/2) (grazing passed by the perturbed orbit) has 2N + 1 coefficients
        length = 2 * result.order + 1 if gauges.get(label) == "sqrt(epsilon)" else expected_length
        assert len(values) == length and all(isinstance(value, str) for value in values)
    assert all(check["agrees"] for check in data["checks"]), data["checks"]


# --------------------------------------------------------------------------- #
# numbers against independent references (read back from the JSON)
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize("normalization", ["initial", "harmonic"])
def test_duffing_equals_the_exact_elliptic_series(results, normalization):
    data = json.loads(results["duffing"].paths[1].read_text(encoding="utf-8"))
    order = SMALL_ORDER["duffing"]
    reference = duffing_frequency_taylor(order, normalization=normalization)
    for k, text in enumerate(data["omega"][normalization]):
        assert sympy.simplify(parse(text) - OMEGA0 * reference[k] * (A0**2 / OMEGA0**2) ** k) == 0


def test_u_plus_equals_the_exact_period_series(results):
    data = results["u_plus"].json
    series = piecewise_linear_frequency_taylor_symbolic(SMALL_ORDER["u_plus"], epsilon=EPSILON, a=A, omega0=OMEGA0)
    for k, text in enumerate(data["omega"]["a u_+"]):
        assert sympy.simplify(parse(text) - series.coeff(EPSILON, k)) == 0
    assert data["variants"][0]["contact_angles"] == ["pi/2"]


@pytest.mark.parametrize(
    ("name", "label", "b", "a0"),
    [("gap", "kappa = 1/3", "1/3", 1), ("prestress", "kappa = -1/2", "-1/2", 1), ("negative_release", "a0 = -1", "1/3", -1)],
)
def test_piecewise_cases_equal_the_exact_period_taylor_coefficients(results, name, label, b, a0):
    data = results[name].json
    order = SMALL_ORDER[name]
    with mpmath.workdps(40):
        reference = piecewise_linear_frequency_taylor(order, a=1, b=mpmath.mpf(sympy.Rational(b).p) / sympy.Rational(b).q, a0=a0, precision=40)
        for k, text in enumerate(data["omega"][label]):
            value = mpmath.mpf(str(sympy.N(parse(text), 40)))
            assert abs(value - reference[k][0]) <= PIECEWISE_TOLERANCE, (name, k)
    variant = data["variants"][0]
    assert variant["regime"] == "contact" and variant["validity"]["exponent"] == "-1"


def test_gap_closed_forms_in_kappa_against_independent_references(results):
    forms = results["gap"].json["closed_forms"]["omega"]
    omega1, omega2 = parse(forms["omega_1"]), parse(forms["omega_2"])

    def at(expression, kappa):
        return expression.subs({KAPPA: kappa, BETA: sympy.acos(kappa), SIGMA: sympy.sqrt(1 - kappa**2)})

    # κ = 0 is the spring without gap: ω1 = 1/(4ω0), ω2 = -1/(8ω0³) exactly
    series = piecewise_linear_frequency_taylor_symbolic(2, epsilon=EPSILON, a=1, omega0=OMEGA0)
    assert sympy.simplify(at(omega1, 0) - series.coeff(EPSILON, 1)) == 0
    assert sympy.simplify(at(omega2, 0) - series.coeff(EPSILON, 2)) == 0
    # any |κ| < 1, both signs: the exact period (ω0 = 1)
    for kappa in (sympy.Rational(1, 3), sympy.Rational(-1, 2), sympy.Rational(7, 10)):
        with mpmath.workdps(40):
            reference = piecewise_linear_frequency_taylor(2, a=1, b=mpmath.mpf(kappa.p) / kappa.q, a0=1, precision=40)
            for k, form in ((1, omega1), (2, omega2)):
                value = mpmath.mpf(str(sympy.N(at(form, kappa).subs(OMEGA0, 1), 40)))
                assert abs(value - reference[k][0]) <= PIECEWISE_TOLERANCE, (kappa, k)
    assert r"\omega_{1} &= \frac{\beta - \kappa \sigma}{2 \pi \omega_{0}}" in results["gap"].latex


def test_negative_release_shares_omega_1_with_the_positive_release_only(results):
    differences = [float(value) for value in results["negative_release"].json["comparison_with_positive_release"]["omega_difference"]]
    assert differences[0] == 0 and abs(differences[1]) < 1e-25 and abs(differences[2]) > 1e-3


def test_grazing_flags_the_regime_and_expands_in_the_right_gauge(results):
    data = results["grazing"].json
    for variant in data["variants"]:
        assert variant["regime"] == "grazing"
    touching, passing, inside = data["variants"]
    assert inside["expansion"]["gauge"] == "sqrt(epsilon)" and inside["expansion"]["problem"]["a1"] == "1"
    assert touching["validity"]["exponent"] == "-1/2" and touching["contact_angles"] == []
    assert data["omega"]["b = a0"] == ["omega0", "0", "0"]
    assert {row["difference"] for row in data["exact_comparison"]["rows"]["b = a0"]} == {"0.0"}
    # b = -a0: gauge eps^(1/2), the free arc opens at the far turning point
    assert passing["expansion"]["gauge"] == "sqrt(epsilon)" and passing["contact_angles"] == ["pi"]
    # even powers: the Taylor series of the contact side sqrt(omega0^2 + eps), which the O(eps^(1/2)) free arc
    # changes only from eps^(5/2) on (order 2 stops at eps^2)
    linear = sympy.series(sympy.sqrt(OMEGA0**2 + EPSILON), EPSILON, 0, 3).removeO()
    for k, text in enumerate(data["omega"]["b = -a0"]):
        expected = linear.coeff(EPSILON, k // 2) if k % 2 == 0 else 0
        assert sympy.simplify(parse(text) - expected) == 0, k
    for row in data["exact_comparison"]["rows"]["b = -a0"]:
        ratio = abs(float(row["difference"])) / float(row["first_neglected_term"])
        assert 0.5 < ratio < 2, row  # the remainder is the first neglected term (-8/(3 pi) eps^(5/2)) and less
    assert r"\varepsilon^{-1/2}" in results["grazing"].latex and r"\varepsilon^{\frac{5}{2}}" in results["grazing"].latex


def test_nnm_2dof_every_mode_against_closed_forms(results):
    data = results["nnm_2dof"].json
    assert list(data["omega"]) == ["mode 1", "mode 2"]
    # chain of 2: λ = 1, √3; zero-gap spring on mass 1: ω1 = φ_1j² / (4 λ_j) with φ_1j = 1/√2
    with mpmath.workdps(40):
        for j, lam in enumerate([mpmath.mpf(1), mpmath.sqrt(3)]):
            omegas = [mpmath.mpf(text) for text in data["omega"][f"mode {j + 1}"]]
            assert abs(omegas[0] - lam) <= NNM_TOLERANCE
            assert abs(omegas[1] - 1 / (8 * lam)) <= NNM_TOLERANCE
    for variant in data["variants"]:
        assert len(variant["nnm"]["a_k"]) == 1 and variant["validity"]["exponent"] == "-1"


def test_nnm_5dof_uses_the_documented_springs_and_every_mode(results):
    data = results["nnm_5dof"].json
    assert [spring["gap"] for spring in data["system"]["springs"]] == ["0", "-1/5"]
    assert data["system"]["definition"]["b"] == ["0", "-1/5"]
    with mpmath.workdps(40):
        for j in range(1, 6):
            omegas = data["omega"][f"mode {j}"]
            assert abs(mpmath.mpf(omegas[0]) - 2 * mpmath.sin(j * mpmath.pi / 12)) <= NNM_TOLERANCE
    assert len(data["checks"]) == 5
    assert "preloaded" in results["nnm_5dof"].latex


def test_all_modes_zero_gap_corrections_equal_the_closed_form(results):
    data = results["all_modes"].json
    for k in range(1, 4):
        lam, correction = (float(text) for text in data["omega"][f"zero gaps, mode {k}"])
        shape = mpmath.sqrt(mpmath.mpf(1) / 2) * mpmath.sin(k * mpmath.pi / 4)  # φ_1k of the 3-mass chain
        assert lam == pytest.approx(float(2 * mpmath.sin(k * mpmath.pi / 8)), rel=FLOAT_TOLERANCE)
        assert correction == pytest.approx(float(shape**2 / (4 * lam)), rel=FLOAT_TOLERANCE)
    gapped = next(variant for variant in data["variants"] if variant["label"] == "with a gap")
    assert {entry["method"] for entry in gapped["corrections"]} == {"almost-periodic average"}


# --------------------------------------------------------------------------- #
# the scripts
# --------------------------------------------------------------------------- #
@pytest.mark.slow  # every derivation script as a subprocess from two directories (10–15 s); in-process they run in the default run (test_render)
def test_every_script_runs_from_any_directory_and_prints_its_coefficients_checks_and_files(tmp_path):
    processes = {}
    for name in NAMES:
        command = [sys.executable, str(SCRIPTS / f"{name}.py"), "--order", str(min(SMALL_ORDER[name], 2)), "--output", str(tmp_path / name)]
        processes[name] = subprocess.Popen(command, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    failing = subprocess.Popen(
        [sys.executable, str(SCRIPTS / "grazing.py"), "--order", "0", "--output", str(tmp_path / "bad")],
        cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    for name, process in processes.items():
        stdout, stderr = process.communicate(timeout=600)  # a hang guard: all scripts together take ~10 s
        assert process.returncode == 0, (name, stderr)
        expected = [tmp_path / name / f"{name}.tex", tmp_path / name / f"{name}.json"]
        assert [Path(line.split("wrote ", 1)[1]) for line in stdout.splitlines() if line.startswith("  wrote ")] == expected
        assert stdout.startswith(f"{name} (order ") and "omega = " in stdout
        assert "DISAGREES" not in stdout and "agrees" in stdout
        assert "omega" in json.loads(expected[1].read_text(encoding="utf-8"))
        assert_valid_latex(expected[0].read_text(encoding="utf-8"))
    _, stderr = failing.communicate(timeout=600)
    assert failing.returncode == 2 and stderr.startswith("error:") and not (tmp_path / "bad").exists()


def test_every_case_has_a_script_and_no_script_is_unlisted():
    scripts = {path.stem for path in SCRIPTS.glob("*.py") if not path.name.startswith("_")}
    assert scripts == set(NAMES)
    assert "output/" in (SCRIPTS / ".gitignore").read_text(encoding="utf-8").split()


def test_cli_derive_list_and_run(tmp_path, capsys):
    assert main(["derive", "--list"]) == 0
    listed = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in listed] == sorted(NAMES)
    assert listed == [f"{name:18s} {description}" for name, description in common.list_derivations()]
    assert main(["derive", "u_plus", "--order", "2", "--format", "json", "--output", str(tmp_path)]) == 0
    assert '"omega"' in capsys.readouterr().out
    assert (tmp_path / "u_plus.tex").exists() and (tmp_path / "u_plus.json").exists()
    assert main(["derive", "gap", "--order", "1", "--format", "latex", "--output", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("% lindstedt derive gap --order 1") and "\\subsection*" in out
    assert (tmp_path / "out" / "gap.tex").read_text(encoding="utf-8") == out
    assert main(["derive", "no_such_case"]) == 2
    assert "unknown derivation" in capsys.readouterr().err
    assert main(["derive", "nnm_2dof", "--order", "13"]) == 2
    assert "order" in capsys.readouterr().err


def test_cli_derive_without_the_source_tree_names_it(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(lindstedt, "__file__", str(tmp_path / "site-packages" / "lindstedt" / "__init__.py"))
    assert main(["derive", "--list"]) == 2
    assert "source tree" in capsys.readouterr().err
