"""Jupyter display of results: ``_repr_latex_`` (from each ``to_latex``), ``_repr_html_`` tables and short reprs."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import lindstedt
from lindstedt.render.display import jupyter_latex
from lindstedt.numerics.results import NNMBranch


def _balanced(latex: str) -> bool:
    depth = 0
    for character in latex.replace(r"\{", "").replace(r"\}", ""):
        depth += {"{": 1, "}": -1}.get(character, 0)
        if depth < 0:
            return False
    return depth == 0 and latex.count(r"\left") == latex.count(r"\right")


def test_duffing_latex_is_in_increasing_powers_with_its_assumptions():
    # ω = ω0 + 3 a0² ε / (8 ω0) − 21 a0⁴ ε² / (256 ω0³), derived by hand
    latex = lindstedt.expand("u**3", order=2).to_latex()
    assert (
        r"\omega(\varepsilon) &= \omega_{0} + \frac{3 a_{0}^{2} \varepsilon}{8 \omega_{0}}"
        r" - \frac{21 a_{0}^{4} \varepsilon^{2}}{256 \omega_{0}^{3}} + O(\varepsilon^{3})"
    ) in latex
    assert r"& \ddot u + \omega_{0}^{2} u + \varepsilon u^{3} = 0,\quad u(0) = a_{0},\ \dot u(0) = 0 \\" in latex
    assert r"& \text{assuming } a_{0} > 0,\ \omega_{0} > 0 \\" in latex


def test_unit_and_numeric_stiffness_drop_the_coefficient_one():
    unit = lindstedt.expand("u**3 - u**2", order=1, a0=1, omega0=1).to_latex()
    assert r"\ddot u + u + \varepsilon \left(u^{3} - u^{2}\right) = 0" in unit and "1 u" not in unit
    assert r"\omega(\varepsilon) &= 1 + \frac{3 \varepsilon}{8} + O(\varepsilon^{2})" in unit
    assert r"\ddot u + 4 u + \varepsilon u^{3} = 0" in lindstedt.expand("u**3", order=1, a0=1, omega0=2).to_latex()


def test_symbolic_gap_states_its_contact_assumption_and_names_long_coefficients():
    expansion = lindstedt.expand("Max(0, u - b)", order=2, params={"b": None})
    latex = expansion.to_latex()
    assert r"- a_{0} < b < a_{0}\ \text{(contact: the orbit crosses the breakpoint u = b)}" in latex
    assert r"\text{regime: contact, valid for } t = O(\varepsilon^{-1})" in latex
    assert r"\omega(\varepsilon) &= \omega_{0} + \omega_{1} \varepsilon + \omega_{2} \varepsilon^{2} + O(\varepsilon^{3})" in latex
    shown = expansion._repr_latex_()
    assert shown.startswith("$$\\begin{aligned}") and shown.endswith("\\end{aligned}$$")
    assert "%" not in shown and "align*" not in shown and _balanced(shown)
    text = repr(expansion)
    assert len(text) < 1500 and "full: .omega[2]" in text and "regime='contact'" in text
    assert text.startswith("Expansion(\n  problem=\"u'' + omega0**2*u + eps*(Max(0, -b + u))")


def test_expansion_repr_is_labelled_and_short():
    text = repr(lindstedt.expand("u**3", order=2, a0=1, omega0=1))
    assert text == "Expansion(problem=\"u'' + u + eps*(u**3) = 0, u(0) = 1 [initial]\", order=2, omega=(1, 3/8, -21/256))"


def test_nnm_expansion_shows_numbers_not_mpf_tuples():
    result = lindstedt.nnm(lindstedt.UnilateralSystem.one_dof(1, a=1, b=0), mode=1, a0=1, order=2)
    text = repr(result)
    assert "mpf(" not in text and "omega=[1.0, 0.25, -0.125]" in text and "validity_exponent=-1" in text
    latex = result.to_latex()
    assert r"\omega(\varepsilon) &= 1.0 + 0.25\,\varepsilon - 0.125\,\varepsilon^{2} + O(\varepsilon^{3})" in latex
    assert r"\text{springs: simple, valid for } t = O(\varepsilon^{-1})" in latex
    assert result._repr_latex_() == jupyter_latex(latex) and _balanced(latex)


def test_chain_nnm_repr_has_ten_digits():
    chain = lindstedt.UnilateralSystem.chain(5, unilateral=[(0, 0.0), (3, -0.2)])
    text = repr(lindstedt.nnm(chain, mode=1, a0=1.0, order=2))
    assert "omega=[0.5176380902, 0.2207987821, -0.2472766648]" in text and len(text) < 600


@pytest.fixture(scope="module")
def point():
    return lindstedt.nnm_point(lindstedt.UnilateralSystem.one_dof(1), 3.0, 1, modal_amplitude=1.0)


def test_nnm_result_repr_and_html_table(point):
    text = repr(point)
    assert "success=True" in text and "frequency=1.333333333" in text and "flow_evaluations=" in text
    assert len(text) < 1000 and "problem" not in text
    table = point._repr_html_()
    assert "<b>NNMResult: mode 1, converged</b>" in table
    assert '<th style="text-align:left">success</th><td style="text-align:left">True</td>' in table
    assert f'<td style="text-align:left">{point.message}</td>' in table
    failed = dataclasses.replace(point, success=False, message="no convergence <after 50 iterations>", frequency=float("nan"))
    table = failed._repr_html_()
    assert "FAILED" in table and "no convergence &lt;after 50 iterations&gt;" in table and ">nan<" in table


def test_branch_html_is_a_summary_not_every_point(point):
    points = tuple(dataclasses.replace(point, epsilon=0.001 * k) for k in range(1000))
    branch = NNMBranch(True, "reached stop = 1", "natural", "epsilon", points, np.arange(1000) * 0.001,
                       (), (), (500,), 4000, 3000, 2, 12.5)
    text = repr(branch)
    assert len(text) < 1000 and "points=1000" in text and "contact_changes=[500]" in text
    assert "parameter_range=[0, 0.999]" in text
    table = branch._repr_html_()
    assert table.count("<tr><td>") == 12  # the points grid: 12 rows (ends, the event, evenly spaced)
    assert "<tr><td>500</td>" in table and "<tr><td>999</td>" in table
    assert "12 of 1000 points shown" in table and "contact change →" in table and "reached stop = 1" in table


def test_flow_result_repr_and_html():
    run = lindstedt.ExactFlow(lindstedt.UnilateralSystem.one_dof(1), 0.5).solve([1.0], [0.0], 100.0)
    text = repr(run)
    assert "success=True" in text and f"n_switches={run.n_switches}" in text and "all in .events" in text
    assert len(text) < 1200
    table = run._repr_html_()
    assert "<b>FlowResult: success</b>" in table and run.message in table and "n_root_solves" in table


def test_stretched_arc_latex_and_repr():
    arc = lindstedt.expand("Max(0, u)**(3/2)", order=1, a0=1, omega0=1, precision=20).stretched_arcs[0]
    latex = arc.to_latex()
    assert r"(release side, contact law $\propto |u - b|^{3/2}$)" in latex
    assert r"$\ell(\varepsilon) = 1.57079632679 - 0.359442070421\,\hat\varepsilon + \dots$" in latex and "+ -" not in latex
    assert arc._repr_latex_() == latex
    text = repr(arc)
    assert "length=[1.570796327, -0.3594420704]" in text and "<2 orders x 64 coefficients" in text and len(text) < 500


@pytest.fixture(scope="module")
def validation_results():
    import lindstedt.validate as validate

    expansion = lindstedt.expand("Max(0, u)", order=2, a0=1, omega0=1)
    problem = lindstedt.Oscillator("u**3", a0=1, omega0=1)
    return [
        validate.exact_period(problem, 0.1),
        validate.expansion_error(expansion, 0.1, 10.0),
        validate.fitted_convergence_order(expansion, [0.01, 0.02, 0.04]),
        validate.reference_solution(expansion, 0.1, [0.0, 1.0, 2.0]),
        validate.expansion_spectrum(expansion, 0.1),
        validate.contact_measure(np.cos(np.linspace(0, 10, 201)), np.linspace(0, 10, 201), 0.1),
    ]


def test_every_validation_result_has_a_short_labelled_repr_and_an_html_table(validation_results):
    for result in validation_results:
        name = type(result).__name__
        text = repr(result)
        assert text.startswith(f"{name}(") and "success=True" in text, name
        assert "array(" not in text and "mpf(" not in text, f"{name}: raw array/mpf in the repr"
        assert len(text) < 2500, f"{name}: repr of {len(text)} characters"
        html = result._repr_html_()
        assert html.startswith('<table class="lindstedt">') and f"{name}: success" in html, name
        assert "<th" in html and "message" in html, name


def test_generated_code_shows_its_source_in_a_notebook_and_cuts_it_in_the_repr():
    expansion = lindstedt.expand("u**3", order=1, a0=1, omega0=1)
    for language, fence in (("numpy", "python"), ("octave", "matlab"), ("rust", "rust")):
        code = lindstedt.generate_code(expansion, "frequency", language)
        markdown = code._repr_markdown_()
        assert f"```{fence}\n{code.source.rstrip()}\n```" in markdown
        assert code.accuracy in markdown
        assert code.source not in repr(code) and f"{len(code.source.splitlines())} lines" in repr(code)
