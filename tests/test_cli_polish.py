"""The command line's polish: help on every option, --eps evaluation, pretty/plain output, nothing written unasked."""

import argparse
import json
import os
import pathlib
import subprocess
import sys

import mpmath
import pytest

from lindstedt.cli import build_parser, main

ROOT = pathlib.Path(__file__).resolve().parent.parent
CHAIN = str(ROOT / "examples" / "chain2.json")


def _subparsers(parser):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            yield from action.choices.items()


def test_every_option_of_every_subcommand_has_help():
    parser = build_parser()
    commands = dict(_subparsers(parser))
    assert set(commands) == {"expand", "nnm", "forced", "derive", "demo"}
    for name, sub in [("lindstedt", parser), *commands.items()]:
        for action in sub._actions:
            assert action.help and action.help.strip(), f"{name}: {action.option_strings or action.dest} has no help"


def test_format_help_names_the_text_alias():
    expand = dict(_subparsers(build_parser()))["expand"]
    fmt = next(action for action in expand._actions if "--format" in action.option_strings)
    assert fmt.default == "pretty" and {"pretty", "plain", "text", "latex", "json"} <= set(fmt.choices)
    assert "alias" in fmt.help and "plain" in fmt.help


def _last_value(text, prefix):
    line = [line for line in text.splitlines() if line.startswith(prefix)][-1]
    return float(line.rsplit("=", 1)[1])


