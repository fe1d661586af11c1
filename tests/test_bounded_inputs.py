"""Bounded input files (issue 23, item 4): the JSON files of ``lindstedt nnm`` and ``lindstedt forced`` are read
with a size limit checked before the file is in memory, a depth limit and entry-count limits (degrees of freedom,
springs), each refused with one ``error:`` line naming the limit and the option that raises it, exit status 2."""

import json
import os
import subprocess
import sys

import pytest

from lindstedt.cli import main

NNM = ["--mode", "1", "--a0", "1", "--format", "plain"]
FORCED = ["--eps", "0.1", "--at", "1", "--format", "plain"]


def _chain(n, springs=1):
    """An n-mass chain M = I, K = tridiag(-1, 2, -1), with ``springs`` unilateral springs on mass 1."""
    return {
        "M": [[int(i == j) for j in range(n)] for i in range(n)],
        "K": [[2 if i == j else -1 if abs(i - j) == 1 else 0 for j in range(n)] for i in range(n)],
        "A": [[int(j == 0) for j in range(n)] for _ in range(springs)],
        "b": [f"{k + 1}/100" for k in range(springs)],
    }


def _forced(n):
    return {"system": _chain(n), "load": [1] + [0] * (n - 1), "rayleigh": ["0", "1/50"]}


def _write(tmp_path, name, data):
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else json.dumps(data))
    return str(path)


def _cli(*arguments):
    """Run the installed command in a subprocess: (exit status, stdout, stderr)."""
    run = subprocess.run([sys.executable, "-m", "lindstedt", *arguments], capture_output=True, text=True, timeout=120)
    return run.returncode, run.stdout, run.stderr


def _refused(status, stdout, stderr, *words):
    assert status == 2, stderr
    assert stdout == ""
    assert len(stderr.splitlines()) == 1 and stderr.startswith("error: "), stderr
    assert "Traceback" not in stderr
    for word in words:
        assert word in stderr, stderr


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
def test_a_file_that_never_ends_is_refused_at_the_size_limit():
    # before: read until memory ran out (7.7 GB in 10 s); now at most the limit plus one byte is read
    _refused(*_cli("nnm", "/dev/zero", *NNM), "larger than", "bytes", "--max-dof", "--max-springs")


def test_too_many_degrees_of_freedom_is_refused_naming_the_option(tmp_path):
    path = _write(tmp_path, "chain.json", _chain(101))
    _refused(*_cli("nnm", path, *NNM), "101", "--max-dof")
    _refused(*_cli("forced", _write(tmp_path, "forced.json", _forced(101)), *FORCED), "101", "--max-dof")


def test_raising_the_limit_reads_the_larger_system(tmp_path, capsys):
    path = _write(tmp_path, "chain.json", _chain(101))
    assert main(["nnm", path, *NNM, "--max-dof", "101"]) == 0
    lambdas = [float(x) for x in capsys.readouterr().out.splitlines()[1].split("=")[1].split(",")]
    # the linear frequencies of the chain in closed form: 2 sin(k π / (2 (n + 1)))
    import math

    assert lambdas[0] == pytest.approx(2 * math.sin(math.pi / (2 * 102)), rel=1e-9)
    assert len(lambdas) == 101


def test_too_many_springs_is_refused_naming_the_option(tmp_path):
    # the audit: 500 springs on a 2-dof system
    _refused(*_cli("nnm", _write(tmp_path, "springs.json", _chain(2, springs=500)), *NNM), "500", "--max-springs")
    assert main(["nnm", _write(tmp_path, "s3.json", _chain(2, springs=3)), *NNM, "--max-springs", "2"]) == 2


def test_a_system_at_the_default_limits_is_read(tmp_path, capsys):
    assert main(["nnm", _write(tmp_path, "chain.json", _chain(100)), *NNM]) == 0
    assert "NNM of mode 1" in capsys.readouterr().out


@pytest.mark.parametrize("text", ["[" * 100_000 + "]" * 100_000, json.dumps([[[[[[[[[[1]]]]]]]]]])])
def test_deep_nesting_is_refused_naming_the_depth(tmp_path, text):
    _refused(*_cli("nnm", _write(tmp_path, "deep.json", text), *NNM), "deeper than 8")


def test_a_long_row_is_refused_before_the_matrices_are_built(tmp_path, capsys):
    data = {"M": [[1] * 5000], "K": [[1]], "A": [], "b": []}
    assert main(["nnm", _write(tmp_path, "row.json", data), *NNM]) == 2
    error = capsys.readouterr().err
    assert error.startswith("error: ") and "5000 entries" in error and "--max-dof" in error


@pytest.mark.parametrize("option", ["--max-dof", "--max-springs"])
def test_limits_must_be_positive(tmp_path, capsys, option):
    assert main(["nnm", _write(tmp_path, "c.json", _chain(2)), *NNM, option, "0"]) == 2
    assert f"{option} must be a positive integer" in capsys.readouterr().err


def test_size_limit_grows_with_the_options(tmp_path, capsys):
    # 2 dof, 1 spring, but padded with whitespace beyond the default limit of 64 × 101 × 201 bytes
    padded = json.dumps(_chain(2)) + " " * (64 * 101 * 201)
    path = _write(tmp_path, "padded.json", padded)
    assert main(["nnm", path, *NNM]) == 2
    assert "larger than 1299264 bytes" in capsys.readouterr().err
    assert main(["nnm", path, *NNM, "--max-dof", "200"]) == 0


@pytest.mark.parametrize("content, words", [
    ('{"M": [[NaN]], "K": [[1]], "A": [[1]], "b": [0]}', ["NaN", "finite"]),
    (b"\xff\xfe{}", ["UTF-8"]),
    ('{"M": [[1]]', ["not valid JSON"]),
])
def test_bad_files_are_one_error_line(tmp_path, content, words):
    path = tmp_path / "bad.json"
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    _refused(*_cli("nnm", str(path), *NNM), *words)


def test_a_directory_or_a_missing_file_is_refused(tmp_path):
    _refused(*_cli("nnm", str(tmp_path), *NNM), "cannot read the system file")
    _refused(*_cli("forced", str(tmp_path / "missing.json"), *FORCED), "cannot read the forced system file")
