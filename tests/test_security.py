"""Security suite: no user string runs code, hangs the process or silently changes a number.

Every payload class is sent through every entry point (Python API arguments,
``values=``, UnilateralSystem entries, CLI flags, SYSTEM.json entries).  Each must
fail with a typed ``LindstedtError`` (API) or one ``error:`` line and exit 2 (CLI),
quickly, and must never create the canary file that a payload would create if it
were executed.  "Quickly" is measured as work, not time (a busy machine must not turn the suite red): the
Python function calls a rejection makes are counted, and a rejection that would exceed the bound is stopped.
"""

from __future__ import annotations

import ast
import json
import math
import pathlib
import re
import sys
from contextlib import contextmanager
from decimal import Decimal
from fractions import Fraction

import numpy as np
import pytest
import sympy
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import lindstedt
from lindstedt import LindstedtError, ParameterError, ProblemError, UnilateralSystem
from lindstedt.cli import main

#: Python function calls (profile "call" and "c_call" events) a rejection or a parse may make.  Measured: at most
#: 1.9e4 once the entry point's modules are imported (median 215; a fuzzed text at most 1.7e3), 3.3e5 for a first
#: call that imports the numerics (scipy); evaluating a payload (9**9**9, exp(exp(exp(100))), a 300-level tower)
#: would take far more.  Work, not seconds: the bound is the same on an idle and on a loaded machine.
CALL_BOUND = 2_000_000


class RunawayWork(BaseException):
    """Raised by the call counter past CALL_BOUND (a BaseException: no ``except Exception`` in the code swallows it)."""


@contextmanager
def bounded_work(bound: float = CALL_BOUND):
    """Count the Python function calls made in the block; stop it with RunawayWork past ``bound`` (a hang guard too).

    Yields a one-element list holding the count so far.
    """
    count = [0]

    def counter(frame, event, arg):
        if event in ("call", "c_call"):
            count[0] += 1
            if count[0] > bound:
                sys.setprofile(None)
                raise RunawayWork(f"more than {bound} function calls")

    previous = sys.getprofile()
    sys.setprofile(counter)
    try:
        yield count
    finally:
        sys.setprofile(previous)


def payloads(canary: pathlib.Path) -> dict[str, str]:
    touch = f"__import__('pathlib').Path({str(canary)!r}).touch()"
    return {
        "string literal in a call": f"sin({touch!r})",
        "string literal alone": repr(touch),
        "f-string": 'f"{' + touch + '}"',
        "attribute access": "u.__class__.__mro__[1].__subclasses__()",
        "dunder call": touch,
        "builtin": "eval('1')",
        "lambda": f"(lambda: {touch})()",
        "walrus": "(x := 1)",
        "comprehension": f"[{touch} for x in (1,)]",
        "bytes": "b'1'",
        "subscript": "u[0]",
        "keyword argument": "sin(x=1)",
        "huge power": "9**9**9",
        "huge power of a parameter-free base": "(2**64)**(2**64)",
        "huge exponent": "1e999999999",
        "huge negative exponent": "1e-999999999",
        "deep nesting": "(" * 300 + "1" + ")" * 300,
        "deep unary nesting": "-" * 500 + "1",
        "power tower": "**".join(["2"] * 300),
        "long input": "+".join(["1"] * 3000),
        "exponential tower": "exp(exp(exp(100)))",
        "word nan": "nan",
        "word inf": "inf",
        "complex literal": "1j",
        "newline statement": "1\nimport os",
        "semicolon": "1; import os",
    }


def expect_rejected(call, canary: pathlib.Path) -> LindstedtError:
    with pytest.raises(LindstedtError) as info, bounded_work():
        call()
    assert not canary.exists()
    return info.value


@pytest.fixture
def canary(tmp_path):
    path = tmp_path / "canary"
    yield path
    assert not path.exists(), "a payload was executed"


PAYLOAD_NAMES = list(payloads(pathlib.Path("x")))