def test_expand_eps_prints_the_frequency_of_the_expansion(capsys):
    assert main(["expand", "u**3", "--order", "2", "--a0", "1", "--omega0", "1", "--eps", "0.1"]) == 0
    captured = capsys.readouterr()
    assert captured.err == ""
    assert _last_value(captured.out, "ω(ε = 0.1)") == pytest.approx(1 + 3 / 8 * 0.1 - 21 / 256 * 0.01, rel=1e-15)
    assert main(["expand", "u**3", "--order", "2", "--a0", "1", "--omega0", "1", "--eps", "1/10", "--format", "plain"]) == 0
    assert _last_value(capsys.readouterr().out, "omega(0.1)") == pytest.approx(1 + 3 / 8 * 0.1 - 21 / 256 * 0.01, rel=1e-15)
    assert main(["expand", "u**3", "--order", "2", "--a0", "1", "--omega0", "1", "--eps", "0.1", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    # the truncation error's estimate is the first omitted term |ω_3| ε³, ω_3 = 81/2048 (the elliptic series of the
    # exact frequency π√(1+ε)/(2K(m)), m = ε/(2(1+ε)), which the omitted terms are measured against below)
    assert data["evaluated"] == {"epsilon": 0.1, "omega": pytest.approx(1 + 3 / 8 * 0.1 - 21 / 256 * 0.01, rel=1e-15),
                                 "truncation_error_estimate": pytest.approx(81 / 2048 * 0.1**3, rel=1e-12)}
    assert data["omega"] == ["1", "3/8", "-21/256"]
    exact = float(mpmath.pi * mpmath.sqrt(1.1) / (2 * mpmath.ellipk(mpmath.mpf("0.1") / 2.2)))
    error = abs(exact - data["evaluated"]["omega"])
    assert 0.5 * data["evaluated"]["truncation_error_estimate"] <= error <= 2 * data["evaluated"]["truncation_error_estimate"]
    assert main(["expand", "u**3", "--order", "1", "--a0", "1", "--omega0", "1", "--eps", "0.1", "--format", "latex"]) == 0
    assert r"\omega(0.1) \approx 1.0375 \quad (\text{truncation error} \approx 0.00082)" in capsys.readouterr().out


def test_expand_eps_warns_in_one_line_where_the_series_diverges(capsys):
    assert main(["expand", "u**3", "--order", "2", "--a0", "1", "--omega0", "1", "--eps", "5"]) == 0
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: ") and "not converging" in lines[0]
    assert _last_value(captured.out, "ω(ε = 5.0)") == pytest.approx(1 + 3 / 8 * 5 - 21 / 256 * 25, rel=1e-15)


def test_expand_eps_grazing_uses_the_sqrt_gauge(capsys):
    # Max(0, u + 1) at a0 = 1 grazes: omega = 1 + eps/2 - eps^2/8 (in powers of sqrt(eps))
    assert main(["expand", "Max(0, u + 1)", "--order", "2", "--a0", "1", "--omega0", "1", "--eps", "0.01"]) == 0
    out = capsys.readouterr().out
    assert "√ε" in out
    assert _last_value(out, "ω(ε = 0.01)") == pytest.approx(1 + 0.01 / 2 - 0.01**2 / 8, rel=1e-14)


@pytest.mark.parametrize(
    "arguments, fragment",
    [
        (["expand", "u**3", "--order", "1", "--eps", "0.1"], "--a0 A and --omega0 W"),
        (["expand", "u**3 + c*u**5", "--order", "1", "--a0", "1", "--omega0", "1", "--param", "c", "--eps", "0.1"], "NAME=VALUE"),
        (["expand", "u**3", "--order", "1", "--a0", "1", "--omega0", "1", "--eps", "nan"], "--eps"),
        (["expand", "u**3", "--order", "1", "--a0", "1", "--omega0", "1", "--eps", "abc"], "--eps"),
        (["nnm", CHAIN, "--mode", "1", "--a0", "1", "--energy", "0.5"], "--numeric"),
        (["expand", "u**3", "--format", "html"], "invalid choice"),
    ],
)
def test_bad_eps_and_formats_are_one_error_line(arguments, fragment, capsys):
    assert main(arguments) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: ") and fragment in err


def test_pretty_is_the_default_and_plain_keeps_python_syntax(capsys):
    assert main(["expand", "u**3", "--order", "2"]) == 0
    pretty = capsys.readouterr().out
    assert "ω₁" in pretty and "ε" in pretty and "a₀" in pretty and "─" in pretty  # a 2-D fraction bar
    assert "omega_1" not in pretty
    for alias in ("plain", "text"):
        assert main(["expand", "u**3", "--order", "2", "--format", alias]) == 0
        plain = capsys.readouterr().out
        assert "  omega_1 = 3*a0**2/(8*omega0)" in plain.splitlines() and "ω" not in plain
    assert main(["expand", "u**3", "--order", "1", "--u0", "3/5", "--v0", "4/5", "--omega0", "1"]) == 0
    out = capsys.readouterr().out
    assert "φ₀ = -atan(4/3)" in out and "A₀ = 1" in out
    assert main(["expand", "u**2", "--order", "1", "--a0", "1", "--omega0", "1", "--waveforms"]) == 0
    assert "v₁(s) =" in capsys.readouterr().out


def test_nnm_eps_evaluates_the_expansion(capsys):
    import lindstedt

    expansion = lindstedt.nnm(lindstedt.UnilateralSystem.from_json_dict(json.loads(pathlib.Path(CHAIN).read_text())), mode=1, a0=1)
    expected = float(expansion.frequency(0.05))
    assert main(["nnm", CHAIN, "--mode", "1", "--a0", "1", "--eps", "0.05"]) == 0
    out = capsys.readouterr().out
    assert "λ = " in out and "ω₂ = " in out
    assert _last_value(out, "ω(ε = 0.05)") == pytest.approx(expected, rel=1e-15)
    assert main(["nnm", CHAIN, "--mode", "1", "--a0", "1", "--eps", "0.05", "--format", "json"]) == 0
    assert json.loads(capsys.readouterr().out)["evaluated"]["omega"] == pytest.approx(expected, rel=1e-15)
    assert main(["nnm", CHAIN, "--mode", "1", "--a0", "1", "--format", "plain"]) == 0
    assert "  omega_0 = 1.0" in capsys.readouterr().out.splitlines()


def test_help_documents_eps_and_formats(capsys):
    assert main(["expand", "--help"]) == 0
    out = capsys.readouterr().out
    assert "--eps" in out and "pretty" in out and "alias" in out


def test_nothing_is_written_unasked(tmp_path, monkeypatch):
    from lindstedt.cli import demo

    calls = []
    monkeypatch.setattr(demo, "run_demo", lambda order, figure_path: calls.append(figure_path) or "tour")
    monkeypatch.chdir(tmp_path)
    assert main(["demo"]) == 0 and calls == [None]
    assert main(["derive", "--list"]) == 0
    assert main(["expand", "u**3", "--order", "1", "--eps", "0.1", "--a0", "1", "--omega0", "1"]) == 0
    assert list(tmp_path.iterdir()) == []
    assert main(["demo", "--figure", "x.png"]) == 0 and calls[-1] == "x.png"


def test_default_outputs_are_git_ignored():
    ignored = (ROOT / ".gitignore").read_text(encoding="utf-8").split()
    assert "out/" in ignored and "lindstedt-demo.png" in ignored


def test_packaging_metadata_and_markers():
    tomllib = pytest.importorskip("tomllib", reason="tomllib is in the standard library from Python 3.11 on")

    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert (ROOT / "lindstedt" / "py.typed").is_file()
    assert "py.typed" in project["tool"]["setuptools"]["package-data"]["lindstedt"]
    assert "Typing :: Typed" in project["project"]["classifiers"] and project["project"]["keywords"]
    citation = (ROOT / "CITATION.cff").read_text(encoding="utf-8")
    assert "cff-version:" in citation and "title:" in citation and "Junca" in citation


def test_unencodable_terminal_names_the_plain_format():
    result = subprocess.run(
        [sys.executable, "-m", "lindstedt", "expand", "u**3", "--order", "1"],
        capture_output=True, text=True, timeout=120, check=False, env={**os.environ, "PYTHONIOENCODING": "ascii"},
    )
    assert result.returncode == 2 and result.stderr.startswith("error: ") and "--format plain" in result.stderr


def test_demo_figure_is_drawn_by_the_plotting_api(tmp_path, capsys):
    pytest.importorskip("matplotlib", reason="the demo's figure needs matplotlib: pip install 'lindstedt[plot]'")
    path = tmp_path / "demo.png"
    assert main(["demo", "--order", "1", "--figure", str(path)]) == 0
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 10_000
    assert f"written to {path}" in capsys.readouterr().out


def test_demo_figure_suffix_and_missing_matplotlib_are_named(tmp_path, capsys, monkeypatch):
    pytest.importorskip("matplotlib", reason="the suffix is checked against matplotlib's formats")
    assert main(["demo", "--order", "1", "--figure", str(tmp_path / "demo.xyz")]) == 2
    assert "the suffix must name an image format" in capsys.readouterr().err
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)  # as if matplotlib were not installed
    assert main(["demo", "--order", "1", "--figure", str(tmp_path / "demo.png")]) == 2
    assert "pip install 'lindstedt[plot]'" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------- #
# malformed input through every sub-command: one `error:` line, exit 2 (bad input) or 1 (a computation that
# failed), never a traceback nor an untyped "internal failure"
# --------------------------------------------------------------------------- #
FILES = {
    "good": {"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]], "A": [[1, 0]], "b": ["1/10"]},
    "extra": {"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]], "A": [[1, 0]], "b": [0], "X": 1},
    "word": {"M": [[1, "a"], [0, 1]], "K": [[2, -1], [-1, 2]], "A": [[1, 0]], "b": [0]},
    "shape": {"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]], "A": [[1, 0, 3]], "b": [0]},
    "list": [1, 2],
    "string": "x",
    "damping": {"system": {"M": [[1]], "K": [[1]], "A": [[1]], "b": [0]}, "load": [1], "rayleigh": [0, "x"]},
    "noload": {"system": {"M": [[1]], "K": [[1]], "A": [[1]], "b": [0]}},
    "load": {"system": {"M": [[1]], "K": [[1]], "A": [[1]], "b": [0]}, "load": [1, 2], "rayleigh": [0, 0.01]},
    "twice": {"system": {"M": [[1]], "K": [[1]], "A": [[1]], "b": [0]}, "load": [1], "rayleigh": [0, 0.01], "C": [[1]]},
}
RAW = {"truncated": b'{"M": [[1, 0], [0, 1]], "K": [[2', "binary": b"\xff\xfe", "nan": b'{"M": [[NaN]], "K": [[1]], "A": [[1]], "b": [0]}'}
MALFORMED = [
    (2, "expand u**3 --order x"), (2, "expand u**3 --order 1.5"), (2, "expand u**3 --order -3"), (2, "expand u**3 --order 101"),
    (2, "expand u**3 --order 99999999999999999999"), (2, "expand u**3 --a0 x_y"), (2, "expand u**3 --a0 nan"),
    (2, "expand u**3 --a0 inf"), (2, "expand u**3 --a0 0 --omega0 1"), (2, "expand u**3 --omega0 0"), (2, "expand u**3 --omega0 1j"),
    (2, "expand u**3 --omega0 I"), (2, "expand u**3 --param =1"), (2, "expand u**3 --param c=1"), (2, "expand c*u**3 --param c=x+"),
    (2, "expand c*u**3 --param u=1"), (2, "expand c*u**3 --param c=1 --param c=2"), (2, "expand u**3 --precision 3"),
    (2, "expand u**3 --precision x"), (2, "expand u**3 --normalization foo"), (2, "expand u**3 --a1 nan"),
    (2, "expand u**3 --u0 1 --a0 1"), (2, "expand u**3 --u0 0 --v0 0"), (2, "expand u**3 --eps 1e999 --a0 1 --omega0 1"),
    (2, "expand u**3 --eps 1/0 --a0 1 --omega0 1"), (2, "expand u** --order 1"), (2, "expand x**3"), (2, "expand 1/u"),
    (2, "expand u**3 --order"), (2, "expand u**3 --bogus"), (2, "expand --order 2"), (2, "expand u**3 --format xml"),
    (2, "expand Max(0,u-b) --param b --a0 1 --omega0 1 --eps 0.1"),
    (2, "nnm /nonexistent/system.json --mode 1 --a0 1"), (2, "nnm {truncated} --mode 1 --a0 1"), (2, "nnm {list} --mode 1 --a0 1"),
    (2, "nnm {extra} --mode 1 --a0 1"), (2, "nnm {word} --mode 1 --a0 1"), (2, "nnm {shape} --mode 1 --a0 1"),
    (2, "nnm {binary} --mode 1 --a0 1"), (2, "nnm {nan} --mode 1 --a0 1"), (2, "nnm {directory} --mode 1 --a0 1"),
    (2, "nnm {good} --mode 0 --a0 1"), (2, "nnm {good} --mode 3 --a0 1"), (2, "nnm {good} --mode x --a0 1"), (2, "nnm {good} --mode 1"),
    (2, "nnm {good} --a0 1"), (2, "nnm {good} --mode 1 --a0 0"), (2, "nnm {good} --mode 1 --a0 1 --order 50"),
    (2, "nnm {good} --mode 1 --a0 1 --precision 2"), (2, "nnm {good} --mode 1 --a0 1 --eps x"),
    (2, "nnm {good} --mode 1 --numeric --a0 1"), (2, "nnm {good} --mode 1 --numeric --eps 1"),
    (2, "nnm {good} --mode 1 --numeric --a0 1 --energy 1 --eps 1"), (2, "nnm {good} --mode 1 --numeric --energy 1 --eps nan"),
    (1, "nnm {good} --mode 1 --numeric --a0 0 --eps 1"), (1, "nnm {good} --mode 1 --numeric --energy 0 --eps 1"),
    (2, "forced u**3"), (2, "forced u**3 --eps x --at 1"), (2, "forced u**3 --eps -1 --at 1"), (2, "forced u**3 --eps 0.1 --at x"),
    (2, "forced u**3 --eps 0.1 --at -1"), (2, "forced u**3 --eps 0.1 --at inf"), (2, "forced u**3 --eps 0.1 --from x --to 1"),
    (2, "forced u**3 --eps 0.1 --from 0 --to 1"), (2, "forced u**3 --eps 0.1 --at 1 --omega0 0"), (2, "forced u**3 --eps 0.1 --at 1 --zeta x"),
    (2, "forced u**3 --eps 0.1 --at 1 --forcing 0"), (2, "forced c*u**3 --eps 0.1 --at 1"), (2, "forced c*u**3 --eps 0.1 --at 1 --param c"),
    (2, "forced u**3 --eps 0.1 --at 1 --param d=1"), (2, "forced c*u**3 --eps 0.1 --at 1 --param c=1 --param c=1"),
    (2, "forced u**3 --eps 0.1 --at 1 --method foo"), (2, "forced u**3 --eps 0.1 --method multiple-scales --order 3"),
    (2, "forced Max(0,u) --eps 0.1 --method multiple-scales --order 2"), (2, "forced u**3 --eps 0.1 --method multiple-scales --from 0.9"),
    (2, "forced u**3 --eps 0.1 --from 0.9 --to 1.1 --figure noext"), (2, "forced /nonexistent.json --eps 0.1 --at 1"),
    (2, "forced {truncated} --eps 0.1 --at 1"), (2, "forced {damping} --eps 0.1 --at 1"), (2, "forced {noload} --eps 0.1 --at 1"),
    (2, "forced {load} --eps 0.1 --at 1"), (2, "forced {twice} --eps 0.1 --at 1"), (2, "forced {string} --eps 0.1 --at 1"),
    (2, "forced {binary} --eps 0.1 --at 1"), (2, "forced {good} --eps 0.1 --at 1"), (2, "forced {directory} --eps 0.1 --at 1"),
    (2, "forced u** --eps 0.1 --at 1"), (2, "forced u**3 --eps 0.1 --at 1 --bogus"),
    (2, "derive"), (2, "derive nosuch"), (2, "derive ../../etc/passwd"), (2, "derive duffing --order x"), (2, "derive duffing --order -1"),
    (2, "derive duffing --order 1000"), (2, "derive duffing --format pretty"),
    (2, "demo --order x"), (2, "demo --order -1"), (2, "demo --order 1000"), (2, "demo --bogus"), (2, ""), (2, "bogus"), (2, "--bogus"),
]


@pytest.fixture
def malformed_files(tmp_path):
    paths = {"directory": str(tmp_path / "directory.json")}
    (tmp_path / "directory.json").mkdir()
    for name, data in FILES.items():
        (tmp_path / f"{name}.json").write_text(json.dumps(data), encoding="utf-8")
        paths[name] = str(tmp_path / f"{name}.json")
    for name, data in RAW.items():
        (tmp_path / f"{name}.json").write_bytes(data)
        paths[name] = str(tmp_path / f"{name}.json")
    return paths


@pytest.mark.parametrize("status, command", MALFORMED)
def test_malformed_input_is_one_typed_error_line(status, command, malformed_files, capsys):
    assert main([word.format(**malformed_files) for word in command.split()]) == status
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), captured.err
    assert "internal failure" not in lines[0] and "Traceback" not in captured.err
    if status == 2:
        assert captured.out == ""  # bad input computes nothing


def test_a_library_warning_is_one_line_too():
    # ε = 1e300 overflows inside the flow (numpy RuntimeWarnings): each is one `warning:` line, then the failure
    result = subprocess.run([sys.executable, "-m", "lindstedt", "nnm", CHAIN, "--mode", "1", "--numeric", "--energy", "1",
                             "--eps", "1e300"], capture_output=True, text=True, timeout=300, check=False)
    lines = result.stderr.splitlines()
    assert result.returncode == 1 and lines[-1].startswith("error: ") and "Traceback" not in result.stderr
    assert lines[:-1] and all(line.startswith("warning: ") and line.endswith("(RuntimeWarning)") for line in lines[:-1])


# -- issue 23, item 6: output streams, results that overflow a float, pickling ---------------------------------


def _run_cli(*arguments, stdout=subprocess.PIPE):
    return subprocess.run([sys.executable, "-m", "lindstedt", *arguments], stdout=stdout, stderr=subprocess.PIPE,
                          text=True, timeout=120)


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_a_full_output_device_is_one_error_line():
    with open("/dev/full", "w") as full:
        run = _run_cli("expand", "u**3", "--a0", "1", "--omega0", "1", stdout=full)
    assert run.returncode == 1
    assert run.stderr == "error: cannot write output: No space left on device\n"


@pytest.mark.parametrize("arguments", [
    ["derive", "duffing", "--order", "2", "--output", "{blocker}/sub"],
    pytest.param(["demo", "--order", "2", "--figure", "{blocker}/x.png"], marks=pytest.mark.slow),  # 5 s each
    pytest.param(["forced", "u**3", "--eps", "0.1", "--from", "0.9", "--to", "1.1", "--figure", "{blocker}/x.png"],
                 marks=pytest.mark.slow),
])
def test_an_unwritable_output_path_is_one_error_line(tmp_path, arguments):
    # a path under a regular file can be written by nobody, root included
    blocker = tmp_path / "file"
    blocker.write_text("")
    run = _run_cli(*[argument.format(blocker=blocker) for argument in arguments])
    assert run.returncode == 2, run.stderr
    assert len(run.stderr.splitlines()) == 1 and run.stderr.startswith("error: ") and "Traceback" not in run.stderr
    assert "Not a directory" in run.stderr or "not a directory" in run.stderr.lower()


def test_to_json_writes_null_for_a_coefficient_beyond_a_float():
    import dataclasses

    import mpmath

    import lindstedt

    mode = lindstedt.nnm(lindstedt.UnilateralSystem.one_dof(1, a=1, b=0), mode=1, a0=1, order=2)
    huge = dataclasses.replace(mode, omega=(mode.omega[0], mpmath.mpf("1e400"), mode.omega[2]))
    data = json.loads(huge.to_json())  # strict JSON: no Infinity
    # b = 0: the bilinear oscillator, ω(ε) = 2√(1+ε)/(1+√(1+ε)) = 1 + ε/4 − ε²/8 + …, so ω_2 = -1/8 exactly
    assert data["omega"][1] is None and data["omega"][2] == -0.125
    assert data["omega_digits"][1].endswith("e+399") or data["omega_digits"][1].endswith("e+400")


def test_an_nnm_expansion_pickles_as_its_recipe():
    import pickle

    import lindstedt

    system = lindstedt.UnilateralSystem(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], A=[[1, 0]], b=["1/10"])
    mode = lindstedt.nnm(system, mode=2, a0=1, order=2, precision=40)
    copy = pickle.loads(pickle.dumps(mode))
    assert copy.omega == mode.omega and copy.release_modal == mode.release_modal and copy.digits == mode.digits
    assert copy.problem == mode.problem
    assert float(copy.frequency(0.01)) == float(mode.frequency(0.01))
