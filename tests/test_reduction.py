"""Modal truncation with residual flexibility (lindstedt.ResidualFlexibility): a large structure reduced to its low
modes plus one static vector per element.

References, none from the code under test: the full model's strained-coordinates NNM (every mode to 30 digits,
itself checked against shooting and closed forms in test_structures / test_nnm_element_laws); the plain modal
truncation (the same kept modes without the residual vector) as the baseline the residual flexibility must beat.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy

import lindstedt
from lindstedt import EulerBernoulliBeam, ResidualFlexibility, UnilateralSystem


def _relative(values, reference):
    return [abs(a - b) / abs(b) for a, b in zip(values, reference)]


@pytest.fixture(scope="module")
def cracked_beam():
    beam = EulerBernoulliBeam(40, cracks=[(10, 10)])
    return beam, lindstedt.nnm(beam.system(), 1, a0=1, order=2).omega


def _truncated(system: UnilateralSystem, elements: int) -> UnilateralSystem:
    """The same Galerkin projection without the residual vectors (plain modal truncation)."""
    keep = system.n_dof - elements
    return UnilateralSystem(system.M_exact[:keep, :keep], system.K_exact[:keep, :keep], system.A_exact[:, :keep],
                            list(system.b), system.W_exact[:keep, :])


def test_kept_mode_is_exact_and_residual_flexibility_beats_truncation(cracked_beam):
    beam, full = cracked_beam
    for modes in (2, 4):
        reduced = ResidualFlexibility(modes=modes).reduce(beam)
        assert reduced.success, reduced.message
        assert reduced.system.n_dof == modes + 1 and reduced.n_dof == beam.n_dof == 81
        assert reduced.bandwidth <= 4
        omega = lindstedt.nnm(reduced.system, 1, a0=1, order=2).omega
        # ω₀ and ω₁ of a kept mode are the full model's to the working precision (30 digits)
        assert all(error < 1e-28 for error in _relative(omega[:2], full[:2]))
        # the mode is the full model's first: λ₁ equals its refined value
        assert abs(reduced.frequencies[0] - full[0]) < 1e-28
        # ω₂ carries the truncation: with the residual vector at least 10³ times smaller than without it
        plain = lindstedt.nnm(_truncated(reduced.system, 1), 1, a0=1, order=2).omega
        with_residual = _relative(omega[2:], full[2:])[0]
        without = _relative(plain[2:], full[2:])[0]
        assert with_residual < 1e-3 * without, (modes, with_residual, without)
        assert with_residual < 1e-3


@pytest.mark.slow
def test_truncation_error_falls_with_the_modes_kept():
    beam = EulerBernoulliBeam(100, cracks=[(25, 10)])
    full = lindstedt.nnm(beam.system(), 1, a0=1, order=2).omega
    errors = []
    for modes in (4, 8, 12, 16):
        reduced = ResidualFlexibility(modes=modes).reduce(beam)
        omega = lindstedt.nnm(reduced.system, 1, a0=1, order=2).omega
        assert all(error < 1e-28 for error in _relative(omega[:2], full[:2]))
        errors.append(float(_relative(omega[2:], full[2:])[0]))
    # not monotone mode by mode (a mode whose curvature vanishes at the crack adds nothing), but falling overall
    assert errors[-1] < 1e-2 * errors[0], errors
    assert errors[-1] < 1e-9, errors


def test_matrices_and_any_law_match_the_full_system():
    full_system = UnilateralSystem.chain(12, unilateral=[(3, 0)])
    cubic = "u**3"
    laws_system = UnilateralSystem(full_system.M_exact, full_system.K_exact, full_system.A_exact, [0],
                                   full_system.W_exact, [cubic])
    M = np.array(full_system.M_exact.tolist(), dtype=float)
    K = np.array(full_system.K_exact.tolist(), dtype=float)
    A = np.array(full_system.A_exact.tolist(), dtype=float)
    for system, laws in ((full_system, None), (laws_system, [cubic])):
        reference = lindstedt.nnm(system, 1, a0=1, order=2).omega
        import scipy.sparse

        reduced = ResidualFlexibility(modes=3).reduce((scipy.sparse.csr_matrix(M), K), A=A, laws=laws)
        assert reduced.system.n_dof == 4
        omega = lindstedt.nnm(reduced.system, 1, a0=1, order=2).omega
        assert all(error < 1e-28 for error in _relative(omega[:2], reference[:2]))
        assert _relative(omega[2:], reference[2:])[0] < 1e-2


def test_estimate_and_budget(cracked_beam):
    beam, _ = cracked_beam
    estimate = ResidualFlexibility(modes=6).estimate(10001, 4, 1, 40)
    assert estimate.seconds > 1 and estimate.memory_mb > 10
    with lindstedt.limits.budget(seconds=1e-6):
        with pytest.raises(lindstedt.limits.BudgetError, match="residual-flexibility reduction"):
            ResidualFlexibility(modes=2).reduce(beam)


@pytest.mark.parametrize("build, match", [
    (lambda beam: ResidualFlexibility(modes=0), "modes must be a positive integer"),
    (lambda beam: ResidualFlexibility(modes=2, digits=True), "digits must be a positive integer"),
    (lambda beam: ResidualFlexibility(modes=80).reduce(beam), "leave nothing to reduce"),
    (lambda beam: ResidualFlexibility(modes=2).reduce(beam, A=np.ones((1, 81))), "brings its own elements"),
    (lambda beam: ResidualFlexibility(modes=2).reduce("beam.npz"), "EulerBernoulliBeam or a pair"),
    (lambda beam: ResidualFlexibility(modes=2).reduce((beam.M, beam.K)), "give the elements' rows A"),
    (lambda beam: ResidualFlexibility(modes=2).reduce((beam.M, beam.K), A=np.ones((1, 5))), "expected 1×81"),
    (lambda beam: ResidualFlexibility(modes=2).reduce((beam.M, -beam.K), A=np.ones((1, 81))), "positive definite"),
])
def test_bad_input(cracked_beam, build, match):
    beam, _ = cracked_beam
    with pytest.raises(lindstedt.ProblemError, match=match):
        build(beam)


def test_precision_does_not_leak(cracked_beam):
    import gmpy2

    beam, _ = cracked_beam
    before = (mpmath.mp.prec, gmpy2.get_context().precision)
    ResidualFlexibility(modes=2, digits=20).reduce(beam)
    assert (mpmath.mp.prec, gmpy2.get_context().precision) == before


def test_reduction_is_reproducible_to_the_last_bit(cracked_beam):
    # the float Lanczos start is fixed: ARPACK's default random start vector changed the reduced data below 1e-30
    # (and ω_2 of an NNM on them in the 35th digit) from one call to the next
    beam, _ = cracked_beam
    first, second = (ResidualFlexibility(modes=4).reduce(beam).system for _ in range(2))
    for name in ("M_exact", "K_exact", "A_exact", "W_exact"):
        assert getattr(first, name) == getattr(second, name), name


def test_reducing_a_reduced_model_equals_the_direct_reduction(cracked_beam):
    # span(Φ_8, Z_8) holds Φ_4 and K⁻¹W exactly, so its Galerkin 4-mode reduction is the full model's
    beam, _ = cracked_beam
    direct = ResidualFlexibility(modes=4).reduce(beam)
    large = ResidualFlexibility(modes=8).reduce(beam).system
    again = ResidualFlexibility(modes=4).reduce((large.M_exact, large.K_exact), A=large.A_exact, b=list(large.b),
                                                W=large.W_exact)
    assert again.system.n_dof == direct.system.n_dof == 5
    first = lindstedt.nnm(direct.system, 1, a0=1, order=2).omega
    second = lindstedt.nnm(again.system, 1, a0=1, order=2).omega
    assert all(error < 1e-25 for error in _relative(second, first))


def test_forced_linear_response_with_the_load_residual_matches_the_full_model():
    # M X'' + C X' + K X = ε P cos Ωt on the 100-dof cantilever (stops at the tip out of reach): the exact response
    # X = Re(X̂ e^{iΩt}), X̂ = ε (K − Ω² M + iΩ C)⁻¹ P, solved at 30 digits (mpmath) on the full model, against the
    # periodic orbit of the reduced model (4 modes + the residual vectors of the stops and of the load at mid-span)
    beam = EulerBernoulliBeam(50)
    exact = beam.system()
    n, tip, mid = beam.n_dof, beam.index("w50"), beam.index("w25")
    A = np.zeros((2, n))
    A[0, tip], A[1, tip] = 1, -1
    shape = [sympy.Rational(1, 15) if i == mid else sympy.Integer(0) for i in range(n)]
    reduced = ResidualFlexibility(modes=4).reduce((exact.M_exact, exact.K_exact), A=A, b=[10, 10], loads=shape)
    assert reduced.system.n_dof == 6  # the stops share one residual vector, the load has its own
    lam1 = float(reduced.frequencies[0])
    alpha, beta, frequency, eps = 0.01 * lam1, 0.01 / lam1, 1.1 * lam1, 1.0

    def response(load: list) -> np.ndarray:
        orbit = lindstedt.forced_periodic_orbit(lindstedt.ForcedSystem(reduced.system, load, rayleigh=(alpha, beta)),
                                                frequency, epsilon=eps)
        assert orbit.success, orbit.message
        return reduced.basis @ (orbit.harmonic_cos - 1j * orbit.harmonic_sin)

    with mpmath.workdps(30):
        def matrix(exact_matrix):
            return mpmath.matrix([[mpmath.mpf(v.p) / v.q for v in row] for row in exact_matrix.tolist()])

        M, K = matrix(exact.M_exact), matrix(exact.K_exact)
        omega = mpmath.mpf(frequency)
        dynamic = K - omega**2 * M + 1j * omega * (mpmath.mpf(alpha) * M + mpmath.mpf(beta) * K)
        full = mpmath.lu_solve(dynamic, mpmath.matrix([eps * mpmath.mpf(v.p) / v.q for v in shape]))
    reference = np.array([complex(full[i]) for i in range(n)])
    with_residual = response(list(reduced.loads[0]))
    plain = response(list(reduced.basis[:, :4].T @ np.array([float(v) for v in shape])) + [0.0, 0.0])
    for dof in (tip, mid):
        # the shooting tolerance (1e-10 on the orbit) bounds the reduced side; the truncation is below it
        assert abs(with_residual[dof] - reference[dof]) < 1e-9 * abs(reference[dof])
    # the load's quasi-static share above the kept modes: missing without its residual vector
    assert abs(plain[mid] - reference[mid]) > 1e-5 * abs(reference[mid])


def test_loads_of_the_wrong_shape_are_refused(cracked_beam):
    beam, _ = cracked_beam
    with pytest.raises(lindstedt.ProblemError, match="one row per degree of freedom"):
        ResidualFlexibility(modes=2).reduce(beam, loads=[1, 2, 3])


@pytest.mark.parametrize("matrices, match", [
    (lambda M, K: (M, K + np.triu(K, 1)), "K is not symmetric"),
    (lambda M, K: (M - 2 * np.diag(np.diag(M)), K), "M in the structure must be positive definite"),
    (lambda M, K: (M, sympy.Matrix(K) * sympy.Symbol("k")), "must be a real number"),
    (lambda M, K: (M, K.astype(object)), "must be a real numeric matrix"),
])
def test_bad_matrices(matrices, match):
    chain = UnilateralSystem.chain(8, unilateral=[(2, 0)])
    M = np.array(chain.M_exact.tolist(), dtype=float)
    K = np.array(chain.K_exact.tolist(), dtype=float)
    with pytest.raises(lindstedt.ProblemError, match=match):
        ResidualFlexibility(modes=2).reduce(matrices(M, K), A=np.array(chain.A_exact.tolist(), dtype=float))


def test_irrational_exact_entries_keep_the_working_precision():
    # K = √2 · (chain stiffness): every λ_k scales by 2^(1/4) exactly
    chain = UnilateralSystem.chain(8, unilateral=[(2, 0)])
    scaled = ResidualFlexibility(modes=3).reduce((chain.M_exact, chain.K_exact * sympy.sqrt(2)), A=chain.A_exact)
    plain = ResidualFlexibility(modes=3).reduce((chain.M_exact, chain.K_exact), A=chain.A_exact)
    for a, b in zip(scaled.frequencies, plain.frequencies):
        assert abs(a / b - mpmath.root(2, 4)) < mpmath.mpf(10) ** -28


@pytest.mark.slow
def test_reduced_forced_orbit_in_contact_converges_to_the_full_models():
    # the string-scaled 100-mass chain between two stops, forced at its first frequency hard enough to hit the stop
    # at mass 25: the full model's periodic orbit (exact event-driven flow, checked by an independent DOP853 period)
    # against the reduced models' (K modes + the residual vectors of the stops and the load). A string's modes sit
    # near the harmonics of the response (λ_k ≈ k λ₁), so the truncation converges only algebraically in K: the
    # fitted order must be positive and steep, the error at K = 16 small
    n = 100
    system = UnilateralSystem.chain(n, unilateral=[(n // 4, 1), (3 * n // 4, 1, -1)], mass=f"1/{n + 1}", stiffness=n + 1)
    load = [sympy.Integer(0)] * n
    load[n // 2] = sympy.Rational(1, 20)
    lam1 = float(system.modes().frequencies[0])
    rayleigh, frequency, eps = (0.01 * lam1, 0.01 / lam1), lam1, 10.0
    full = lindstedt.forced_periodic_orbit(lindstedt.ForcedSystem(system, load, rayleigh=rayleigh), frequency, epsilon=eps)
    assert full.success, full.message
    assert full.maximum[n // 4] > 1.05  # in contact with the stop
    errors = []
    for modes in (4, 8, 16):
        reduced = ResidualFlexibility(modes=modes).reduce((system.M_exact, system.K_exact), A=system.A_exact,
                                                          b=list(system.b_exact), loads=load)
        start = np.linalg.lstsq(reduced.basis, full.state.reshape(2, n).T, rcond=None)[0].T.ravel()
        orbit = lindstedt.forced_periodic_orbit(lindstedt.ForcedSystem(reduced.system, list(reduced.loads[0]),
                                                                       rayleigh=rayleigh),
                                                frequency, epsilon=eps, initial_state=start)
        assert orbit.success, orbit.message
        displacement = reduced.basis @ orbit.state[:reduced.system.n_dof]
        errors.append(np.max(np.abs(displacement - full.state[:n])) / np.max(np.abs(full.state[:n])))
    order = -np.polyfit(np.log([4, 8, 16]), np.log(errors), 1)[0]
    assert order > 2 and errors[-1] < 1e-3, (order, errors)


def test_unconverged_modes_are_reported_and_warned():
    # 36 of a 40-mass chain's modes: the Ritz values of the top kept modes gain a factor (x + √(x² − 1))² ≈ 2 an
    # iteration (x = 2λ_39/λ_36 − 1 ≈ 1.07), too slowly for 30 digits within the iterations allowed
    chain = UnilateralSystem.chain(40, unilateral=[(10, 0)])
    with pytest.warns(UserWarning, match="not converged to 30 digits"):
        reduced = ResidualFlexibility(modes=36).reduce((chain.M_exact, chain.K_exact), A=chain.A_exact)
    assert not reduced.success and "still moving" in reduced.message
