"""The strained-coordinates NNM of a chain whose elements carry any law, every modal component kept (issue 26).

``M X'' + K X + ε Σ_i w_i f_i(a_iᵀ X − b_i) = 0`` on a chain of 12 or 13 masses with three unilateral springs, a Hertz
contact ``Max(0, u)**(3/2)`` (its contact arc holds the release turning point, solved in stretched time) and a cubic
spring between the first two masses.  Every order's right-hand side reaches each component through the elements'
projections ``c_e · W`` only, and the engine solves those shared parts term by term for every component instead of
one branch per component (the highest order's branches formed only when asked for).  The arc is solved on a
Chebyshev grid by fixed-point transforms that take two components — or a component's cosine and sine integrands —
at once, doubling the grid until the stiffest component is resolved: 13 masses give an odd number of components (one
transform carries a lone component) and two doublings.

Reference, not the code under test: shooting on the DOP853 flow (:func:`lindstedt.numerics.nnm_point`, agreement
with closed forms ~1e-14, tests/test_nnm_any_law.py).  The order-2 expansion must approach it as ε³ — the fitted
slope of the frequency error over ε = 1e-3 … 1e-4 (errors 6e-10 … 4e-13 at 12 masses, 2.2e-8 … 2.6e-11 at 13, above
the shooting's 1e-14; the series' estimated radius is ~1e-3, so the ε⁴ term still tilts it) measured 3.17 and 2.93 —
and its waveform W_0 + ε̂ W_1 as ε² at the release point (measured 1.95 and 1.94; the slope fell to 1.78 when the
lone component's series was zeroed, and the test fails when the shared part is off by 10 % or has the wrong sign).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import lindstedt
from lindstedt.numerics import nnm_point


def _chain(size: int) -> lindstedt.UnilateralSystem:
    springs = [(0, 0.1), (size // 2, -0.05), (size - 1, 0.0)]
    elements = [(size // 3, None, "Max(0, u)**(3/2)", "1/100"), (0, 1, "u**3")]
    return lindstedt.UnilateralSystem.chain(size, unilateral=springs, elements=elements)


@pytest.mark.parametrize("size", [12, 13])
def test_the_nnm_of_a_chain_with_a_hertz_contact_and_a_cubic_spring_approaches_shooting_at_its_order(size):
    system = _chain(size)
    expansion = lindstedt.nnm(system, 1, a0=1.0, order=2)
    assert expansion.spring_roots == ("none", "simple", "simple", "simple", "none")
    epsilons = np.geomspace(1e-3, 1e-4, 4)
    errors, release_errors = [], []
    for epsilon in epsilons:
        orbit = nnm_point(system, epsilon, 1, modal_amplitude=1.0)
        assert orbit.success, orbit.message
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", lindstedt.ExpansionValidityWarning)  # 1e-3 is at the estimated radius
            errors.append(abs(float(expansion.frequency(epsilon)) - orbit.frequency))
            release_errors.append(np.max(np.abs(expansion.displacement(0.0, epsilon) - orbit.release_position)))
    assert min(errors) > 1e-13  # above the shooting's own error: the slope is the expansion's
    slope = np.polyfit(np.log(epsilons), np.log(errors), 1)[0]
    assert 2.8 <= slope <= 3.3, errors
    release_slope = np.polyfit(np.log(epsilons), np.log(release_errors), 1)[0]
    assert 1.8 <= release_slope <= 2.2, release_errors
