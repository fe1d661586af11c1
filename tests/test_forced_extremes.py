"""Forced responses at extreme forcing frequencies (issue 23, item 5): refused up front, or right, or failed.

References (independent of the code under test):

* the textbook linear response ``u = Re(H e^{iΩt})``, ``H = ε F/(ω0² − Ω² + 2iζω0Ω)``, exact for
  ``Max(0, u − 1)`` while |u| < 1 (the response far above resonance is ~εF/Ω² ≪ 1) and for ``u**3`` up to the
  cubic's relative size ``ε |u|²/|ω0² − Ω²| < 1e-20`` there;
* the cost of a period map: 2π/Ω long, i.e. ``ω0/Ω`` natural periods — at Ω = 1e-4 that is 1e4 natural periods,
  beyond anything interactive, so it must be refused before integrating (a hang guard only, no wall clock).
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import lindstedt
from lindstedt import ForcedOscillator, ParameterError
from lindstedt.cli import main
from lindstedt.numerics import SmoothForcedFlow

EPSILON, ZETA = 0.1, 0.01
LAWS = ("u**3", "Max(0, u - 1)")  # DOP853 flow and the exact event-driven flow
FAR = (1e-4, 1e-9, 1e-300, 1e300)
INVALID = (float("inf"), float("nan"), 0.0, -1.0)


def problem(law: str) -> ForcedOscillator:
    return ForcedOscillator(law, omega0=1, zeta="1/100", forcing=1)


def textbook_state(omega: float) -> np.ndarray:
    """z0 = (u(0), u'(0)) of the linear steady response ``Re(H e^{iΩt})``."""
    H = EPSILON / (1 - omega**2 + 2j * ZETA * omega)
    return np.array([H.real, -omega * H.imag])


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("omega", FAR)
def test_far_frequencies_are_refused_with_the_estimate(law, omega):
    with pytest.raises(ParameterError) as orbit_error:
        lindstedt.forced_periodic_orbit(problem(law), omega, epsilon=EPSILON)
    message = str(orbit_error.value)
    if omega < 1:  # the estimate: ω0/Ω natural periods per forcing period, and the way out
        assert "far below" in message and "natural periods" in message and f"{1 / omega:.1e}" in message
        assert "quasi-static" in message
    else:
        assert "far above" in message and "ε F/Ω²" in message
    with pytest.raises(ParameterError, match="far (below|above)"):
        lindstedt.frequency_response(problem(law), omega, 1.0, epsilon=EPSILON)


@pytest.mark.parametrize("omega", INVALID)
def test_non_finite_and_non_positive_frequencies_are_refused(omega):
    with pytest.raises(ParameterError):
        lindstedt.forced_periodic_orbit(problem("u**3"), omega, epsilon=EPSILON)
    with pytest.raises(ParameterError):
        lindstedt.frequency_response(problem("u**3"), 0.5, omega, epsilon=EPSILON)


def test_a_range_reaching_far_below_resonance_is_refused():
    with pytest.raises(ParameterError, match="start Ω = 1e-09 is far below"):
        lindstedt.frequency_response(problem("u**3"), 1e-9, 1e9, epsilon=EPSILON)


def _right_or_reported(orbit, omega: float) -> None:
    """A successful orbit is the textbook one to the verification's 1e-6 (×10 margin); otherwise it says why."""
    if orbit.success:
        reference = textbook_state(omega)
        size = float(np.max(np.abs(reference)))
        assert np.max(np.abs(orbit.state - reference)) <= 1e-5 * size
        assert "verified" in orbit.message
    else:
        assert "independent check" in orbit.message


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("omega", (1e3, 1e6))
def test_far_above_resonance_the_orbit_is_the_linear_response_or_a_failure(law, omega):
    orbit = lindstedt.forced_periodic_orbit(problem(law), omega, epsilon=EPSILON)
    if omega == 1e3:  # well conditioned: must succeed (it was right before too)
        assert orbit.success, orbit.message
    _right_or_reported(orbit, omega)


def test_a_loose_integration_is_not_reported_converged():
    """rtol 1e-6 at Ω = 1e3: the period map errs by ~rtol·(Ω/ω0)², Newton converges to a wrong fixed point."""
    flow = SmoothForcedFlow(problem("u**3"), EPSILON, rtol=1e-6, atol=1e-6)
    _right_or_reported(lindstedt.forced_periodic_orbit(flow, 1e3), 1e3)


def test_a_branch_far_above_resonance_is_a_success_only_where_it_is_right():
    """Swept from Ω = 1e3 to 9e5 (response 1e-6 … 1e-12, linear: the gap at 1 is never reached), the branch's
    first harmonics stay right, but its sampled amplitudes drift from the textbook |H| by rounding noise (38× at
    Ω = 7e5, measured); the branch is checked at sampled points by an independent DOP853 period, so it cannot be
    reported a success with such points."""
    response = lindstedt.frequency_response(problem("Max(0, u - 1)"), 1e3, 9e5, epsilon=EPSILON)
    errors = [abs(float(p.amplitude[0]) / abs(EPSILON / (1 - p.frequency**2 + 2j * ZETA * p.frequency)) - 1)
              for p in response.points]
    assert max(errors) > 1e-6  # what the check guards against is there
    assert not response.success and "fails the independent check" in response.message, response.message
    near = lindstedt.frequency_response(problem("Max(0, u - 1)"), 2.0, 20.0, epsilon=EPSILON)
    assert near.success, near.message  # where the branch is right, it is a success
    for p in near.points:
        textbook = abs(EPSILON / (1 - p.frequency**2 + 2j * ZETA * p.frequency))
        assert float(p.amplitude[0]) == pytest.approx(textbook, rel=1e-6)


@pytest.mark.parametrize("at", ["1e-4", "1e-9", "1e-300", "1e300", "inf", "nan", "0", "-1"])
def test_cli_refuses_in_one_line(at, capsys):
    assert main(["forced", "u**3", "--eps", "0.1", "--zeta", "0.01", "--at", at]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and "Traceback" not in captured.err


def test_cli_subprocess_refuses_a_sweep_from_far_below():
    command = [sys.executable, "-m", "lindstedt", "forced", "u**3", "--eps", "0.1", "--zeta", "0.01",
               "--from", "1e-9", "--to", "1e9"]
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)  # a hang guard, not a timing
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and "natural periods" in lines[0]
