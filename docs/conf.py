"""Sphinx configuration.

* The API reference comes from the numpy-style docstrings (autodoc + napoleon).
* Figures on the pages are drawn by :mod:`lindstedt.plot` at build time (matplotlib's ``.. plot::`` directive).
* The gallery is the notebooks of ``../notebooks``, executed at every build (myst-nb): they are stored without
  outputs, so what the site shows is what the code computes now, and a notebook whose checks fail breaks the
  build.  Sphinx only reads documents inside ``docs/``, so the notebooks are copied to ``docs/notebooks/``
  (generated, git-ignored by ``docs/.gitignore``) when a build starts (``config-inited``); the copies are never
  edited, and reading this file has no side effect.
"""

import os
import pathlib
import re
import shutil

DOCS = pathlib.Path(__file__).resolve().parent
NOTEBOOKS = DOCS.parent / "notebooks"
GALLERY = DOCS / "notebooks"  # generated copies of ../notebooks/*.ipynb


def _prepare_gallery(app, config) -> None:
    """Copy ../notebooks/*.ipynb to docs/notebooks/ (only what changed; stale copies go) before Sphinx reads."""
    GALLERY.mkdir(exist_ok=True)
    sources = {path.name: path for path in NOTEBOOKS.glob("*.ipynb")}
    for stale in GALLERY.glob("*.ipynb"):
        if stale.name not in sources:
            stale.unlink()
    for name, source in sources.items():
        target = GALLERY / name
        if not target.exists() or target.read_bytes() != source.read_bytes():
            shutil.copyfile(source, target)
    # the notebook kernels (children of this process) draw with Jupyter's inline backend, so that figures become
    # image/png outputs whatever the environment says (MPLBACKEND=Agg would leave the gallery without figures);
    # the plot directive selects Agg for itself
    os.environ["MPLBACKEND"] = "module://matplotlib_inline.backend_inline"


# sphinx.ext.viewcode links each object of a source page back to its entry as "#<module>.<name>", with ONE module
# per source file (the first one it was documented under); the facade re-exports names of modules whose other names
# are documented under their subpackage (lindstedt.ExactFlow next to lindstedt.numerics.FlowResult, both from
# numerics/flow.py), so those [docs] links missed.  The targets are recorded as the pages are read and the links set
# to them when the source pages are written (a source object documented nowhere loses its link).
def _record_viewcode_targets(app, doctree) -> None:
    from sphinx import addnodes
    from sphinx.ext.viewcode import viewcode_anchor

    targets = app.env.__dict__.setdefault("lindstedt_viewcode_targets", {})
    for signature in doctree.findall(addnodes.desc_signature):
        for anchor in signature.findall(viewcode_anchor):
            if signature["ids"]:
                targets[anchor["reftarget"], anchor["refid"]] = (app.env.docname, signature["ids"][0])


def _purge_viewcode_targets(app, env, docname) -> None:
    targets = env.__dict__.get("lindstedt_viewcode_targets", {})
    for key in [key for key, (target_doc, _) in targets.items() if target_doc == docname]:
        del targets[key]


_BACKLINK = re.compile(r'(<div class="viewcode-block" id="([^"]+)">\n)<a class="viewcode-back" href="[^"]*">([^<]*)</a>\n')


def _fix_viewcode_backlinks(app, pagename, templatename, context, doctree) -> None:
    if not pagename.startswith("_modules/") or "body" not in context:
        return
    targets = app.env.__dict__.get("lindstedt_viewcode_targets", {})

    def link(match) -> str:
        target = targets.get((pagename, match.group(2)))
        if target is None:
            return match.group(1)
        href = app.builder.get_relative_uri(pagename, target[0]) + "#" + target[1]
        return f'{match.group(1)}<a class="viewcode-back" href="{href}">{match.group(3)}</a>\n'

    context["body"] = _BACKLINK.sub(link, context["body"])


def setup(app):
    app.connect("config-inited", _prepare_gallery)
    app.connect("doctree-read", _record_viewcode_targets, priority=600)  # after viewcode's own (500)
    app.connect("env-purge-doc", _purge_viewcode_targets)
    app.connect("html-page-context", _fix_viewcode_backlinks)


project = "lindstedt"
author = "The lindstedt maintainers"
copyright = "2026, The lindstedt maintainers (MIT licence)"
extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    # MathJax 3 served from the built site (_static/mathjax/), not from a CDN: formulas render offline
    "sphinx-mathjax-offline",
    "sphinx.ext.viewcode",
    "matplotlib.sphinxext.plot_directive",
    "myst_nb",
]
autodoc_member_order = "bysource"
autodoc_typehints = "none"
napoleon_numpy_docstring = True
napoleon_google_docstring = False
exclude_patterns = ["_build", "jupyter_execute", "**.ipynb_checkpoints"]
html_theme = "alabaster"

# figures drawn by lindstedt.plot at build time (.. plot::)
plot_include_source = True
plot_html_show_source_link = False
plot_html_show_formats = False
plot_formats = [("png", 90)]
plot_rcparams = {"figure.figsize": (7.0, 4.0)}

# the gallery: notebooks executed at every build, a failing cell (or assertion) fails the build
nb_execution_mode = "force"
nb_execution_timeout = 600  # seconds per cell: a hang guard, far above normal (tests/test_notebooks.py: CELL_TIMEOUT)
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_merge_streams = True
myst_enable_extensions = ["dollarmath", "amsmath"]
