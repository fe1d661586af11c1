"""Properties of the contact Fourier coefficients: the a0 ↦ −a0 relation c̃_k = (−1)^k c_k (hypothesis)."""

import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

import lindstedt
from lindstedt.algebra import contact_ramp_coefficient, contact_ramp_coefficients_float


@settings(max_examples=40, deadline=None)
@given(kappa=st.floats(-0.99, 0.99), harmonic=st.integers(0, 12))
def test_mirrored_ramp_coefficients_by_quadrature(kappa, harmonic):
    # (−cos s − κ)_+ = (cos(s + π) − κ)_+ : its k-th cosine coefficient is (−1)^k c_k[κ]
    weight = (1 if harmonic == 0 else 2) / np.pi
    beta = np.arccos(-kappa)  # contact for cos s < −κ, i.e. s > π − arccos κ
    mirrored = weight * quad(lambda s: max(0.0, -np.cos(s) - kappa) * np.cos(harmonic * s), beta, np.pi, epsabs=1e-13, epsrel=1e-13)[0]
    expected = (-1) ** harmonic * float(contact_ramp_coefficients_float(kappa, harmonic))
    assert mirrored == pytest.approx(expected, abs=1e-11)


@settings(max_examples=8, deadline=None)
@given(numerator=st.integers(-9, 9))
def test_negative_release_first_order_waveform_has_alternating_coefficients(numerator):
    # u'' + u + ε (u − b)_+ with u(0) = −1: v0 = −cos s and the forcing is (−1)^k c_k[κ] with κ = b:
    # v1 = Σ d̃_k cos(ks), d̃_k = −(−1)^k c_k[κ]/(1 − k²) for k ≠ 1
    kappa = sympy.Rational(numerator, 10)
    v1 = lindstedt.expand(f"Max(0, u - ({kappa}))", order=1, a0=-1, omega0=1).waveforms[1]
    for k in (0, 2, 3, 4):
        expected = -((-1) ** k) * contact_ramp_coefficient(k, kappa) / (1 - k**2)
        assert abs(sympy.N(v1.cosine_coefficient(k) - expected, 30)) < 1e-25
