"""The stretched contact arc with many components, as the fast arc computes it.

The arc (a Hertz contact holding the release point) is solved on a Chebyshev grid by fixed-point transforms that
take two components — or a component's cosine and sine integrands — at once, doubling the grid until the stiffest
component is resolved.  A chain of 13 masses (an odd number of modal components: one transform carries a lone
component) with a Hertz element and a cubic spring needs two such doublings; the reference is Newton shooting on
the exact flow (:func:`lindstedt.nnm_point`).  The order-2 frequency's error must fall as ε³ and the release point
of the order-2 waveform (W_0 + ε̂ W_1 on the arc, read from the arc's Chebyshev series) as ε²; measured slopes
2.93 and 1.94 at ε = 1e-3 … 1e-4 (frequency errors 2.2e-8 … 2.6e-11, well above the shooting's ~1e-14; the
release-point slope fell to 1.78 when the lone component's series was zeroed).
"""

import numpy as np

import lindstedt


def _chain(size: int) -> lindstedt.UnilateralSystem:
    springs = [(0, 0.1), (size // 2, -0.05), (size - 1, 0.0)]
    elements = [(size // 3, None, "Max(0, u)**(3/2)", "1/100"), (0, 1, "u**3")]
    return lindstedt.UnilateralSystem.chain(size, unilateral=springs, elements=elements)


def test_a_hertz_contact_on_a_chain_of_13_masses_approaches_shooting_at_its_order():
    system = _chain(13)
    expansion = lindstedt.nnm(system, 1, a0=1.0, order=2)
    epsilons = np.geomspace(1e-3, 1e-4, 4)
    errors, release_errors = [], []
    for epsilon in epsilons:
        orbit = lindstedt.nnm_point(system, epsilon, 1, modal_amplitude=1.0)
        assert orbit.success, orbit.message
        errors.append(abs(float(expansion.frequency(epsilon)) - orbit.frequency))
        release_errors.append(np.max(np.abs(expansion.displacement(0.0, epsilon) - orbit.release_position)))
    assert min(errors) > 1e-13  # above the shooting's own error: the slope is the expansion's
    slope = np.polyfit(np.log(epsilons), np.log(errors), 1)[0]
    assert 2.8 <= slope <= 3.2, errors
    release_slope = np.polyfit(np.log(epsilons), np.log(release_errors), 1)[0]
    assert 1.8 <= release_slope <= 2.2, release_errors
