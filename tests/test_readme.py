"""The README's code is true: its doctest blocks pass and its plain Python blocks run."""

import doctest
import pathlib
import re

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
