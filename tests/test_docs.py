"""The documentation is true: every example on its pages runs and prints what it says, and the site builds
with warnings as errors (Sphinx autodoc of the docstrings, napoleon for the numpy style)."""

import doctest
import pathlib
import subprocess
import sys

import pytest

DOCS = pathlib.Path(__file__).resolve().parent.parent / "docs"
PAGES = sorted(DOCS.glob("*.rst"))


def test_the_pages_exist():
    assert {"index.rst", "install.rst", "tutorial.rst", "theory.rst", "gallery.rst", "api.rst"} <= {p.name for p in PAGES}


@pytest.mark.parametrize("page", [p for p in PAGES if ">>>" in p.read_text(encoding="utf-8")], ids=lambda p: p.name)
def test_page_examples_pass(page):
    pytest.importorskip("matplotlib", reason="the tutorial draws a figure: pip install 'lindstedt[plot]'")
    parser = doctest.DocTestParser()
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    test = parser.get_doctest(page.read_text(encoding="utf-8"), {}, page.name, str(page), 0)
    assert test.examples
    runner.run(test)
    assert runner.failures == 0


@pytest.mark.slow
def test_site_builds_with_warnings_as_errors(tmp_path):
    pytest.importorskip("sphinx", reason="the docs extra: pip install 'lindstedt[docs]'")
    result = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", str(DOCS), str(tmp_path)],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stderr[-3000:]
    assert (tmp_path / "api.html").read_text(encoding="utf-8").count("lindstedt.expand") >= 1
