"""The notebooks in ``notebooks/`` run end to end and are stored without outputs.

Each notebook reproduces a figure of the seed with lindstedt and ends with a
cell of assertions against independent references, so executing it is a test.
They run in a fresh ``python3`` kernel (nbclient) with matplotlib's inline
backend (headless, as in Jupyter), from the ``notebooks/`` directory.  Their
speed is not a test (a busy machine must not turn the suite red): nbclient's
per-cell timeout only catches a hang.  The executed notebooks must show what a
reader sees in Jupyter: the figures drawn by ``lindstedt.plot`` (``image/png``
outputs) and the results' rich displays (``_repr_latex_`` / ``_repr_html_``).

Needs the ``notebooks`` extra (``pip install -e ".[dev,notebooks]"``).  Without
it the execution tests are skipped locally, but fail under CI (``CI`` set), so
that CI cannot pass without running the notebooks.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"

#: every notebook of the gallery
NAMES = (
    "backbone.ipynb",
    "fig2_spectrum_u_plus.ipynb",
    "fig3_lp_nnm_5dof.ipynb",
    "fig4_8_numerical_nnm.ipynb",
    "forced_response.ipynb",
    "hertz_backbone.ipynb",
    "nnm_any_law.ipynb",
    "peer_nlvib02.ipynb",
    "peer_nlvib03.ipynb",
    "peer_sdnd123.ipynb",
    "runtime_vs_error.ipynb",
    "validity_time.ipynb",
)
#: nbclient's limit for one cell: a hang guard, far above normal (a whole notebook takes 3–12 s on an idle 2-core
#: machine, about 100 s on a loaded one; no cell takes more than a few seconds when idle)
CELL_TIMEOUT = 600
#: the matplotlib backend of the kernel: Jupyter's inline backend, so that figures become image/png outputs
INLINE_BACKEND = "module://matplotlib_inline.backend_inline"

#: the ``lindstedt.plot`` functions each notebook draws its figures with (runtime_vs_error plots benchmark files,
#: for which the plotting API has no figure)
PLOT_FUNCTIONS = {
    "backbone.ipynb": {"backbone", "branch"},
    "fig2_spectrum_u_plus.ipynb": {"spectrum", "waveform"},
    "fig3_lp_nnm_5dof.ipynb": {"waveform"},
    "fig4_8_numerical_nnm.ipynb": {"nnm_orbit", "branch"},
    "hertz_backbone.ipynb": {"backbone", "convergence", "waveform"},
    "validity_time.ipynb": {"convergence"},
    "runtime_vs_error.ipynb": set(),
    "forced_response.ipynb": {"frequency_response", "spectrum"},
    "peer_sdnd123.ipynb": {"branch"},
    "peer_nlvib02.ipynb": {"frequency_response"},
    "peer_nlvib03.ipynb": {"frequency_response"},
    "nnm_any_law.ipynb": {"branch"},
}
#: the figures (image/png outputs) each executed notebook shows, at least
FIGURES = {
    "backbone.ipynb": 2,
    "fig2_spectrum_u_plus.ipynb": 1,
    "fig3_lp_nnm_5dof.ipynb": 2,
    "fig4_8_numerical_nnm.ipynb": 3,
    "hertz_backbone.ipynb": 2,
    "validity_time.ipynb": 2,
    "runtime_vs_error.ipynb": 3,
    "forced_response.ipynb": 3,
    "peer_sdnd123.ipynb": 1,
    "peer_nlvib02.ipynb": 3,
    "peer_nlvib03.ipynb": 3,
    "nnm_any_law.ipynb": 3,
}
#: rich displays of results (the last expression of a cell): (mime type, fragments that one such output contains)
DISPLAYS = {
    "backbone.ipynb": [
        # Expansion._repr_latex_: the equation and the exact ω_1 of the gap b = 1/2
        ("text/latex", [r"\ddot u + u + \varepsilon \max\left(0, u - \frac{1}{2}\right) = 0",
                        r"\omega_{1} &= \frac{- 3 \sqrt{3} + 4 \pi}{24 \pi}"]),
        ("text/latex", [r"\lambda_{1} &=", r"a_{2} &="]),                              # NNMExpansion
        ("text/html", ['<table class="lindstedt">', "<b>NNMBranch: "]),
        ("text/html", ['<table class="lindstedt">', "<b>NNMResult: mode 1, converged"]),
    ],
    "fig2_spectrum_u_plus.ipynb": [
        ("text/latex", [r"\ddot u + u + \varepsilon \max\left(0, u\right) = 0", r"\omega_{1} &= \frac{1}{4}"]),
    ],
    "fig3_lp_nnm_5dof.ipynb": [("text/latex", [r"\lambda_{1} &=", r"\omega(\varepsilon) &="])],
    "forced_response.ipynb": [
        ("text/html", ['<table class="lindstedt">', "<b>FrequencyResponse: "]),
        # FrequencyResponseCurve._repr_latex_: the equation and the closed-form first harmonic of (A cos θ − 1/5)_+
        ("text/latex", [r"\varepsilon F \cos \Omega t", r"\operatorname{acos}{\left(\frac{1}{5 A} \right)}"]),
    ],
    "peer_sdnd123.ipynb": [("text/html", ['<table class="lindstedt">', "<b>NNMBranch: "])],
    "peer_nlvib02.ipynb": [("text/html", ['<table class="lindstedt">', "<b>FrequencyResponse: "])],
    "peer_nlvib03.ipynb": [("text/html", ['<table class="lindstedt">', "<b>FrequencyResponse: "])],
    "hertz_backbone.ipynb": [
        ("text/latex", ["Stretched contact arc", r"|u - b|^{3/2}"]),
        ("text/html", ['<table class="lindstedt">', "<b>StretchedArcSeries"]),
    ],
    # NNMExpansion._repr_latex_ of the 3-mass chain's mode 1 to order 3, and the continued NNMBranch
    "nnm_any_law.ipynb": [
        ("text/latex", [r"\lambda_{1} &=", r"\omega_{3} &=", r"a_{3} &="]),
        ("text/html", ['<table class="lindstedt">', "<b>NNMBranch: "]),
    ],
}


def _load(name: str) -> dict:
    return json.loads((NOTEBOOKS / name).read_text(encoding="utf-8"))


def _code_cells(notebook: dict) -> list[dict]:
    return [cell for cell in notebook["cells"] if cell["cell_type"] == "code"]


def test_the_notebook_list_is_complete():
    assert sorted(path.name for path in NOTEBOOKS.glob("*.ipynb")) == list(NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_saved_without_outputs(name):
    notebook = _load(name)
    for index, cell in enumerate(_code_cells(notebook)):
        assert cell.get("outputs") == [], f"{name}: code cell {index} has outputs saved; strip them"
        assert cell.get("execution_count") is None, f"{name}: code cell {index} has an execution count; strip it"
        assert "execution" not in cell.get("metadata", {}), f"{name}: code cell {index} has execution metadata"
    assert notebook["metadata"]["kernelspec"]["name"] == "python3"


@pytest.mark.parametrize("name", NAMES)
def test_figures_come_from_the_plotting_api(name):
    sources = "".join("".join(cell["source"]) for cell in _code_cells(_load(name)))
    for function in sorted(PLOT_FUNCTIONS[name]):
        assert f"lindstedt.plot.{function}(" in sources, f"{name}: draw with lindstedt.plot.{function}"
    assert set(PLOT_FUNCTIONS) == set(NAMES) == set(FIGURES)


@pytest.mark.parametrize("name", NAMES)
def test_header_and_final_assertions(name):
    notebook = _load(name)
    first = notebook["cells"][0]
    assert first["cell_type"] == "markdown" and "".join(first["source"]).startswith("# "), name
    assert "Reproduces" in "".join(first["source"]), f"{name}: the header must say what it reproduces"
    last = _code_cells(notebook)[-1]
    assert "assert " in "".join(last["source"]), f"{name}: the last code cell must check the numbers"


def _client_modules():
    try:
        import nbclient
        import nbformat
    except ImportError as error:
        if os.environ.get("CI"):
            pytest.fail(f"the notebooks extra is not installed ({error}): CI must `pip install -e \".[dev]\"` (dev includes the notebooks extra)")
        pytest.skip(f"the notebooks extra is not installed ({error}); pip install -e \".[notebooks]\"")
    return nbclient, nbformat


#: notebooks taking 5–20 s each: executed by `pytest -m slow` (CI runs it) and by every build of the docs site
HEAVY = ("backbone.ipynb", "hertz_backbone.ipynb", "peer_sdnd123.ipynb", "peer_nlvib02.ipynb",
         "peer_nlvib03.ipynb", "nnm_any_law.ipynb",
         # 4–5 s each: the default run stays near five minutes (the slow run executes them)
         "fig4_8_numerical_nnm.ipynb", "forced_response.ipynb", "validity_time.ipynb", "runtime_vs_error.ipynb")


@pytest.mark.parametrize("name", [pytest.param(name, marks=pytest.mark.slow) if name in HEAVY else name for name in NAMES])
def test_notebook_executes(name, monkeypatch):
    nbclient, nbformat = _client_modules()
    monkeypatch.setenv("MPLBACKEND", INLINE_BACKEND)
    notebook = nbformat.read(NOTEBOOKS / name, as_version=4)
    client = nbclient.NotebookClient(
        notebook,
        timeout=CELL_TIMEOUT,
        kernel_name="python3",
        resources={"metadata": {"path": str(NOTEBOOKS)}},
    )
    try:
        client.execute()
    except nbclient.exceptions.CellExecutionError as error:
        pytest.fail(f"{name} failed:\n{error}")
    outputs = [output for cell in notebook.cells if cell.cell_type == "code" for output in cell.outputs]
    # an exception raised while a figure is drawn (after the cell's code ran) does not stop nbclient
    errors = [f"{output.get('ename')}: {output.get('evalue')}" for output in outputs if output.get("output_type") == "error"]
    assert not errors, f"{name}: error outputs {errors}"
    printed = "".join(output.get("text", "") for output in outputs)
    assert "all checks passed" in printed, f"{name}: the final checks did not report success"
    rich = [output.get("data", {}) for output in outputs]
    figures = sum("image/png" in data for data in rich)
    assert figures >= FIGURES[name], f"{name}: {figures} figures (image/png outputs), expected {FIGURES[name]}"
    for mime, fragments in DISPLAYS.get(name, []):
        shown = [data[mime] for data in rich if mime in data]
        assert any(all(fragment in text for fragment in fragments) for text in shown), (
            f"{name}: no {mime} output shows {fragments}; got {[text[:200] for text in shown]}")
    if name == "backbone.ipynb":
        # the LaTeX Jupyter shows is the expansion's own, display math around its to_latex() equations
        import lindstedt

        expected = lindstedt.expand("Max(0, u - 1/2)", order=2, a0=1, omega0=1)._repr_latex_()
        assert expected.startswith("$$") and r"\omega" in expected
        assert expected in [data["text/latex"] for data in rich if "text/latex" in data]
