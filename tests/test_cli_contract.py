"""The command-line contract on every path (issue 23, item 6).

Every failure of ``lindstedt COMMAND …`` is exactly one stderr line ``error: <message>``, no traceback, nothing on
stdout, and the exit status says why: 2 for bad input (arguments, files, values outside what a method takes),
1 for a computation that failed or an output that cannot be written, 130 for an interrupt.  The table below
drives each command (``expand``, ``nnm``, ``forced`` exact and multiple-scales, ``derive``, ``demo``) with each
bad-input class of the hostile-input audit — malformed and hostile f strings, complex constants, bad numbers for
every numeric option, bad orders, bad system files, unwritable outputs, unknown options — in-process
(``lindstedt.cli.main``).  A subprocess is used only where the process itself is the subject: stdout on
``/dev/full``.  Ctrl-C in a running command is tests/test_cli_signals.py; file sizes, depth and entry counts
are tests/test_bounded_inputs.py — only the classes they lack are here (FIFOs, empty and non-object files,
entries beyond a float, unreadable paths).
"""

from __future__ import annotations

import json
import os
import signal
import stat
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from lindstedt.cli import main

BAD, FAILED = 2, 1

# --------------------------------------------------------------------------------------------- the commands
EXPAND = ["--a0", "1", "--omega0", "1", "--format", "plain"]
FORCED_AT = ["--eps", "0.1", "--at", "1", "--format", "plain"]
MULTIPLE_SCALES = ["--eps", "0.1", "--method", "multiple-scales", "--from", "0.9", "--to", "1.1", "--format", "plain"]
NNM = ["--mode", "1", "--a0", "1", "--format", "plain"]
NNM_NUMERIC = ["--mode", "1", "--numeric", "--a0", "1", "--eps", "0.1", "--format", "plain"]

#: each way of running a nonlinearity f given as text
F_COMMANDS = {
    "expand": lambda f: ["expand", f, *EXPAND],
    "forced": lambda f: ["forced", f, *FORCED_AT],
    "forced-ms": lambda f: ["forced", f, *MULTIPLE_SCALES],
}

#: malformed and hostile nonlinearities: each is refused by the parser or the problem (bad input, exit 2)
HOSTILE_F = [
    # syntax
    "u**", "u**3)", "(u", "", "   ", "u**3; u", "u**3 = 0", "lambda u: u", "u if u else 0", "[u]", "u**3,",
    # names the grammar does not know
    "x**3", "foo(u)", "u**3 + epsilon", "u**3 + t", "Symbol('u')", "eval('u')",
    # dunder and attribute access, code
    "u.__class__", "__import__('os').system('true')", "().__class__.__bases__[0]", "u.subs(u, 1)", "getattr(u, 'func')",
    # exponents beyond the bound, before and after sympy combines powers
    "u**10**10", "u**(10**100)", "u**1e400", "(u**200)**200", "((u+1)**200)**200", "(((u**200)**200)**200)**200",
    "u**3*exp(10**10)",
    # constants that are not real
    "sqrt(-1)*u**3", "log(-1)*u**3", "acos(2)*u**3", "(-8)**(1/3)*u**3", "I*u**3", "u**3 + 1j", "zoo*u**3",
    "nan*u**3", "oo*u**3",
    # no Taylor series at u = 0 (the orbit passes through it)
    "1/u", "u**-1", "log(u)", "u**3/u**4",
    # look-alikes (a full-width ｕ is u itself: Python reads identifiers in NFKC)
    "u³", "u²",
    # unbounded text
    "u+" * 50_000 + "u", "(" * 5_000 + "u" + ")" * 5_000,
]

#: parameters that are not real numbers (f = c u³ with --param c=VALUE)
BAD_PARAMETERS = ["sqrt(-1)", "I", "log(-1)", "nan", "oo", "1/0", "", "__import__('os')", "u", "epsilon"]