@pytest.mark.parametrize("name", PAYLOAD_NAMES)
def test_python_api_entry_points_reject_every_payload(name, canary):
    text = payloads(canary)[name]
    chain = UnilateralSystem.chain(2, unilateral=[(0, 0.0)])
    calls = [
        lambda: lindstedt.expand(text, order=1),
        lambda: lindstedt.expand(f"u**3 + ({text})*u", order=1),
        lambda: lindstedt.expand("u**3", order=1, a0=text),
        lambda: lindstedt.expand("u**3", order=1, omega0=text),
        lambda: lindstedt.expand("c*u**3", order=1, params={"c": text}),
        lambda: lindstedt.Oscillator("u**3", a0=text),
        lambda: lindstedt.expand("u**3", order=1).frequency(0.1, values={"a0": text, "omega0": 1}),
        lambda: lindstedt.nnm(chain, mode=1, a0=text),
        lambda: lindstedt.nnm(chain, mode=1, a0=1, a1=text),
        lambda: UnilateralSystem(M=[[1]], K=[[text]], A=[[1]], b=[0]),
        lambda: UnilateralSystem.from_json_dict({"M": [[1]], "K": [[1]], "A": [[1]], "b": [text]}),
        lambda: lindstedt.nnm_point(chain, text, 1, modal_amplitude=1.0),
    ]
    for call in calls:
        expect_rejected(call, canary)


def run_cli(argv, capsys, bound=None):
    """Exit status, stdout, stderr of ``lindstedt argv`` in process; with ``bound``, its work is bounded."""
    with bounded_work(math.inf if bound is None else bound) as calls:
        status = main(argv)
    captured = capsys.readouterr()
    return status, captured.out, captured.err, calls[0]


