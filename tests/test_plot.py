"""lindstedt.plot draws the package's results and the independent references faithfully.

References: the Duffing frequency from the complete elliptic integral (lindstedt.references.duffing_exact_frequency)
for the backbone; the closed-form bilinear orbit of u'' + u + ε u_+ = 0 (two harmonic arcs, derived in the
waveform test) for the waveform.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib", reason="plots are optional: pip install 'lindstedt[plot]'")
matplotlib.use("Agg")

import lindstedt  # noqa: E402
import lindstedt.plot  # noqa: E402
from lindstedt.references import duffing_exact_frequency  # noqa: E402
from lindstedt.validate import exact_spectrum, expansion_spectrum, fitted_convergence_order  # noqa: E402


@pytest.fixture(autouse=True)
def close_figures():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


def test_backbone_draws_the_exact_duffing_frequency_and_orders_that_approach_it():
    amplitudes, epsilon = [0.4, 0.8, 1.2], 0.1
    ax = lindstedt.plot.backbone("u**3", amplitudes, epsilon, order=3)
    lines = {line.get_label(): line for line in ax.get_lines()}
    assert list(lines) == ["order 1", "order 2", "order 3", "exact"]
    exact = [float(duffing_exact_frequency(epsilon, amplitude=a, precision=30)) for a in amplitudes]
    assert np.allclose(lines["exact"].get_ydata(), exact, rtol=1e-15)
    errors = {n: np.abs(lines[f"order {n}"].get_ydata() - exact) for n in (1, 2, 3)}
    assert np.all(errors[3] < errors[2]) and np.all(errors[2] < errors[1])


def test_waveform_draws_the_closed_form_bilinear_orbit():
    # u'' + u + ε u_+ = 0, u(0) = 1, u'(0) = 0: u = cos(k t) (k = √(1+ε)) until t₁ = π/(2k), where u' = −k;
    # then u < 0 at frequency 1: u = −k sin(t − t₁), for t₁ ≤ t ≤ t₁ + π
    epsilon = 0.3
    k = math.sqrt(1 + epsilon)
    t1 = math.pi / (2 * k)
    times = np.linspace(0, t1 + math.pi, 41)
    closed_form = np.where(times <= t1, np.cos(k * times), -k * np.sin(times - t1))
    expansion = lindstedt.expand("Max(0, u)", order=2, a0=1, omega0=1)
    ax = lindstedt.plot.waveform(expansion, epsilon, times)
    expansion_line, exact_line = ax.get_lines()
    assert np.allclose(exact_line.get_ydata(), closed_form, atol=1e-11)
    assert np.allclose(expansion_line.get_ydata(), expansion.displacement(times, epsilon), rtol=0, atol=0)
    assert np.max(np.abs(expansion_line.get_ydata() - closed_form)) < 0.05  # order 2 at ε = 0.3 over half a period


def test_error_over_time_draws_the_distance_to_the_closed_form_bilinear_orbit():
    # the same closed-form orbit of u'' + u + ε u_+ = 0 as above, over its first half period
    epsilon = 0.05
    k = math.sqrt(1 + epsilon)
    t1 = math.pi / (2 * k)
    times = np.linspace(0, t1 + math.pi, 61)
    closed_form = np.where(times <= t1, np.cos(k * times), -k * np.sin(times - t1))
    expansions = [lindstedt.expand("Max(0, u)", order=n, a0=1, omega0=1) for n in (0, 1, 2)]
    ax = lindstedt.plot.error_over_time(expansions, epsilon, times)
    assert ax.get_yscale() == "log" and [line.get_label() for line in ax.get_lines()] == ["order 0", "order 1", "order 2"]
    for expansion, line in zip(expansions, ax.get_lines()):
        drawn = line.get_ydata()
        expected = np.maximum(np.abs(expansion.displacement(times, epsilon) - closed_form), 1e-16)
        # the exact flow matches the closed form to ~1e-15; errors are compared where they exceed that by 1e3
        large = expected > 1e-12
        assert np.allclose(drawn[large], expected[large], rtol=1e-3)
    maxima = [float(np.max(line.get_ydata())) for line in ax.get_lines()]
    assert maxima[0] > maxima[1] > maxima[2]


def test_error_over_time_needs_an_expansion():
    with pytest.raises(lindstedt.LindstedtError, match="at least one"):
        lindstedt.plot.error_over_time([], 0.1, [0.0, 1.0])


def test_frequency_response_draws_the_textbook_linear_resonance():
    # f = u: u'' + 2ζu' + (1 + ε)u = εF cos Ωt has the steady amplitude εF / √((1 + ε − Ω²)² + (2ζΩ)²) (textbook)
    epsilon, zeta, forcing = 0.1, 0.05, 1.0
    problem = lindstedt.ForcedOscillator("u", omega0=1, zeta=zeta, forcing=forcing)
    response = lindstedt.frequency_response(problem, 0.8, 1.3, epsilon=epsilon)
    ax = lindstedt.plot.frequency_response(response)
    lines = [line for line in ax.get_lines() if line.get_linestyle() == "-"]
    assert len(lines) == len(response) - 1 and lines[0].get_label() == "stable"
    for line in lines:
        omega, peak = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
        exact = epsilon * forcing / np.sqrt((1 + epsilon - omega**2) ** 2 + (2 * zeta * omega) ** 2)
        assert np.allclose(peak, exact, rtol=1e-9)  # the orbit's peak: shooting to 1e-10 (Hermite-refined samples)
    assert not [line for line in ax.get_lines() if line.get_linestyle() == "--"]  # a linear response is stable


def test_frequency_response_overlay_is_drawn_only_where_multiple_scales_applies():
    # the method covers |Ω − ω0| < ω0/2 (primary resonance); a sweep to 1.6 must not fail, and draw nothing beyond
    problem = lindstedt.ForcedOscillator("u", omega0=1, zeta="1/20", forcing=1)
    response = lindstedt.frequency_response(problem, 0.8, 1.6, epsilon=0.1)
    ax = lindstedt.plot.frequency_response(response, curve=lindstedt.frequency_response_curve(problem))
    overlay = next(line for line in ax.get_lines() if line.get_label() == "multiple scales, order 1")
    omega = np.asarray(overlay.get_xdata())
    assert omega.min() >= 0.8 and omega.max() < 1.5 and len(omega) > 100


def test_spectra_are_drawn_side_by_side_with_their_amplitudes():
    expansion = lindstedt.expand("Max(0, u)", order=3, a0=1, omega0=1)
    spectra = [expansion_spectrum(expansion, 0.2), exact_spectrum(expansion, 0.2)]
    ax = lindstedt.plot.spectrum(spectra, labels=["expansion", "exact"])
    assert ax.get_yscale() == "log"
    collections = ax.collections
    assert [c.get_label() for c in collections] == ["expansion", "exact"]
    for collection, item in zip(collections, spectra):
        tops = sorted(max(segment[:, 1]) for segment in collection.get_segments())
        amplitudes = np.asarray(item.amplitudes, dtype=float)
        assert np.allclose(tops, sorted(amplitudes[amplitudes > 0]))


def test_convergence_draws_the_fitted_line_and_states_the_slope():
    fit = fitted_convergence_order(lindstedt.expand("u**3", order=1, a0=1, omega0=1), [0.01, 0.02, 0.04])
    ax = lindstedt.plot.convergence(fit, labels=["Duffing, N = 1"])
    points, line = ax.get_lines()
    assert np.allclose(points.get_ydata(), fit.max_errors)
    assert np.allclose(line.get_ydata(), np.exp(fit.intercept) * np.asarray(fit.epsilons) ** fit.slope)
    assert points.get_label() == f"Duffing, N = 1: slope {fit.slope:.2f} (expected {fit.expected_slope:g})"


def test_branch_styles_follow_stability_and_jumps():
    system = lindstedt.UnilateralSystem.one_dof(1)
    result = lindstedt.continue_nnm(system, 1, start=0.0, stop=0.5, modal_amplitude=1.0)
    ax = lindstedt.plot.branch(result)
    segments = ax.get_lines()
    assert len(segments) == len(result.points) - 1
    for k, segment in enumerate(segments):
        expected = ":" if k in result.jumps else ("-" if result.points[k].stable and result.points[k + 1].stable else "--")
        assert segment.get_linestyle() == expected
        assert np.allclose(segment.get_ydata(), [result.points[k].frequency, result.points[k + 1].frequency])


def test_without_matplotlib_the_error_names_the_extra(monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "matplotlib.pyplot", None)
    with pytest.raises(lindstedt.LindstedtError, match=r"pip install 'lindstedt\[plot\]'"):
        lindstedt.plot.waveform(lindstedt.expand("u**3", order=1, a0=1, omega0=1), 0.1, [0.0, 1.0])


def test_nnm_orbit_of_the_seed_system_is_the_linear_mode_line_at_the_nonlinear_frequency():
    # seed system (5 dof): only u_1 is nonlinear, so the mode-1 NNM keeps every other modal coordinate at zero —
    # in configuration space X(t) = φ_1 q(t) is a segment along the first mode shape — and, with F = (X_1)_+ M φ_1,
    # q'' + λ1² q + ε (φ_11 q)_+ = 0 is bilinear: ω = 2 λ1 k / (λ1 + k), k² = λ1² + ε φ_11 (half a period per side)
    system = lindstedt.seed_example_system(5)
    epsilon = 0.2581
    point = lindstedt.nnm_point(system, epsilon, 1, modal_amplitude=1.0)
    orbit, lines = lindstedt.plot.nnm_orbit(point, dofs=(0, 2))
    x, y = orbit.get_lines()[0].get_data()
    shape = np.asarray(system.modes().shapes, dtype=float)[:, 0]
    assert np.allclose(y * shape[0], x * shape[2], atol=1e-12)  # collinear with φ_1
    assert (x[0], y[0]) == pytest.approx((point.release_position[0], point.release_position[2]), abs=1e-13)
    lam = float(system.modes().frequencies[0])
    stiff = math.sqrt(lam**2 + epsilon * shape[0])
    assert point.frequency == pytest.approx(2 * lam * stiff / (lam + stiff), rel=1e-12)
    fundamental = min(lines.collections[0].get_segments(), key=lambda segment: segment[0, 0] if segment[0, 0] > 1e-9 else np.inf)
    assert fundamental[0, 0] == pytest.approx(point.frequency, rel=1e-12)


def test_nnm_orbit_of_a_cubic_spring_between_two_masses_is_the_anti_phase_line():
    # chain(2) with (x1 − x2)³ between the masses: mode 2 stays on x1 = −x2 (the spring's force is odd, the chain
    # symmetric), sampled from the DOP853 flow of a law the exact flow does not take
    system = lindstedt.UnilateralSystem.chain(2, elements=[(0, 1, "u**3")])
    point = lindstedt.nnm_point(system, 0.5, 2, modal_amplitude=1.0)
    orbit, _ = lindstedt.plot.nnm_orbit(point)
    x, y = orbit.get_lines()[0].get_data()
    assert np.allclose(x, -y, atol=1e-10)
    assert (x[0], y[0]) == pytest.approx(tuple(point.release_position), abs=1e-13)
    assert np.max(x) == pytest.approx(point.release_position[0], rel=1e-9)  # released at a turning point


def test_frequency_response_in_the_load_is_drawn_against_the_load():
    # f = u: the steady amplitude is linear in the load scale s, s εF/|1 + ε − Ω² + 2iζΩ| (textbook)
    problem = lindstedt.ForcedOscillator("u", omega0=1, zeta="1/20", forcing=1)
    response = lindstedt.frequency_response(problem, 0.5, 2.0, epsilon=0.1, parameter="forcing", frequency=1.0)
    ax = lindstedt.plot.frequency_response(response)
    line = ax.get_lines()[0]
    s = np.asarray(line.get_xdata())
    assert "load scale" in ax.get_xlabel() and s.min() >= 0.5 - 1e-12 and s.max() <= 2.0 + 1e-12
    assert np.allclose(line.get_ydata(), s * 0.1 / abs(1.1 - 1.0 + 0.1j), rtol=1e-9)
    with pytest.raises(lindstedt.LindstedtError, match="problem's own load"):
        lindstedt.plot.frequency_response(response, curve=lindstedt.frequency_response_curve(problem))
    with pytest.raises(lindstedt.LindstedtError, match="dof must be"):
        lindstedt.plot.frequency_response(response, dof=1)