#: values that are no real number, for every numeric option
NOT_NUMBERS = ["nan", "inf", "-inf", "1e400", "1/0", "sqrt(-1)", "", "None", "True", "one", "__import__('os')", "1,5"]
#: every numeric option, with the rest of a command that is otherwise good (the value goes in VALUE)
NUMERIC_OPTIONS = {
    "expand --eps": ["expand", "u**3", *EXPAND, "--eps", "VALUE"],
    "expand --a1": ["expand", "u**3", *EXPAND, "--a1", "VALUE"],
    "expand --u0": ["expand", "u**3", "--omega0", "1", "--u0", "VALUE", "--v0", "1"],
    "expand --v0": ["expand", "u**3", "--omega0", "1", "--u0", "1", "--v0", "VALUE"],
    "expand --param": ["expand", "c*u**3", *EXPAND, "--param", "c=VALUE"],
    "nnm --eps": ["nnm", "{system}", *NNM, "--eps", "VALUE"],
    "nnm --a0": ["nnm", "{system}", "--mode", "1", "--a0", "VALUE"],
    "nnm --numeric --eps": ["nnm", "{system}", "--mode", "1", "--numeric", "--a0", "1", "--eps", "VALUE"],
    "nnm --numeric --a0": ["nnm", "{system}", "--mode", "1", "--numeric", "--a0", "VALUE", "--eps", "0.1"],
    "nnm --numeric --energy": ["nnm", "{system}", "--mode", "1", "--numeric", "--energy", "VALUE", "--eps", "0.1"],
    "forced --eps": ["forced", "u**3", "--eps", "VALUE", "--at", "1"],
    "forced --omega0": ["forced", "u**3", *FORCED_AT, "--omega0", "VALUE"],
    "forced --zeta": ["forced", "u**3", *FORCED_AT, "--zeta", "VALUE"],
    "forced --forcing": ["forced", "u**3", *FORCED_AT, "--forcing", "VALUE"],
    "forced --param": ["forced", "c*u**3", *FORCED_AT, "--param", "c=VALUE"],
    "forced --at": ["forced", "u**3", "--eps", "0.1", "--at", "VALUE"],
    "forced --from": ["forced", "u**3", "--eps", "0.1", "--from", "VALUE", "--to", "1.1"],
    "forced --to": ["forced", "u**3", "--eps", "0.1", "--from", "0.9", "--to", "VALUE"],
    "forced-ms --eps": ["forced", "u**3", *MULTIPLE_SCALES[2:], "--eps", "VALUE"],
    "forced-ms --from": ["forced", "u**3", "--eps", "0.1", "--method", "multiple-scales", "--from", "VALUE", "--to", "1.1"],
    "forced-ms --forcing": ["forced", "u**3", *MULTIPLE_SCALES, "--forcing", "VALUE"],
}
#: words are symbol names for expand's --a0, --omega0 (symbolic expansions): there only the non-symbols
EXPAND_SYMBOLIC = {
    "expand --a0": ["expand", "u**3", "--omega0", "1", "--a0", "VALUE"],
    "expand --omega0": ["expand", "u**3", "--a0", "1", "--omega0", "VALUE"],
}
NOT_SYMBOLS = ["nan", "inf", "-inf", "1/0", "sqrt(-1)", "", "__import__('os')", "1,5"]

#: every integer option (orders, precision, mode, size limits)
INTEGER_OPTIONS = {
    "expand --order": ["expand", "u**3", *EXPAND, "--order", "VALUE"],
    "expand --precision": ["expand", "sin(u)", *EXPAND, "--precision", "VALUE"],
    "nnm --order": ["nnm", "{system}", *NNM, "--order", "VALUE"],
    "nnm --precision": ["nnm", "{system}", *NNM, "--precision", "VALUE"],
    "nnm --mode": ["nnm", "{system}", "--a0", "1", "--mode", "VALUE"],
    "nnm --max-dof": ["nnm", "{system}", *NNM, "--max-dof", "VALUE"],
    "forced --max-springs": ["forced", "{forced}", *FORCED_AT, "--max-springs", "VALUE"],
    "forced-ms --order": ["forced", "u**3", *MULTIPLE_SCALES, "--order", "VALUE"],
    "derive --order": ["derive", "duffing", "--order", "VALUE"],
    "demo --order": ["demo", "--order", "VALUE"],
}
NOT_COUNTS = ["-1", "1.5", "x", "", "1e3", "nan", "0x10", "99999999999999999999", "10000000"]

