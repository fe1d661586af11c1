"""``numeric=True`` at gaps κ new to a warm process, against the exact Taylor coefficients of the period.

u'' + u + ε (u − κ)₊ = 0, u(0) = 1: every ω_k to the requested digits (less one for the cancellation of the
order's sums, two for margin), at κ where the float normal form takes its shortcuts (|κ| ≤ 1/2: no guard digits;
κ = 1/2: acos κ = π/3; κ = 0; negative κ) and near grazing (|κ| = 999/1000, guard digits), after an expansion at
another κ (the cached float field and its constants are shared).  Reference: the independent closed-form
piecewise-linear period expanded in ε (``lindstedt.references.piecewise_linear_frequency_taylor``), with its own
error estimate.
"""

import mpmath
import pytest
import sympy

import lindstedt
from lindstedt.references import piecewise_linear_frequency_taylor

KAPPAS = ["-999/1000", "-7/10", "-1/2", "0", "1/2", "3/101", "7/10", "999/1000"]


@pytest.mark.parametrize("precision", [16, 30])
def test_new_kappas_keep_the_requested_digits(precision):
    lindstedt.expand("Max(0, u - kappa)", order=4, a0=1, omega0=1, params={"kappa": "1/3"}, numeric=True,
                     precision=precision).omega  # warm: the field of these digits exists before the new κ
    for kappa in KAPPAS:
        omega = lindstedt.expand("Max(0, u - kappa)", order=4, a0=1, omega0=1, params={"kappa": kappa}, numeric=True,
                                 precision=precision).omega
        gap = sympy.Rational(kappa)
        with mpmath.workdps(precision + 20):
            reference = piecewise_linear_frequency_taylor(4, a=1, b=mpmath.mpf(gap.p) / gap.q, a0=1,
                                                          precision=precision + 20)
            assert float(omega[0]) == 1.0
            for k in range(1, 5):
                value, error = reference[k]
                ours = mpmath.mpf(sympy.N(omega[k], precision + 5))
                bound = max(mpmath.mpf(10) ** (2 - precision) * abs(value), 10 * error)
                assert abs(ours - value) <= bound, (kappa, k, ours, value)
