"""Fourier spectra (lindstedt.validate.spectrum and friends) against exact line spectra and closed forms.

Expected values: trigonometric polynomials (exact line spectra); the exact
solution of u'' + ω0² u + ε u_+ = 0 written by hand (contact arc a0 cos(ω' t),
free arc −(a0 ω'/ω0) sin(ω0 (t − t1))) whose Fourier coefficients are computed
here by scipy quadrature; the cosine coefficients of v_1 for u_+ derived by hand
from |cos s| = 2/π − (4/π) Σ (−1)^k cos(2ks)/(4k² − 1):

    d_0 = −a0/(π ω0²),   d_2k = −2 a0 (−1)^k / (π ω0² (4k² − 1)²),   d_odd≥3 = 0;

and Duffing's exact period 4K(m)/Ω and first correction (a0³/(32 ω0²)) cos 3s.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.special

import lindstedt
from lindstedt import ProblemError
from lindstedt.validate import exact_period, exact_spectrum, expansion_spectrum, spectrum


def d_u_plus(k, a0=1.0, omega0=1.0):
    """Cosine coefficient d_k of v_1 for f = u_+ (a0 > 0), derived by hand (module docstring)."""
    if k == 0:
        return -a0 / (math.pi * omega0**2)
    if k % 2 == 1:
        return a0 / (4 * omega0**2) if k == 1 else 0.0
    half = k // 2
    return -2 * a0 * (-1) ** half / (math.pi * omega0**2 * (4 * half**2 - 1) ** 2)


def u_plus_fourier(k, a0, omega0, eps):
    """c_k of the exact u_+ solution, integrated by hand over the half period [0, P/2].

    c_0 = (2/P) ∫ u dt and c_k = (4/P) ∫ u cos(kΩt) dt, Ω = 2π/P, with u = a0 cos(ω' t)
    on [0, t1] and u = −(a0 ω'/ω0) sin(ω0 τ), τ = t − t1 ∈ [0, L = π/(2ω0)], after.
    """
    omega_c = math.sqrt(omega0**2 + eps)
    t1 = math.pi / (2 * omega_c)
    period = math.pi / omega_c + math.pi / omega0
    beta = k * 2 * math.pi / period
    length = math.pi / (2 * omega0)

    def cos_integral(x, upper):  # ∫_0^upper cos(x τ) dτ
        return upper * np.sinc(x * upper / math.pi)

    def sin_integral(x, upper):  # ∫_0^upper sin(x τ) dτ = 2 sin²(x upper/2)/x
        return upper * math.sin(x * upper / 2) * np.sinc(x * upper / (2 * math.pi))

    contact = a0 * 0.5 * (cos_integral(omega_c - beta, t1) + cos_integral(omega_c + beta, t1))
    # cos(β(τ + t1)) = cos(βt1) cos(βτ) − sin(βt1) sin(βτ)
    sin_cos = 0.5 * (sin_integral(omega0 + beta, length) + sin_integral(omega0 - beta, length))
    sin_sin = 0.5 * (cos_integral(omega0 - beta, length) - cos_integral(omega0 + beta, length))
    free = -(a0 * omega_c / omega0) * (math.cos(beta * t1) * sin_cos - math.sin(beta * t1) * sin_sin)
    return (2.0 if k == 0 else 4.0) / period * (contact + free)


# --------------------------------------------------------------------------- #
# the transform itself
# --------------------------------------------------------------------------- #
def test_pure_cosines_give_exactly_their_harmonic_lines():
    periods, per_period = 3, 128
    omega = 1.7
    duration = periods * 2 * math.pi / omega
    t = np.arange(periods * per_period) * duration / (periods * per_period)
    signal = 0.3 - 1.25 * np.cos(omega * t) + 0.5 * np.cos(2 * omega * t) + 1e-3 * np.cos(7 * omega * t)
    result = spectrum(signal, duration, periods=periods)
    assert result.success and result.window == "rectangular"
    assert result.fundamental == pytest.approx(omega, rel=1e-15)
    assert result.labels == (0, 1, 2, 7)
    assert [peak.bin for peak in result.peaks] == [0, 3, 6, 21]
    expected = {0: 0.3, 1: -1.25, 2: 0.5, 7: 1e-3}
    for k, value in expected.items():
        assert abs(result.cosine_coefficient(k) - value) < 1e-14
    others = np.ones(result.amplitudes.size, dtype=bool)
    others[[0, 3, 6, 21]] = False
    assert np.max(result.amplitudes[others]) < 1e-14  # no leakage
    assert result.log10_relative[3] == 0.0  # |û|/max|û| = 1 at the fundamental
    assert result.log10_relative[21] == pytest.approx(math.log10(1e-3 / 1.25), abs=1e-12)
    assert result.harmonic_numbers[21] == pytest.approx(7.0, abs=1e-12)


def test_sine_phase_and_nyquist_bin():
    n = 16
    t = np.arange(n) * 2 * math.pi / n
    result = spectrum(np.sin(2 * t) + 0.25 * np.cos(8 * t), 2 * math.pi, periods=1)
    assert result.coefficients[2] == pytest.approx(-1j, abs=1e-15)  # c_k − i s_k with s_2 = 1
    assert result.amplitudes[8] == pytest.approx(0.25, abs=1e-15)  # Nyquist bin not doubled


def test_hann_window_labels_lines_of_a_non_whole_window():
    omega = 1.0
    duration = 40.3 * 2 * math.pi / omega  # not a whole number of periods
    n = 8192
    t = np.arange(n) * duration / n
    result = spectrum(np.cos(omega * t) + 0.1 * np.cos(3 * omega * t) + 0.5, duration, fundamental=omega, peak_floor=-3)
    assert result.window == "hann"
    assert result.labels == (0, 1, 3)
    amplitudes = [peak.amplitude for peak in result.peaks]
    # the Hann window's scalloping loss is at most 15.2 % (line midway between bins)
    assert amplitudes[1] == pytest.approx(1.0, rel=0.16) and amplitudes[2] == pytest.approx(0.1, rel=0.16)


def test_spectrum_rejects_bad_input():
    with pytest.raises(ProblemError):
        spectrum([1.0, 2.0], 1.0)
    with pytest.raises(ProblemError):
        spectrum(np.ones(8), 1.0, periods=1, fundamental=2.0)
    with pytest.raises(ProblemError):
        spectrum(np.ones(8), -1.0)


# --------------------------------------------------------------------------- #
# u_+ : mean and even harmonics
# --------------------------------------------------------------------------- #
def test_u_plus_expansion_spectrum_matches_hand_and_library_coefficients():
    expansion = lindstedt.expand("Max(0, u)", order=1, a0=1, omega0=1)
    v1 = lindstedt.expand("Max(0, u)", order=1).waveforms[1]  # symbolic a0, omega0
    eps = 0.01
    result = expansion_spectrum(expansion, eps, samples_per_period=1024, peak_floor=-8)
    assert result.success
    assert result.labels[:5] == (0, 1, 2, 4, 6)  # a mean, the fundamental, even harmonics
    for k in range(0, 9):
        hand = d_u_plus(k)
        exact = v1.cosine_coefficient(k)
        library = float(exact.subs({symbol: 1 for symbol in exact.free_symbols}))
        assert abs(library - hand) < 1e-15
        measured = result.cosine_coefficient(k) - (1.0 if k == 1 else 0.0)  # remove v_0 = cos s
        assert abs(measured - eps * hand) < 1e-12


@pytest.mark.parametrize("eps", [0.1, 0.01])
def test_exact_u_plus_spectrum(eps):
    result = exact_spectrum(lindstedt.Oscillator("Max(0, u)", a0=1, omega0=1), eps, samples_per_period=1024)
    assert result.success
    omega_c = math.sqrt(1 + eps)
    period = math.pi / omega_c + math.pi
    assert result.duration == pytest.approx(period, rel=1e-14)
    # the mean by hand: (2/P)(a0/ω' − a0 ω'/ω0²); the coefficients decay like k^-4
    # (u''' jumps), so aliasing from harmonics beyond 1024 stays below 1e-12
    assert result.cosine_coefficient(0) == pytest.approx(2 / period * (1 / omega_c - omega_c), abs=1e-12)
    for k in range(0, 9):
        assert abs(result.cosine_coefficient(k) - u_plus_fourier(k, 1.0, 1.0, eps)) < 1e-12
        if k % 2 == 0:  # mean and even harmonics: ε d_k + O(ε²)
            assert abs(result.cosine_coefficient(k) - eps * d_u_plus(k)) < 0.1 * eps**2
        elif k >= 3:  # odd harmonics are absent from v_1: O(ε²) only
            assert result.harmonic_amplitude(k) < 0.02 * eps**2


def test_exact_period_of_u_plus_and_duffing():
    eps = 0.5
    u_plus = exact_period(lindstedt.Oscillator("Max(0, u)", a0=2, omega0=3), eps)
    assert u_plus.success and u_plus.reference_method == "exact"
    assert u_plus.period == pytest.approx(math.pi / math.sqrt(9 + eps) + math.pi / 3, rel=1e-14)
    a0 = 1.5
    big_omega2 = 1 + eps * a0**2
    duffing = 4 * scipy.special.ellipk(eps * a0**2 / (2 * big_omega2)) / math.sqrt(big_omega2)
    assert exact_period(lindstedt.Oscillator("u**3", a0="1.5", omega0=1), eps).period == pytest.approx(duffing, rel=1e-11)


# --------------------------------------------------------------------------- #
# Duffing: odd harmonics only
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize("eps", [0.05, 0.2])
def test_duffing_has_only_odd_harmonics(eps):
    result = exact_spectrum(lindstedt.Oscillator("u**3", a0=1, omega0=1), eps, samples_per_period=128)
    assert result.success
    assert all(label % 2 == 1 for label in result.labels)
    assert result.labels[:3] == (1, 3, 5)
    even = result.amplitudes[0:64:2]  # bins 0, 2, 4, … (one period: bin = harmonic)
    assert np.max(even) < 1e-10  # DOP853 at rtol 1e-12
    # first correction (a0³/(32 ω0²)) (cos 3s − cos s): c_3 = ε/32 + O(ε²)
    assert abs(result.cosine_coefficient(3) - eps / 32) < 0.05 * eps**2


def test_duffing_expansion_spectrum_lines():
    expansion = lindstedt.expand("u**3", order=2, a0=1, omega0=1)
    result = expansion_spectrum(expansion, 0.1, periods=2, samples_per_period=64, peak_floor=-14)
    assert result.labels == (1, 3, 5)  # v_2 reaches 5 s; lines at bins 2, 6, 10
    assert [peak.bin for peak in result.peaks] == [2, 6, 10]
    v1, v2 = expansion.waveforms[1], expansion.waveforms[2]
    expected = 0.1 * float(v1.coefficient(3)) + 0.01 * float(v2.coefficient(3))
    assert result.cosine_coefficient(3) == pytest.approx(expected, abs=1e-15)
