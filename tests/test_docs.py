"""The documentation is true: every example on its pages runs and prints what it says, its figures are drawn by
:mod:`lindstedt.plot` (matplotlib's ``.. plot::`` directive), its gallery is the notebooks, executed, and the
site builds with warnings as errors (Sphinx autodoc of the docstrings, napoleon for the numpy style, myst-nb
for the notebooks).  The site works offline: it loads no script, style or font from the network (MathJax is served
from the site), a headless Chromium with no network renders its formulas, every local link resolves, and the API
reference has an entry for every public name."""

import doctest
import pathlib
import re
import runpy
import shutil
import subprocess
import sys
import tempfile
from html.parser import HTMLParser
from urllib.parse import unquote, urlsplit

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


# --------------------------------------------------------------------------- the built site
class _Page(HTMLParser):
    """What a built page loads (scripts, styles, images), links to, and the anchors it defines."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.loads: list[str] = []        # <script src>, <link href>, <img src>: fetched by the browser
        self.links: list[str] = []        # <a href>
        self.inline_scripts: list[str] = []
        self.anchors: set[str] = set()
        self._in_script = False

    def handle_starttag(self, tag, attrs):
        attributes = dict(attrs)
        self.anchors.update(attributes[key] for key in ("id", "name") if attributes.get(key))
        if tag in {"script", "img", "iframe", "source"} and attributes.get("src"):
            self.loads.append(attributes["src"])
        elif tag == "link" and attributes.get("href"):
            self.loads.append(attributes["href"])
        elif tag == "a" and attributes.get("href") is not None:
            self.links.append(attributes["href"])
        self._in_script = tag == "script" and not attributes.get("src")
        if self._in_script:
            self.inline_scripts.append("")

    def handle_endtag(self, tag):
        if tag == "script":
            self._in_script = False

    def handle_data(self, data):
        if self._in_script:
            self.inline_scripts[-1] += data


def _pages(site: pathlib.Path) -> dict[pathlib.Path, _Page]:
    pages = {}
    for path in sorted(site.rglob("*.html")):
        page = _Page()
        page.feed(path.read_text(encoding="utf-8"))
        pages[path.resolve()] = page
    return pages


def _network_loads(site: pathlib.Path) -> list[str]:
    """Everything a browser would fetch from the network to show the site: scripts, styles, images, fonts."""
    found = []
    for path, page in _pages(site).items():
        name = path.relative_to(site.resolve()).as_posix()
        found += [f"{name}: {url}" for url in page.loads if urlsplit(url).scheme or url.startswith("//")]
        found += [f"{name}: inline script names {url}" for text in page.inline_scripts
                  for url in re.findall(r"(?:https?:)?//[\w.-]+\.\w+/\S*", text)]
    for style in sorted(site.rglob("*.css")):
        found += [f"{style.relative_to(site).as_posix()}: {url}"
                  for url in re.findall(r"(?:url\(|@import)\s*[\"']?((?:https?:)?//[^\"')\s]+)", style.read_text(encoding="utf-8", errors="replace"))]
    return found


def _broken_local_links(site: pathlib.Path) -> list[str]:
    """Local href/src that name no file of the site, or an anchor its page does not define."""
    pages = _pages(site)
    broken = []
    for path, page in pages.items():
        for reference in page.loads + page.links:
            parts = urlsplit(reference)
            if parts.scheme or parts.netloc or reference.startswith("//"):
                continue
            target = (path.parent / unquote(parts.path)).resolve() if parts.path else path
            name = path.relative_to(site.resolve()).as_posix()
            if not target.exists():
                broken.append(f"{name}: {reference} (no such file)")
            elif parts.fragment and target.suffix == ".html" and unquote(parts.fragment) not in pages[target].anchors:
                broken.append(f"{name}: {reference} (no such anchor)")
    return broken


def _sphinx_build(source: pathlib.Path, output: pathlib.Path) -> subprocess.CompletedProcess:
    # the timeout only catches a hang: the full site takes 1–2 min (notebooks executed), a page a few seconds
    return subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", str(source), str(output)],
                          capture_output=True, text=True, timeout=3600, check=False)


@pytest.fixture(scope="module")
def theory_site(tmp_path_factory):
    """The theory page alone, built with the site's configuration (seconds: no notebook, no API page)."""
    pytest.importorskip("sphinx", reason="the docs extra: pip install 'lindstedt[docs]'")
    pytest.importorskip("myst_nb", reason="the docs extra: pip install 'lindstedt[docs]'")
    source = tmp_path_factory.mktemp("theory-source")
    shutil.copyfile(DOCS / "conf.py", source / "conf.py")
    shutil.copyfile(DOCS / "theory.rst", source / "theory.rst")
    (source / "index.rst").write_text("Theory only\n===========\n\n.. toctree::\n\n   theory\n", encoding="utf-8")
    output = tmp_path_factory.mktemp("theory-site")
    result = _sphinx_build(source, output)
    assert result.returncode == 0, result.stderr[-3000:]
    return output


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The whole site, built as the README says (warnings are errors, the notebooks executed)."""
    pytest.importorskip("sphinx", reason="the docs extra: pip install 'lindstedt[docs]'")
    pytest.importorskip("myst_nb", reason="the docs extra: pip install 'lindstedt[docs]'")
    output = tmp_path_factory.mktemp("site")
    result = _sphinx_build(DOCS, output)
    assert result.returncode == 0, result.stderr[-3000:]
    return output


def test_the_site_serves_mathjax_itself(theory_site):
    assert _network_loads(theory_site) == []
    html = (theory_site / "theory.html").read_text(encoding="utf-8")
    (mathjax,) = [src for src in _pages(theory_site)[(theory_site / "theory.html").resolve()].loads if "mathjax" in src.lower()]
    assert (theory_site / urlsplit(mathjax).path).is_file(), mathjax
    assert (theory_site / "_static" / "mathjax" / "output" / "chtml" / "fonts" / "woff-v2").is_dir()  # its fonts too
    assert html.count('class="math notranslate nohighlight"') >= 10


def test_the_link_checks_see_what_they_must(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "a.html").write_text('<p id="here"></p><a href="sub/b.html#there">x</a><a href="#here">y</a>'
                                     '<a href="https://example.org">z</a><script src="https://cdn.example/x.js"></script>'
                                     '<link rel="stylesheet" href="//cdn.example/x.css"><script>load("https://cdn.example/y.js")</script>')
    (tmp_path / "sub" / "b.html").write_text('<a href="../a.html#nowhere">x</a><img src="missing.png">')
    (tmp_path / "style.css").write_text("@font-face { src: url(https://fonts.example/f.woff) }")
    assert sorted(_broken_local_links(tmp_path)) == ["a.html: sub/b.html#there (no such anchor)",
                                             "sub/b.html: ../a.html#nowhere (no such anchor)",
                                             "sub/b.html: missing.png (no such file)"]
    assert len(_network_loads(tmp_path)) == 4  # the two scripts, the style sheet, the font; not the <a> link


#: Chromium (Debian's package; .ci/run installs it): headless, a profile of its own, and every network request sent
#: to a closed port, so that what it renders is what the site shows offline
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
_CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                   "--disable-component-update", "--disable-sync", "--no-first-run", "--hide-scrollbars",
                   "--proxy-server=http://127.0.0.1:9", "--proxy-bypass-list=<-loopback>",
                   "--virtual-time-budget=30000")  # virtual time: the page's scripts finish however loaded the machine


class _VisibleText(HTMLParser):
    """The text of a rendered page a reader sees (not scripts, styles or MathJax's own output), and MathJax's nodes."""

    HIDDEN = {"script", "style", "mjx-container"}

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.text = []
        self.containers = 0
        self.errors = 0
        self._hidden = 0

    def handle_starttag(self, tag, attrs):
        self.containers += tag == "mjx-container"
        self.errors += tag == "mjx-merror"
        self._hidden += tag in self.HIDDEN

    def handle_endtag(self, tag):
        self._hidden -= tag in self.HIDDEN and self._hidden > 0

    def handle_data(self, data):
        if not self._hidden:
            self.text.append(data)


def _render(page: pathlib.Path, screenshot: pathlib.Path) -> _VisibleText:
    """The DOM of ``page`` after its scripts ran in headless Chromium, read; a PNG screenshot written to ``screenshot``."""
    if CHROMIUM is None:
        pytest.skip("no chromium to render the page with (Debian: apt-get install chromium; .ci/run installs it)")

    def run(*arguments):
        profile = tempfile.mkdtemp(prefix="lindstedt-chromium-")
        try:
            # the timeout only catches a hang: a page renders in about a second
            return subprocess.run([CHROMIUM, *_CHROMIUM_FLAGS, f"--user-data-dir={profile}", *arguments, page.as_uri()],
                                  capture_output=True, text=True, timeout=300, check=True)
        finally:
            shutil.rmtree(profile, ignore_errors=True)

    dom = _VisibleText()
    dom.feed(run("--dump-dom").stdout)
    run("--window-size=1200,1600", f"--screenshot={screenshot}")
    assert screenshot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and screenshot.stat().st_size > 20_000
    return dom


def _assert_math_rendered(site: pathlib.Path, screenshot: pathlib.Path) -> None:
    page = site / "theory.html"
    formulas = page.read_text(encoding="utf-8").count('class="math notranslate nohighlight"')
    dom = _render(page, screenshot)
    visible = "".join(dom.text)
    assert dom.containers == formulas >= 10, f"MathJax rendered {dom.containers} of {formulas} formulas"
    assert dom.errors == 0
    raw = [token for token in (r"\(", r"\)", r"\[", r"\]", r"\frac", r"\varepsilon", "$$") if token in visible]
    assert raw == [], f"raw LaTeX in the rendered page: {raw}"


def test_theory_page_renders_its_math_offline(theory_site, tmp_path):
    _assert_math_rendered(theory_site, tmp_path / "theory.png")


@pytest.mark.slow
def test_site_builds_with_warnings_as_errors(site):
    tmp_path = site
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


@pytest.mark.slow
def test_the_site_loads_nothing_from_the_network(site):
    assert _network_loads(site) == []


@pytest.mark.slow
def test_every_local_link_of_the_site_resolves(site):
    # the source pages' [docs] links back to the API entries included (sphinx.ext.viewcode; docs/conf.py sets them)
    assert list(site.glob("_modules/lindstedt/**/*.html"))
    assert _broken_local_links(site) == []


@pytest.mark.slow
def test_the_api_reference_has_an_entry_for_every_public_name(site):
    import importlib

    import lindstedt

    anchors = _pages(site)[(site / "api.html").resolve()].anchors
    for module_name in ("lindstedt", "lindstedt.limits", "lindstedt.plot", "lindstedt.references", "lindstedt.validate",
                        "lindstedt.numerics", "lindstedt.algebra"):
        module = importlib.import_module(module_name)
        names = getattr(module, "__all__", None) or [name for name in vars(module) if not name.startswith("_")]
        missing = [name for name in names
                   if f"{module_name}.{name}" not in anchors and not (
                       getattr(module, name) is getattr(lindstedt, name, None) and f"lindstedt.{name}" in anchors)]
        assert missing == [], f"{module_name}: no API entry for {missing}"


@pytest.mark.slow
def test_the_built_theory_page_renders_its_math_offline(site, tmp_path):
    _assert_math_rendered(site, tmp_path / "theory.png")
