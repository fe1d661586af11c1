"""The documentation is true: every example on its pages runs and prints what it says, its figures are drawn by
:mod:`lindstedt.plot` (matplotlib's ``.. plot::`` directive), its gallery is the notebooks, executed, and the
site builds with warnings as errors (Sphinx autodoc of the docstrings, napoleon for the numpy style, myst-nb
for the notebooks)."""

import doctest
import pathlib
import re
import runpy
import shutil
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.glob("*.rst"))
NOTEBOOKS = sorted(path.stem for path in (ROOT / "notebooks").glob("*.ipynb"))
#: the lindstedt.plot functions the figures page draws with
PLOT_FUNCTIONS = ("backbone", "waveform", "error_over_time", "spectrum", "convergence", "branch", "nnm_orbit")


def test_the_pages_exist():
    assert {"index.rst", "install.rst", "tutorial.rst", "figures.rst", "theory.rst", "gallery.rst", "api.rst"} <= {
        p.name for p in PAGES}


@pytest.mark.parametrize("page", [p for p in PAGES if ">>>" in p.read_text(encoding="utf-8")], ids=lambda p: p.name)
def test_page_examples_pass(page):
    pytest.importorskip("matplotlib", reason="the tutorial draws a figure: pip install 'lindstedt[plot]'")
    parser = doctest.DocTestParser()
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    test = parser.get_doctest(page.read_text(encoding="utf-8"), {}, page.name, str(page), 0)
    assert test.examples
    runner.run(test)
    assert runner.failures == 0


def plot_blocks(page: pathlib.Path) -> list[str]:
    """The code of every ``.. plot::`` directive of a page (its indented body, options excluded)."""
    blocks = []
    lines = page.read_text(encoding="utf-8").splitlines()
    for index, line in enumerate(lines):
        if line.strip() != ".. plot::":
            continue
        body = []
        for following in lines[index + 1:]:
            if following.strip() and not following.startswith("   "):
                break
            if not following.strip().startswith(":"):
                body.append(following[3:])
        blocks.append("\n".join(body).strip("\n"))
    return blocks


FIGURE_BLOCKS = [(page.name, number, code) for page in PAGES for number, code in enumerate(plot_blocks(page), 1)]


def test_the_figures_page_draws_with_the_plotting_api():
    code = "\n".join(plot_blocks(DOCS / "figures.rst"))
    for function in PLOT_FUNCTIONS:
        assert f"lindstedt.plot.{function}(" in code, f"figures.rst: no .. plot:: draws lindstedt.plot.{function}"
    assert any("lindstedt.plot." in block for block in plot_blocks(DOCS / "tutorial.rst"))


@pytest.mark.parametrize("page, number, code", FIGURE_BLOCKS, ids=[f"{p}-{n}" for p, n, _ in FIGURE_BLOCKS])
def test_figure_code_draws(page, number, code):
    """What the plot directive runs at build time: it draws (with lindstedt.plot); its speed is not a test."""
    matplotlib = pytest.importorskip("matplotlib", reason="the figures need matplotlib: pip install 'lindstedt[plot]'")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plt.close("all")
    exec(compile(code, f"{page}, figure {number}", "exec"), {"__name__": "figure"})  # noqa: S102 - our own pages
    try:
        figures = [plt.figure(n) for n in plt.get_fignums()]
        assert figures and any(ax.has_data() for figure in figures for ax in figure.axes), f"{page} figure {number} draws nothing"
    finally:
        plt.close("all")


def test_the_gallery_is_every_notebook_executed():
    toctree = re.findall(r"^   notebooks/(\S+)$", (DOCS / "gallery.rst").read_text(encoding="utf-8"), flags=re.M)
    assert sorted(toctree) == NOTEBOOKS
    conf = runpy.run_path(str(DOCS / "conf.py"))         # reading the configuration writes nothing
    assert {"myst_nb", "matplotlib.sphinxext.plot_directive"} <= set(conf["extensions"])
    # the notebooks are stored without outputs: the build executes them, and a failing cell fails it
    assert conf["nb_execution_mode"] == "force" and conf["nb_execution_raise_on_error"] is True
    assert conf["nb_execution_timeout"] >= 300  # a hang guard, never a speed budget


def test_generated_gallery_copies_are_ignored_by_git():
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    probe = subprocess.run(["git", "check-ignore", "-q", "docs/notebooks/backbone.ipynb"], cwd=ROOT, check=False)
    assert probe.returncode == 0, "docs/notebooks/ (the build's copies of notebooks/) must be git-ignored"


@pytest.mark.slow
def test_site_builds_with_warnings_as_errors(tmp_path):
    pytest.importorskip("sphinx", reason="the docs extra: pip install 'lindstedt[docs]'")
    pytest.importorskip("myst_nb", reason="the docs extra: pip install 'lindstedt[docs]'")
    result = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", str(DOCS), str(tmp_path)],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stderr[-3000:]
    assert (tmp_path / "api.html").read_text(encoding="utf-8").count("lindstedt.expand") >= 1
    # the figures: drawn by the plot directive, one image per block
    for page in ("figures", "tutorial"):
        html = (tmp_path / f"{page}.html").read_text(encoding="utf-8")
        images = re.findall(r'<img alt="[^"]*" class="plot-directive" src="([^"]+)"', html)
        assert len(images) == len(plot_blocks(DOCS / f"{page}.rst")) >= 1, page
        assert all((tmp_path / image).stat().st_size > 1000 for image in images), page
    # the gallery: every notebook executed (its checks passed) with its figures
    for name in NOTEBOOKS:
        html = (tmp_path / "notebooks" / f"{name}.html").read_text(encoding="utf-8")
        assert re.search(r'<div class="output stream[^"]*">\s*<div class="highlight[^"]*"><pre>(?:(?!</pre>).)*all checks passed', html, re.S), name
        assert re.search(r'<img alt="[^"]*" src="\.\./_images/[0-9a-f]+\.png"', html), f"{name}: no figure"
    # an Expansion as Jupyter shows it: its LaTeX, rendered as display math
    backbone = (tmp_path / "notebooks" / "backbone.html").read_text(encoding="utf-8")
    latex = re.findall(r'<div class="output text_latex math[^"]*">(.*?)</div>', backbone, re.S)
    assert any(r"\omega_{1} &amp;= \frac{- 3 \sqrt{3} + 4 \pi}{24 \pi}" in block for block in latex), latex
