"""The README's code is true: its doctest blocks pass, its plain Python blocks run and its commands run literally."""

import doctest
import pathlib
import re
import shlex
import shutil
import subprocess

import pytest

README = pathlib.Path(__file__).resolve().parent.parent / "README.md"
BLOCKS = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)


def test_readme_has_python_examples():
    assert len(BLOCKS) >= 2


def test_readme_doctests_pass():
    parser = doctest.DocTestParser()
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for index, block in enumerate(block for block in BLOCKS if ">>>" in block):
        test = parser.get_doctest(block, {}, f"README block {index}", str(README), 0)
        runner.run(test)
    assert runner.failures == 0


def test_readme_scripts_run():
    for block in (block for block in BLOCKS if ">>>" not in block):
        exec(compile(block, str(README), "exec"), {"__name__": "readme"})  # noqa: S102 - our own README


def readme_commands() -> list[str]:
    """Every `lindstedt …` line of the README's bash blocks (comments stripped)."""
    text = README.read_text(encoding="utf-8")
    lines = []
    for block in re.findall(r"```bash\n(.*?)```", text, flags=re.S):
        for line in block.splitlines():
            command = line.split("  #")[0].strip()
            if command.startswith("lindstedt "):
                lines.append(command)
    return lines


def test_readme_has_commands():
    assert any(command.startswith("lindstedt nnm examples/") for command in readme_commands())


@pytest.mark.parametrize("command", readme_commands())
def test_readme_command_runs_literally(command, tmp_path):
    # run from a copy of the repository's examples in a scratch directory, so written files land there
    shutil.copytree(README.parent / "examples", tmp_path / "examples")
    result = subprocess.run(shlex.split(command), cwd=tmp_path, capture_output=True, text=True, timeout=300, check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip()


def readme_console_blocks() -> list[tuple[str, str]]:
    """The README's ```console blocks: `$ lindstedt …` and the output it prints."""
    text = README.read_text(encoding="utf-8")
    blocks = []
    for block in re.findall(r"```console\n(.*?)```", text, flags=re.S):
        first, _, output = block.partition("\n")
        assert first.startswith("$ lindstedt "), first
        blocks.append((first[2:], output))
    return blocks


def test_readme_shows_pretty_output_and_eps():
    blocks = readme_console_blocks()
    assert any("--eps" in command and "ω" in output and "ε" in output for command, output in blocks)


@pytest.mark.parametrize("command, shown", readme_console_blocks())
def test_readme_console_output_is_what_the_command_prints(command, shown):
    result = subprocess.run(shlex.split(command), cwd=README.parent, capture_output=True, text=True, timeout=300, check=False)
    assert result.returncode == 0, result.stderr

    def lines(text):
        return [line.rstrip() for line in text.strip("\n").splitlines()]

    assert lines(result.stdout) == lines(shown)


def test_readme_states_the_measured_test_time_and_a_venv():
    text = README.read_text(encoding="utf-8")
    assert "python3 -m venv .venv" in text
    assert re.search(r"`pytest` took \d+(\.\d+)? min", text)
