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