@pytest.mark.parametrize("name", PAYLOAD_NAMES)
def test_cli_entry_points_reject_every_payload(name, canary, tmp_path, capsys):
    text = payloads(canary)[name]
    system_file = tmp_path / "system.json"
    system_file.write_text(json.dumps({"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]], "A": [[1, 0]], "b": [text]}))
    good_system = tmp_path / "good.json"
    good_system.write_text(json.dumps({"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]], "A": [[1, 0]], "b": [0]}))
    commands = [
        ["expand", text, "--order", "1"],
        ["expand", "u**3", "--order", "1", "--a0", text],
        ["expand", "u**3", "--order", "1", "--omega0", text],
        ["expand", "c*u**3", "--order", "1", "--param", f"c={text}"],
        ["nnm", str(system_file), "--mode", "1", "--a0", "1"],
        ["nnm", str(good_system), "--mode", "1", "--a0", text],
        ["nnm", str(good_system), "--mode", "1", "--numeric", "--a0", "1", "--eps", text],
        ["nnm", str(good_system), "--mode", "1", "--numeric", "--a0", text, "--eps", "0.01"],
    ]
    for argv in commands:
        status, out, err, _ = run_cli(argv, capsys, bound=CALL_BOUND)
        assert status == 2, (argv, out, err)
        assert err.startswith("error: ") and err.count("\n") == 1, err
        assert "Traceback" not in err
        assert not canary.exists()


def test_a_real_subprocess_runs_no_payload(tmp_path):
    import subprocess
    import sys

    canary = tmp_path / "canary"
    for text in (payloads(canary)["string literal in a call"], payloads(canary)["f-string"]):
        result = subprocess.run(
            [sys.executable, "-m", "lindstedt", "expand", text], capture_output=True, text=True, timeout=120, check=False
        )
        assert result.returncode == 2
        assert result.stderr.startswith("error: ") and result.stderr.count("\n") == 1
        assert not canary.exists()


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["expand", "u!"], "cannot parse"),
        (["expand", "u**3", "--order", "-1"], "order"),
        (["expand", "u**3", "--bogus"], "unrecognized"),
        (["expand", "u**3", "--a0", "E", "--omega0", "0"], "positive"),
        (["derive", "gap", "--output", "/proc/lindstedt-not-writable/x"], "cannot access"),
        (["demo", "--order", "1", "--figure", "/nonexistent-dir/figure.svg"], "cannot access"),
        (["nnm", "/nonexistent/system.json", "--mode", "1", "--a0", "1"], "cannot read"),
    ],
)
def test_cli_failures_are_one_error_line_and_exit_2(argv, fragment, capsys):
    status, out, err, _ = run_cli(argv, capsys)
    assert status == 2
    assert err.startswith("error: ") and err.count("\n") == 1 and fragment in err


def test_cli_nnm_energy_without_numeric_is_an_error(tmp_path, capsys):
    # an energy amplitude belongs to shooting (--numeric); the expansion takes --a0 (--eps then evaluates it)
    system = tmp_path / "system.json"
    system.write_text(json.dumps({"M": [[1]], "K": [[1]], "A": [[1]], "b": [0]}))
    status, _, err, _ = run_cli(["nnm", str(system), "--mode", "1", "--energy", "0.5", "--eps", "0.1"], capsys)
    assert status == 2 and "--numeric" in err


def test_cli_json_system_with_nan_constant_is_rejected(tmp_path, capsys):
    system = tmp_path / "system.json"
    system.write_text('{"M": [[1]], "K": [[NaN]], "A": [[1]], "b": [0]}')
    status, _, err, _ = run_cli(["nnm", str(system), "--mode", "1", "--a0", "1"], capsys)
    assert status == 2 and "finite" in err


def test_failed_numeric_run_exits_1_with_strict_json(tmp_path, capsys):
    system = tmp_path / "system.json"
    system.write_text(json.dumps({"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]], "A": [[1, 0]], "b": [0]}))
    # no periodic orbit has a non-positive energy: the shooting reports failure
    status, out, err, _ = run_cli(["nnm", str(system), "--mode", "1", "--numeric", "--energy", "-1", "--eps", "0.1", "--format", "json"], capsys)
    assert status == 1
    data = json.loads(out, parse_constant=lambda name: pytest.fail(f"JSON contains {name}"))
    assert data["success"] is False and data["status"] == "failed" and data["frequency"] is None and data["message"]
    assert err.startswith("error: ") and err.count("\n") == 1


def test_cli_version(capsys):
    status, out, _, _ = run_cli(["--version"], capsys)
    assert status == 0 and out.startswith("lindstedt ")


# --------------------------------------------------------------------------- numbers where numbers are required
@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf"), 1j, "nan", "inf", "oo", "zoo", "I", "x", "a0", "", "1/0", "log(-1)", "acos(2)", True])
def test_a0_must_be_a_finite_real_number(value):
    with pytest.raises(ProblemError):
        lindstedt.Oscillator("u**3", a0=value)


@pytest.mark.parametrize("value", [float("nan"), float("inf"), "nan", "x", 1j])
def test_parameter_and_values_must_be_finite_real_numbers(value):
    with pytest.raises(ProblemError):
        lindstedt.expand("c*u**3", order=1, params={"c": value})
    expansion = lindstedt.expand("u**3", order=1)
    with pytest.raises(ProblemError):
        expansion.frequency(0.1, values={"a0": value, "omega0": 1})


def test_numbers_are_exact():
    problem = lindstedt.Oscillator("c*u**3", a0=0.1, omega0="1.5", params={"c": Fraction(1, 3)})
    assert problem.a0 == sympy.Rational(*(0.1).as_integer_ratio())
    assert problem.omega0 == sympy.Rational(3, 2)
    assert problem.nonlinearity == sympy.Rational(1, 3) * sympy.Symbol("u", real=True) ** 3
    assert lindstedt.Oscillator("u**3", a0=sympy.Float(0.1)).a0 == problem.a0
    assert lindstedt.Oscillator("u**3", a0=Decimal("0.1")).a0 == sympy.Rational(1, 10)
    assert lindstedt.Oscillator("u**3", a0=np.float64(0.1)).a0 == problem.a0
    assert lindstedt.Oscillator("u**3", a0="pi").a0 == sympy.pi  # the constant, never a symbol named pi


def test_float_near_grazing_equals_the_exact_decimal_of_its_binary_value():
    gap = 0.999999
    from_float = lindstedt.expand("Max(0, u - b)", order=3, a0=1, omega0=1, params={"b": gap})
    from_text = lindstedt.expand("Max(0, u - b)", order=3, a0=1, omega0=1, params={"b": str(Decimal(gap))})
    assert from_float.omega == from_text.omega
    # and it is not the rounded decimal: 0.999999 read as 999999/1000000 gives other coefficients
    rounded = lindstedt.expand("Max(0, u - b)", order=3, a0=1, omega0=1, params={"b": "0.999999"})
    assert rounded.omega[2] != from_float.omega[2]


@pytest.mark.parametrize("name", ["u", "s", "t", "w", "epsilon", "a0", "omega0", "sin", "pi", "E", "Max", "_c", "1c", "lambda"])
def test_reserved_or_invalid_parameter_names_are_refused(name):
    with pytest.raises(ParameterError):
        lindstedt.Oscillator("u**3", params={name: 1})


def test_nnm_release_correction_a1_is_used():
    # one mass, u'' + u + ε (u − 1/2)_+ = 0 released at u(0) = a0 + ε a1: the frequency is ω(ε; a0 + ε a1), so
    # ω_2(a1) − ω_2(0) = a1 dω_1/da0; dω_1/da0 from the scalar engine at two exact amplitudes (central difference,
    # ω_1 is smooth in a0 away from grazing; the difference error O(h²) is far below the tolerance).
    system = UnilateralSystem.one_dof(1, a=1, b="1/2")
    plain = lindstedt.nnm(system, mode=1, a0=1, order=2)
    shifted = lindstedt.nnm(system, mode=1, a0=1, order=2, a1="3/10")
    h = sympy.Rational(1, 10**6)
    up = lindstedt.expand("Max(0, u - 1/2)", order=1, a0=1 + h, omega0=1, numeric=True).omega[1]
    down = lindstedt.expand("Max(0, u - 1/2)", order=1, a0=1 - h, omega0=1, numeric=True).omega[1]
    derivative = float((up - down) / (2 * h))
    assert float(shifted.omega[1]) == pytest.approx(float(plain.omega[1]), rel=1e-25)
    assert float(shifted.omega[2] - plain.omega[2]) == pytest.approx(0.3 * derivative, rel=1e-9)


# --------------------------------------------------------------------------- the one parser
def test_no_module_but_the_parser_turns_text_into_sympy():
    """Static check: outside problems/parsing.py no call of eval/exec/parse_expr/S(), and every sympify is strict."""
    package = pathlib.Path(lindstedt.__file__).parent
    offenders = []
    for path in sorted(package.rglob("*.py")):
        name_in_package = path.relative_to(package).as_posix()
        if name_in_package == "problems/parsing.py":
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            name = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
            if name in {"eval", "parse_expr", "S", "mpmathify"} and not (name == "mpmathify" and name_in_package in ("references/arguments.py", "references/breakpoints.py", "references/trapezoid.py")):
                offenders.append(f"{name_in_package}:{node.lineno} {name}")
            # the code generator, the stable-series compiler and the float families' one-point blocks run the source
            # they generated themselves (from numbers: float reprs and integer indices, never text)
            if name == "exec" and name_in_package not in ("export/codegen.py", "compiled/stable_source.py", "compiled/family.py"):
                offenders.append(f"{name_in_package}:{node.lineno} exec")
            if name == "sympify" and not any(k.arg == "strict" and getattr(k.value, "value", False) is True for k in node.keywords):
                offenders.append(f"{name_in_package}:{node.lineno} sympify without strict=True")
    assert offenders == []


def test_parser_bounds_are_named_in_errors():
    for text, fragment in [
        ("u**3 + " + "+".join(["u"] * 400), "syntax nodes"),
        ("x" * 3000, "longer than"),
        ("1e401*u", "decimal exponent"),
        ("u**201", "exponents are bounded"),
        ("2**100000*u", "bits"),
        ("exp(2000)*u", "exp of a number larger"),
        ("-" * 50 + "u", "nested"),
    ]:
        with pytest.raises(ProblemError, match=fragment):
            lindstedt.Oscillator(text)


# --------------------------------------------------------------------------- grammar fuzz
# Every string reaches the one parser through the public Oscillator; the parameter c is declared when the text names it.
_U = sympy.Symbol("u", real=True)
_C = sympy.Symbol("c", real=True)


def _oscillator(text):
    params = {"c": None} if re.search(r"\bc\b", text) else {}
    return lindstedt.Oscillator(text, a0=1, omega0=1, params=params)


def _pairs():
    """(text, expected sympy value) for random expressions of the accepted grammar."""
    integers = st.integers(-50, 50).map(lambda n: (f"({n})", sympy.Integer(n)))
    decimals = st.decimals(min_value=-100, max_value=100, places=3, allow_nan=False, allow_infinity=False).map(
        lambda d: (f"({d})", sympy.Rational(str(d)))
    )
    names = st.sampled_from([("u", _U), ("c", _C), ("pi", sympy.pi), ("E", sympy.E)])
    leaves = st.one_of(integers, decimals, names)

    def extend(children):
        binary = st.tuples(children, st.sampled_from(["+", "-", "*"]), children).map(
            lambda t: (f"({t[0][0]} {t[1]} {t[2][0]})", {"+": t[0][1] + t[2][1], "-": t[0][1] - t[2][1], "*": t[0][1] * t[2][1]}[t[1]])
        )
        powers = st.tuples(children, st.integers(0, 4), st.sampled_from(["**", "^"])).map(
            lambda t: (f"({t[0][0]}){t[2]}{t[1]}", t[0][1] ** t[1])
        )
        calls = st.tuples(st.sampled_from(["sin", "cos", "exp", "Abs", "atan"]), children).map(
            lambda t: (f"{t[0]}({t[1][0]})", getattr(sympy, t[0])(t[1][1]))
        )
        maxima = st.tuples(children, children).map(lambda t: (f"Max({t[0][0]}, {t[1][0]})", sympy.Max(t[0][1], t[1][1])))
        return st.one_of(binary, powers, calls, maxima)

    return st.recursive(leaves, extend, max_leaves=12)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_pairs())
def test_fuzz_accepted_grammar_reads_exactly_what_it_says(pair):
    text, expected = pair
    magnitudes = [abs(sympy.N(argument, 15)) for function in expected.atoms(sympy.exp) for argument in function.args if argument.is_number]
    if any(magnitude > 900 for magnitude in magnitudes):  # exp of a large number: refused by a size bound, by design
        with pytest.raises(ProblemError, match="larger than 1000|moderate size"):
            _oscillator(text)
    elif expected == 0:
        with pytest.raises(ProblemError, match="identically zero"):
            _oscillator(text)
    elif re.search(r"\bc\b", text) and _C not in expected.free_symbols:  # c cancelled out of the text
        with pytest.raises(ParameterError, match="declared but not used"):
            _oscillator(text)
    else:
        assert sympy.simplify(_oscillator(text).f - expected) == 0


_ALPHABET = "uc0123456789.+-*/^()[]{},:;=<>!~%&|@ '\"\\_fbjexpsinqrtMaHv\n\t"


@settings(max_examples=400, deadline=None)
@given(st.text(alphabet=_ALPHABET, max_size=80))
def test_fuzz_random_text_is_parsed_or_refused_with_a_typed_error(text):
    try:
        with bounded_work():
            result = _oscillator(text).f
    except LindstedtError:
        pass
    else:
        assert isinstance(result, sympy.Expr) and not result.has(sympy.zoo, sympy.nan)


@settings(max_examples=100, deadline=None)
@given(st.floats(allow_nan=False, allow_infinity=False, min_value=-1e300, max_value=1e300))
def test_fuzz_floats_are_read_as_their_exact_binary_value(value):
    # the amplitude a0 is read by the parser's number reader (a0 = 0 is the rest state and is refused)
    if value == 0:
        with pytest.raises(ProblemError, match="a0 = 0"):
            lindstedt.Oscillator("u**3", a0=value)
        return
    exact = lindstedt.Oscillator("u**3", a0=value).a0
    assert exact == sympy.Rational(*Fraction(value).as_integer_ratio())
    assert lindstedt.Oscillator("u**3", a0=str(Decimal(value))).a0 == exact
    assert float(exact) == value and math.isfinite(float(exact))
