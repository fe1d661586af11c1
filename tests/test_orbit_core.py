"""The one periodic-orbit core (issue 24): one Newton, one continuation driver, one set of test functions.

References (independent of the code under test):

* the bilinear oscillator ``u'' + u + ε u_+ = 0`` has ω = 2 ω_c/(1 + ω_c), ω_c = √(1 + ε) (closed form of the
  piecewise-linear period).  Add a second, decoupled degree of freedom ``x2'' + λ2² x2 = 0`` (λ2 = 11/5): the
  NNM of mode 1 stays on dof 1, and the linearisation of the half-period shooting residual in x2 is
  ``−λ2 sin(λ2 T/2)``, singular where ``λ2 = 2ω``: there the family ``x2 = c cos(λ2 t)`` branches off.  So
  the branch point is at ω = 11/10, ω_c = 11/9, ε* = 121/81 − 1 = 40/81, exactly;
* Newton's quadratic convergence on ``z² − 2`` (the fitted order of the error sequence) and its singular case.
"""

from __future__ import annotations

import ast
import math
import pathlib

import numpy as np
import pytest

import lindstedt
from lindstedt import UnilateralSystem, continue_nnm
from lindstedt.numerics.newton import Evaluation, newton

PACKAGE = pathlib.Path(lindstedt.__file__).resolve().parent
BRANCH_POINT = 40 / 81


def _decoupled_system() -> UnilateralSystem:
    return UnilateralSystem(M=[[1, 0], [0, 1]], K=[[1, 0], [0, "121/25"]], W=[[1], [0]], A=[[1, 0]], b=[0])


@pytest.mark.parametrize("start, stop", [(0.0, 1.0), (1.0, 0.0)])
def test_a_free_nnm_branch_reports_its_branch_point_where_lambda2_is_twice_omega(start, stop):
    branch = continue_nnm(_decoupled_system(), 1, modal_amplitude=1.0, start=start, stop=stop)
    assert branch.success, branch.stop_reason
    # every point on the closed-form backbone of the bilinear oscillator
    exact = [2 * math.sqrt(1 + e) / (1 + math.sqrt(1 + e)) for e in branch.parameter_values]
    np.testing.assert_allclose(branch.frequencies, exact, rtol=1e-12, atol=0)
    assert [b.kind for b in branch.bifurcations] == ["branch-point"]
    located = branch.bifurcations[0]
    # located to the driver's locate tolerance, 1e-9 in scaled arclength (ε is scaled by the range, 1)
    assert abs(located.forcing_scale - BRANCH_POINT) <= 1e-9
    assert abs(located.frequency - 1.1) <= 1e-9
    index = located.index
    assert min(branch.parameter_values[index], branch.parameter_values[index + 1]) <= BRANCH_POINT
    assert max(branch.parameter_values[index], branch.parameter_values[index + 1]) >= BRANCH_POINT


def test_a_branch_with_no_special_point_reports_none():
    """The one-dof bilinear oscillator has no non-trivial multiplier and its backbone no fold: nothing to report."""
    branch = continue_nnm(UnilateralSystem.one_dof(1), 1, modal_amplitude=1.0, start=0.0, stop=2.0)
    assert branch.success and branch.bifurcations == ()


def test_newton_converges_quadratically():
    errors = []

    def evaluate(z):
        errors.append(abs(float(z[0]) - math.sqrt(2.0)))
        return Evaluation(True, "", np.array([z[0] ** 2 - 2.0]), np.array([[2.0 * z[0]]]))

    outcome = newton(evaluate, np.array([3.0]), np.array([1.0]), tol=1e-15, max_iterations=20)
    assert outcome.success and abs(float(outcome.unknowns[0]) - math.sqrt(2.0)) <= 4e-16
    e = [x for x in errors if x > 1e-14]
    orders = [math.log(e[k + 1] / e[k]) / math.log(e[k] / e[k - 1]) for k in range(1, len(e) - 1)]
    assert orders[-1] == pytest.approx(2.0, abs=0.1)


def test_newton_names_a_singular_jacobian_in_the_problems_words():
    outcome = newton(lambda z: Evaluation(True, "", np.array([z[0] ** 2 + 1.0, 0.0]),
                                          np.array([[2.0 * z[0], 0.0], [0.0, 0.0]]), singular="two nodes collide"),
                     np.array([1.0, 0.0]), np.ones(2), tol=1e-12, max_iterations=5)
    assert not outcome.success and "singular Jacobian" in outcome.message and "two nodes collide" in outcome.message


def test_newton_keeps_a_step_within_the_trust_bound_and_halves_a_step_that_does_not_decrease():
    visited = []

    def evaluate(z):
        visited.append(float(z[0]))
        return Evaluation(True, "", np.array([math.atan(z[0])]), np.array([[1.0 / (1.0 + z[0] ** 2)]]),
                          step_bound=1.0)

    outcome = newton(evaluate, np.array([1.5]), np.array([1.0]), tol=1e-14, max_iterations=40)
    assert outcome.success and abs(float(outcome.unknowns[0])) <= 1e-14  # Newton alone diverges on atan from 1.5
    assert max(abs(b - a) for a, b in zip(visited, visited[1:])) <= 1.0 + 1e-15


def _defined_functions(path: pathlib.Path) -> list[str]:
    return [node.name for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
            if isinstance(node, (ast.FunctionDef, ast.ClassDef))]


def test_one_newton_and_one_pseudo_arclength_driver_in_the_package():
    """No module but the core defines a Newton or a continuation driver; the branches subclass the one stepper."""
    newtons, drivers = [], []
    for path in PACKAGE.rglob("*.py"):
        names = _defined_functions(path)
        newtons += [(path.name, n) for n in names if "newton" in n.lower()]
        drivers += [(path.name, n) for n in names if n.lstrip("_") in ("drive", "Continuation", "Arclength", "correct",
                                                                       "corrector")]
    assert {module for module, _ in newtons} == {"newton.py"}
    assert {module for module, _ in drivers} == {"arclength.py"}
    steppers = {path.name for path in (PACKAGE / "numerics").glob("*.py")
                for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
                if isinstance(node, ast.ClassDef) and any(getattr(base, "id", "") == "Arclength" for base in node.bases)}
    assert steppers == {"forced_response.py", "nnm_branch.py"}  # forced and free branches: one stepper each


def test_the_special_points_of_a_free_branch_are_located_when_read_and_survive_pickling():
    import pickle

    branch = continue_nnm(_decoupled_system(), 1, modal_amplitude=1.0, start=0.0, stop=1.0)
    flows = branch.flow_evaluations
    copy = pickle.loads(pickle.dumps(branch))
    located = [(b.kind, b.forcing_scale, b.frequency) for b in branch.bifurcations]
    assert located == [(b.kind, b.forcing_scale, b.frequency) for b in copy.bifurcations]
    assert abs(located[0][1] - BRANCH_POINT) <= 1e-9
    assert branch.flow_evaluations == flows  # the continuation's counters are its own