#: every command with an option, an argument or a flag value it does not take
UNKNOWN = [
    ["expand", "u**3", *EXPAND, "--bogus"], ["expand", "u**3", *EXPAND, "-x"], ["expand", "u**3", "extra", *EXPAND],
    ["expand", "u**3", *EXPAND, "--waveforms=yes"], ["expand", "u**3", *EXPAND, "--normalization", "other"],
    ["nnm", "{system}", *NNM, "--bogus"], ["nnm", "{system}", "extra", *NNM], ["nnm", "{system}", *NNM, "--format", "xml"],
    ["forced", "u**3", *FORCED_AT, "--bogus"], ["forced", "u**3", "extra", *FORCED_AT], ["forced", "u**3", *FORCED_AT, "--method", "euler"],
    ["derive", "duffing", "--bogus"], ["derive", "duffing", "extra"], ["derive", "--list", "--format", "pdf"],
    ["demo", "--bogus"], ["demo", "extra"], ["--bogus"], ["bogus"], [], ["expand"], ["nnm"], ["forced"],
]

# ------------------------------------------------------------------------------------------------ the files
GOOD_SYSTEM = {"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]], "A": [[1, 0]], "b": ["1/10"]}
GOOD_FORCED = {"system": {"M": [[1]], "K": [[1]], "A": [[1]], "b": ["1/10"]}, "load": [1], "rayleigh": [0, "1/50"]}


def _system(**entries):
    return json.dumps({**GOOD_SYSTEM, **entries})


def _forced(**entries):
    return json.dumps({**GOOD_FORCED, **entries})


#: files that hold no system (contents): each is one error line, exit 2, for nnm and forced alike
BAD_FILES = {
    "empty": "", "blank": " \n\t", "null": "null", "number": "1", "array": "[]", "object": "{}", "string": '"M"',
    "trailing": json.dumps(GOOD_SYSTEM) + " x", "two-objects": json.dumps(GOOD_SYSTEM) * 2,
    "bom": "\ufeff" + json.dumps(GOOD_SYSTEM), "single-quotes": json.dumps(GOOD_SYSTEM).replace('"', "'"),
    "comment": "// a system\n" + json.dumps(GOOD_SYSTEM), "nul": json.dumps(GOOD_SYSTEM)[:20] + "\0",
    "beyond-float": _system(M=[[1e400, 0], [0, 1]]).replace("Infinity", "1e400"),
    "long-integer": _system(K=[[2, -1], [-1, 2]]).replace("2", "9" * 5000, 1),  # beyond Python's 4300-digit int limit
    "boolean": _system(M=[[True, 0], [0, 1]]),
    "null-entry": _system(b=[None]),
    "code-entry": _system(b=["__import__('os').system('true')"]),
    "complex-entry": _system(b=["sqrt(-1)"]),
    "nan-string": _system(b=["nan"]),
    "nested-entry": _system(b=[[0]]),
    "object-entry": _system(b=[{"value": 0}]),
    "negative-mass": _system(M=[[-1, 0], [0, 1]]),
    "singular-mass": _system(M=[[1, 1], [1, 1]]),
    "unsymmetric": _system(K=[[2, -1], [0, 2]]),
    "ragged": _system(K=[[2, -1], [-1]]),
    "mismatched-b": _system(b=[0, 0]),
    "missing-key": json.dumps({key: value for key, value in GOOD_SYSTEM.items() if key != "K"}),
}
#: forced files that are wrong in their own keys
BAD_FORCED_FILES = {
    "load-word": _forced(load=["x"]), "load-complex": _forced(load=["sqrt(-1)"]), "load-zero": _forced(load=[0]),
    "load-beyond-float": _forced(load=[1e400]).replace("Infinity", "1e400"), "rayleigh-negative": _forced(rayleigh=[0, -1]),
    "rayleigh-short": _forced(rayleigh=[0]), "damping-both": _forced(modal_damping=[0.01]),
    "system-list": _forced(system=[1]), "system-missing": json.dumps({"load": [1], "rayleigh": [0, 0]}),
    "unknown-key": _forced(extra=1),
}


#: options read as exact numbers (symbolic arithmetic), where 1e400 is a number like any other
EXACT_OPTIONS = {"expand --a1", "expand --u0", "expand --v0", "nnm --a0"}

#: extreme but real values, refused up front naming the fix
EXTREME = {
    "forced-1/u": ["forced", "1/u", *FORCED_AT],
    "forced-log(u)-sweep": ["forced", "log(u)", "--eps", "0.1", "--from", "0.9", "--to", "1.1"],
    "forced-omega0-1e400": ["forced", "u**3", *FORCED_AT, "--omega0", "1e400"],
    "forced-zeta-1e400": ["forced", "u**3", *FORCED_AT, "--zeta", "1e400"],
    "forced-forcing-1e400": ["forced", "u**3", *FORCED_AT, "--forcing", "1e400"],
    "forced-ms-forcing-1e400": ["forced", "u**3", *MULTIPLE_SCALES, "--forcing", "1e400"],
    "forced-at-1e300": ["forced", "u**3", "--eps", "0.1", "--at", "1e300"],
    "nnm-max-dof-1e20": ["nnm", "{file:long-integer}", *NNM, "--max-dof", "99999999999999999999"],
}

#: beyond what the float flows follow (refused with the reason, exit 2), and runaway requests refused up front by their
#: cost estimate under a budget (``--budget``; exit 2, in well under a second: nothing is computed)
BEYOND_FLOAT_RANGE = {
    "forced-forcing-1e300": ["forced", "u**3", *FORCED_AT, "--forcing", "1e300"],
    "forced-eps-1e300": ["forced", "u**3", "--eps", "1e300", "--at", "1"],
    "forced-zeta-1e300": ["forced", "u**3", *FORCED_AT, "--zeta", "1e300"],
    "forced-omega0-1e300": ["forced", "u**3", *FORCED_AT, "--omega0", "1e300"],
    "forced-ms-forcing-1e300": ["forced", "u**3", *MULTIPLE_SCALES, "--forcing", "1e300"],
    "expand --u0=1e400": ["expand", "u**3", "--omega0", "1", "--u0", "1e400", "--v0", "1"],
    "expand --v0=1e400": ["expand", "u**3", "--omega0", "1", "--u0", "1", "--v0", "1e400"],
    "expand --u0=1e200": ["expand", "u**3", "--omega0", "1", "--u0", "1e200", "--v0", "1"],  # its square is not
    "nnm --a0=1e400": ["nnm", "{system}", "--mode", "1", "--a0", "1e400", "--format", "plain"],
    "expand-f-Max(0,u-1/5)**200-budget": ["expand", "Max(0, u - 1/5)**200", *EXPAND, "--budget", "10"],
    "forced-ms-f-Max(0,u-1/5)**200-budget": ["forced", "Max(0, u - 1/5)**200", *MULTIPLE_SCALES, "--budget", "10"],
    "expand-gap-order-60": ["expand", "Max(0, u - 1/3)", "--order", "60", *EXPAND],
}
#: a computation that runs and fails (exit 1, its failure printed): a degree-200 law driven at resonance, whose
#: DOP853 flow is too steep to converge and whose multiple-scales start is beyond the budget
FAILED_COMPUTATIONS = {
    "forced-f-Max(0,u-1/5)**200": ["forced", "Max(0, u - 1/5)**200", *FORCED_AT, "--budget", "10"],
}


def _cases():
    cases = []
    for name, command in F_COMMANDS.items():
        cases += [pytest.param(BAD, command(f), id=f"{name}-f-{f[:30]!r}") for f in HOSTILE_F]
    for value in BAD_PARAMETERS:
        cases += [pytest.param(BAD, ["expand", "c*u**3", *EXPAND, "--param", f"c={value}"], id=f"expand-param-{value!r}"),
                  pytest.param(BAD, ["forced", "c*u**3", *FORCED_AT, "--param", f"c={value}"], id=f"forced-param-{value!r}")]
    for option, command in NUMERIC_OPTIONS.items():
        for value in NOT_NUMBERS:
            if value == "1e400" and option in EXACT_OPTIONS:
                continue  # an exact number there (symbolic arithmetic): see BEYOND_FLOAT
            cases.append(pytest.param(BAD, [v if v != "VALUE" else value for v in command], id=f"{option}={value!r}"))
    for option, command in EXPAND_SYMBOLIC.items():
        cases += [pytest.param(BAD, [v if v != "VALUE" else value for v in command], id=f"{option}={value!r}") for value in NOT_SYMBOLS]
    for option, command in INTEGER_OPTIONS.items():
        values = NOT_COUNTS if "--max-" not in option else NOT_COUNTS[:-2]  # a large size limit is the user's to raise
        cases += [pytest.param(BAD, [v if v != "VALUE" else value for v in command], id=f"{option}={value!r}") for value in values]
    cases += [pytest.param(BAD, command, id="unknown-" + "-".join(command)[:40]) for command in UNKNOWN]
    for name in [*BAD_FILES, "missing", "directory", "under-a-file"]:
        cases += [pytest.param(BAD, ["nnm", f"{{file:{name}}}", *NNM], id=f"nnm-file-{name}"),
                  pytest.param(BAD, ["nnm", f"{{file:{name}}}", *NNM_NUMERIC], id=f"nnm-numeric-file-{name}"),
                  pytest.param(BAD, ["forced", f"{{file:{name}}}", *FORCED_AT], id=f"forced-file-{name}")]
    cases += [pytest.param(BAD, ["forced", f"{{file:{name}}}", *FORCED_AT], id=f"forced-file-{name}") for name in BAD_FORCED_FILES]
    cases += [pytest.param(BAD, command, id=name) for name, command in EXTREME.items()]
    cases += [pytest.param(BAD, command, id=name) for name, command in BEYOND_FLOAT_RANGE.items()]
    return cases


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    directory = tmp_path_factory.mktemp("files")
    paths = {"system": directory / "system.json", "forced": directory / "forced.json",
             "file:missing": directory / "missing.json", "file:directory": directory / "directory.json",
             "file:under-a-file": directory / "system.json" / "x.json"}
    paths["system"].write_text(json.dumps(GOOD_SYSTEM))
    paths["forced"].write_text(json.dumps(GOOD_FORCED))
    paths["file:directory"].mkdir()
    for name, text in {**BAD_FILES, **BAD_FORCED_FILES}.items():
        paths[f"file:{name}"] = directory / f"{name}.json"
        paths[f"file:{name}"].write_text(text, encoding="utf-8")
    return {name: str(path) for name, path in paths.items()}


def _argv(command, files):
    return [files[word[1:-1]] if word.startswith("{") and word.endswith("}") and word[1:-1] in files else word for word in command]


def assert_contract(status, expected, out, err):
    """One ``error:`` line, no traceback, nothing on stdout, the expected status."""
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert "Traceback" not in err and "internal failure" not in err, err
    assert out == "", out
    assert status == expected, err


@pytest.mark.parametrize("expected, command", _cases())
def test_every_bad_input_is_one_error_line(expected, command, files, capsys):
    status = main(_argv(command, files))
    captured = capsys.readouterr()
    assert_contract(status, expected, captured.out, captured.err)


@pytest.mark.parametrize("command", list(FAILED_COMPUTATIONS.values()), ids=list(FAILED_COMPUTATIONS))
def test_a_failed_computation_prints_its_failure_and_one_error_line(command, files, capsys):
    status = main(_argv(command, files))
    captured = capsys.readouterr()
    assert status == FAILED
    assert "FAILED" in captured.out and "Traceback" not in captured.err and "internal failure" not in captured.err
    assert captured.err.splitlines() == ["error: the computation did not succeed (see its message above)"]


# ------------------------------------------------------------------------------------ special files and paths
def _fifo(tmp_path, feed):
    """A FIFO and the thread that writes ``feed(handle)`` into it once a reader opens it."""
    path = tmp_path / "system.json"
    os.mkfifo(path)

    def writer():
        try:
            with open(path, "wb") as handle:  # blocks until the command opens the FIFO
                feed(handle)
        except BrokenPipeError:  # the command stopped reading (a size limit): expected
            pass

    thread = threading.Thread(target=writer, daemon=True)
    thread.start()
    return str(path), thread


def _endless(handle):
    while True:
        handle.write(b" " * 65536)


FIFO_FEEDS = {
    "malformed": (lambda handle: handle.write(b'{"M": [[1')),
    "endless": _endless,
    "empty": (lambda handle: None),
}


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
@pytest.mark.parametrize("command", [["nnm", "FILE", *NNM], ["forced", "FILE", *FORCED_AT]], ids=["nnm", "forced"])
@pytest.mark.parametrize("feed", FIFO_FEEDS, ids=list(FIFO_FEEDS))
def test_a_fifo_that_holds_no_system_is_one_error_line(tmp_path, capsys, command, feed):
    path, writer = _fifo(tmp_path, FIFO_FEEDS[feed])
    status = main([path if word == "FILE" else word for word in command])
    writer.join()
    captured = capsys.readouterr()
    assert_contract(status, BAD, captured.out, captured.err)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_a_fifo_is_read_like_a_file(tmp_path, capsys):
    # process substitution (`lindstedt nnm <(generate)`) hands the command a pipe: it must stay readable
    path, writer = _fifo(tmp_path, lambda handle: handle.write(json.dumps(GOOD_SYSTEM).encode()))
    status = main(["nnm", path, *NNM])
    writer.join()
    captured = capsys.readouterr()
    assert status == 0 and captured.err == "" and captured.out.startswith("NNM of mode 1"), captured.err


@pytest.mark.skipif(not hasattr(os, "mkfifo") or sys.platform == "win32", reason="needs FIFOs and POSIX signals")
def test_ctrl_c_while_waiting_on_a_silent_fifo_is_one_line_and_130(tmp_path, capsys):
    # the writer opens the FIFO and never writes: the command waits for input, and Ctrl-C ends the wait
    path, writer = _fifo(tmp_path, lambda handle: os.kill(os.getpid(), signal.SIGINT))
    status = main(["nnm", path, *NNM])
    writer.join()
    captured = capsys.readouterr()
    assert (status, captured.err, captured.out) == (130, "error: interrupted\n", "")


@pytest.mark.skipif(sys.platform == "win32" or os.geteuid() == 0, reason="root reads every file; POSIX permissions")
@pytest.mark.parametrize("command", [["nnm", "FILE", *NNM], ["forced", "FILE", *FORCED_AT]], ids=["nnm", "forced"])
def test_an_unreadable_file_is_one_error_line(tmp_path, capsys, command):
    path = tmp_path / "system.json"
    path.write_text(json.dumps(GOOD_SYSTEM))
    path.chmod(0)
    status = main([str(path) if word == "FILE" else word for word in command])
    captured = capsys.readouterr()
    assert_contract(status, BAD, captured.out, captured.err)
    assert "Permission denied" in captured.err


@pytest.mark.parametrize("command", [
    ["demo", "--order", "1", "--figure", "{missing}/demo.png"],
    ["demo", "--order", "1", "--figure", "{directory}"],
    ["forced", "u", "--eps", "0.1", "--zeta", "0.1", "--from", "0.5", "--to", "0.6", "--figure", "{missing}/forced.png"],
    ["forced", "u", "--eps", "0.1", "--zeta", "0.1", "--from", "0.5", "--to", "0.6", "--figure", "{directory}"],
], ids=["demo-missing-directory", "demo-a-directory", "forced-missing-directory", "forced-a-directory"])
def test_an_unwritable_figure_is_one_error_line(tmp_path, capsys, command):
    (tmp_path / "figure.png").mkdir()  # a directory named like an image
    paths = {"missing": str(tmp_path / "no" / "such"), "directory": str(tmp_path / "figure.png")}
    status = main([word.format(**paths) for word in command])
    captured = capsys.readouterr()
    assert_contract(status, BAD, captured.out, captured.err)
    assert sorted(path.name for path in tmp_path.iterdir()) == ["figure.png"]  # nothing created on the way


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_every_command_on_a_full_stdout_is_one_error_line(files):
    """stdout on a full device: every command ends with one line and status 1 (run at once, in subprocesses)."""
    commands = {
        "expand": ["expand", "u**3", *EXPAND],
        "nnm": ["nnm", files["system"], *NNM],
        "forced": ["forced", "u**3", *FORCED_AT],
        "forced-ms": ["forced", "u**3", *MULTIPLE_SCALES],
        "derive": ["derive", "--list"],
        "demo": ["demo", "--order", "1"],
    }
    with open("/dev/full", "w") as full:
        running = {name: subprocess.Popen([sys.executable, "-m", "lindstedt", *command], stdout=full,
                                          stderr=subprocess.PIPE, text=True) for name, command in commands.items()}
        results = {name: (process.wait(timeout=300), process.stderr.read()) for name, process in running.items()}
    for process in running.values():
        process.stderr.close()
    expected = (FAILED, "error: cannot write output: No space left on device\n")
    assert {name: result for name, result in results.items() if result != expected} == {}
