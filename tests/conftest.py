"""Test-suite settings: no test depends on the machine's speed (issue 22).

Hypothesis's wall-clock checks are off for every property test: its per-example ``deadline`` (200 ms by default)
and its ``too_slow`` health check (data generation timed) would turn the suite red on a loaded machine.  Speed is
measured in ``benchmarks/``, as ratios.
"""

try:
    from hypothesis import HealthCheck, settings
except ImportError:  # the property tests import it themselves and say so
    pass
else:
    settings.register_profile("lindstedt", deadline=None, suppress_health_check=[HealthCheck.too_slow])
    settings.load_profile("lindstedt")


import numpy as np  # noqa: E402
import pytest  # noqa: E402


@pytest.fixture
def slope_against_shooting():
    """``slope(system, mode, a0, order=2)``: the NNM expansion's frequency error against Newton shooting
    (:func:`lindstedt.nnm_point`, the reference) at ε = 1e-2 … 1e-3, and its fitted log-log slope (order + 1 when
    the expansion is right); returns (slope, errors)."""
    import lindstedt

    def slope(system, mode, a0, order=2, epsilons=np.geomspace(1e-2, 1e-3, 4)):
        expansion = lindstedt.nnm(system, mode, a0=a0, order=order)
        errors = []
        for epsilon in epsilons:
            orbit = lindstedt.nnm_point(system, epsilon, mode, modal_amplitude=float(a0))
            assert orbit.success, orbit.message
            errors.append(abs(float(expansion.frequency(epsilon)) - orbit.frequency))
        return float(np.polyfit(np.log(epsilons), np.log(errors), 1)[0]), errors

    return slope
