"""Structural models (issue 25, item 4): FE matrices read from files, the Euler–Bernoulli beam with breathing
cracks, and the lowest modes of sparse models.

References, all independent of the code under test:

* the exact Euler–Bernoulli frequencies ``ω = β² √(EI/ρA)``: cantilever ``β_n L`` = 1.875104068711961,
  4.694091132974175, 7.854757438237613 (roots of ``cos x cosh x = −1``); simply supported ``β_n L = nπ``;
  clamped–pinned: the roots of ``tan x = tanh x``;
* the exact cracked cantilever (rotational spring ``k_c`` at ``x = c``): the 8×8 determinant of the two
  segments' general solutions ``a cos βx + b sin βx + c cosh βx + d sinh βx`` with the clamp, the free end and
  the crack's conditions (``w``, ``EI w''``, ``EI w'''`` continuous, ``EI w''(c) = k_c (w'(c⁺) − w'(c⁻))``);
* the clamped–clamped beam with a hinge at midspan (``k_c = 0``), derived exactly: its symmetric modes have
  zero moment (hinge) and zero shear (symmetry) at midspan, so each half is a cantilever of length L/2; its
  antisymmetric modes have ``w = 0`` and zero moment there, so each half is clamped–pinned of length L/2;
* the textbook cubic-Hermite element matrices, written here; the mode check against a dense mpmath
  eigen-decomposition at 30 digits of the same exact matrices.

The FE frequencies converge like h⁴ (Rayleigh–Ritz, from above): the order is fitted over n = 8 … 32 elements,
where the float eigensolver's own error (measured ≲ 1e-11 relative there) is far below the discretisation
error; at n = 64 the shift-invert solver's floor (≈ 2e-10 relative on the cantilever) starts to show.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.io
import scipy.optimize
import scipy.sparse
import sympy

from lindstedt import EulerBernoulliBeam, ProblemError, UnilateralSystem, read_matrices, sparse_modes

CANTILEVER = np.array([1.875104068711961, 4.694091132974175, 7.854757438237613])
MESHES = (8, 12, 16, 24, 32)
ORDER_TOLERANCE = 0.1  # measured slopes 3.96 … 4.00 over MESHES (pre-asymptotic curvature of the third mode)


def _leading_error(beta, n: int) -> np.ndarray:
    """The leading relative frequency error of cubic Hermite elements with consistent mass, (βh)⁴/1440."""
    return (np.asarray(beta) / n) ** 4 / 1440


def _roots(function, count: int, start: float = 0.5, stop: float = 30.0, step: float = 0.01) -> np.ndarray:
    grid = np.arange(start, stop, step)
    values = np.array([function(x) for x in grid])
    roots = [scipy.optimize.brentq(function, grid[i], grid[i + 1], xtol=1e-15)
             for i in np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))]
    assert len(roots) >= count
    return np.array(roots[:count])


def _clamped_pinned(count: int) -> np.ndarray:
    return _roots(lambda x: np.sin(x) * np.cosh(x) - np.cos(x) * np.sinh(x), count, start=1.0)


def _basis(beta: float, x: float, derivative: int) -> np.ndarray:
    """The ``derivative``-th derivative of (cos βx, sin βx, cosh βx, sinh βx)."""
    c, s, ch, sh = np.cos(beta * x), np.sin(beta * x), np.cosh(beta * x), np.sinh(beta * x)
    rows = [(c, s, ch, sh), (-s, c, sh, ch), (-c, -s, ch, sh), (s, -c, sh, ch)]
    return beta**derivative * np.array(rows[derivative])


def _cracked_cantilever(c: float, kappa: float, count: int) -> np.ndarray:
    """β_n of the unit cantilever (EI = L = 1) with a rotational spring kappa at x = c: exact, by determinant."""
    def determinant(beta: float) -> float:
        zero, right = np.zeros(4), 1 - c
        rows = [
            np.r_[_basis(beta, 0, 0), zero], np.r_[_basis(beta, 0, 1), zero],                        # clamped
            np.r_[_basis(beta, c, 0), -_basis(beta, 0, 0)],                                            # w
            np.r_[_basis(beta, c, 2), -_basis(beta, 0, 2)],                                            # moment
            np.r_[_basis(beta, c, 3), -_basis(beta, 0, 3)],                                            # shear
            np.r_[_basis(beta, c, 2) + kappa * _basis(beta, c, 1), -kappa * _basis(beta, 0, 1)],      # spring
            np.r_[zero, _basis(beta, right, 2)], np.r_[zero, _basis(beta, right, 3)],                  # free
        ]
        return float(np.linalg.det(np.array(rows)) / beta**16)
    return _roots(determinant, count)


def _fitted_order(meshes, errors) -> float:
    return -np.polyfit(np.log(meshes), np.log(errors), 1)[0]


# --------------------------------------------------------------------------- the FE beam
@pytest.mark.parametrize("left, right, exact", [
    ("clamped", "free", CANTILEVER),
    ("pinned", "pinned", np.pi * np.arange(1, 4)),
    ("clamped", "pinned", None),
])
def test_beam_frequencies_converge_to_euler_bernoulli_at_order_four(left, right, exact):
    beta = _clamped_pinned(3) if exact is None else exact
    errors = np.array([EulerBernoulliBeam(n, left=left, right=right).modes(3).frequencies / beta**2 - 1 for n in MESHES])
    assert np.all(errors > 0)  # Rayleigh–Ritz: from above
    for k in range(3):
        assert abs(_fitted_order(MESHES, errors[:, k]) - 4) < ORDER_TOLERANCE
    np.testing.assert_allclose(errors[-1], _leading_error(beta, MESHES[-1]), rtol=0.03)


def test_beam_properties_scale_the_frequencies_exactly_as_beta_squared_root_ei_over_rho_a():
    beam = EulerBernoulliBeam(32, length=2, E=210e9, I="1/12e6", rho=7850, area="1/100")
    scale = np.sqrt(210e9 / 12e6 / (7850 / 100)) / 2**2
    errors = beam.modes(3).frequencies / (CANTILEVER**2 * scale) - 1
    np.testing.assert_allclose(errors, _leading_error(CANTILEVER, 32), rtol=0.03)


def test_element_matrices_are_the_textbook_cubic_hermite_ones_exactly():
    # one element, h = 2, EI = 2/3, ρA = 3/2, clamped at 0: the free node keeps (w1, θ1);
    # EI/h³ [[12, −6h], [−6h, 4h²]] = [[1, −1], [−1, 4/3]] and ρA h/420 [[156, −22h], [−22h, 4h²]]
    system = EulerBernoulliBeam(1, length=2, E=2, I="1/3", rho=3, area="1/2").system()
    assert system.K_exact.tolist() == [[1, -1], [-1, sympy.Rational(4, 3)]]
    assert system.M_exact.tolist() == [[sympy.Rational(39, 35), -sympy.Rational(11, 35)],
                                       [-sympy.Rational(11, 35), sympy.Rational(4, 35)]]


def test_dof_numbering_and_the_unilateral_spring_on_the_relative_rotation():
    beam = EulerBernoulliBeam(4, left="pinned", right="clamped", cracks=[(1, 5, -1, "1/10"), (3, 0)])
    assert beam.dofs == ("theta0", "w1", "theta1-", "theta1+", "w2", "theta2", "w3", "theta3-", "theta3+")
    system = beam.system()
    assert system.symmetric_coupling and system.n_springs == 2
    X = np.zeros(beam.n_dof)
    X[beam.index("theta1+")], X[beam.index("theta1-")] = 0.25, 0.5   # direction −1: engaged while θ⁻ − θ⁺ > 1/10
    X[beam.index("theta3+")] = 0.5
    assert system.gaps(X).tolist() == [0.25 - 0.1, 0.5]
    minus, plus = beam.index("theta1-"), beam.index("theta1+")
    assert system.K_exact[minus, plus] == -5                  # the spring k_c = 5 between θ⁻ and θ⁺ only
    assert system.K_exact[plus, plus] == 5 + 16               # k_c + 4 EI/h, h = 1/4
    assert np.array_equal(beam.K.toarray(), system.K) and np.array_equal(beam.M.toarray(), system.M)
    assert np.array_equal(beam.A.toarray(), system.A) and beam.b.tolist() == [0.1, 0.0]


def test_a_stiff_crack_gives_the_intact_cantilever():
    # k_c → ∞: the exact cracked cantilever tends to the intact one like 1/k_c, and so do the FE frequencies, each
    # within the FE error (βh)⁴/1440 of its exact reference (float noise ~1e-10 at k_c = 1e6 on n = 32)
    stiffnesses = np.array([1e2, 1e4, 1e6])
    intact = EulerBernoulliBeam(32).modes(3).frequencies
    shifts, fe_shifts = [], []
    for stiffness in stiffnesses:
        beta = _cracked_cantilever(0.25, stiffness, 3)
        frequencies = EulerBernoulliBeam(32, cracks=[(8, stiffness)]).modes(3).frequencies
        np.testing.assert_allclose(frequencies / beta**2 - 1, _leading_error(beta, 32), rtol=0.03)
        shifts.append(1 - beta**2 / CANTILEVER**2)
        fe_shifts.append(1 - frequencies / intact)
    shifts, fe_shifts = np.array(shifts), np.array(fe_shifts)
    assert np.all(shifts > 0)
    for k in range(3):
        assert abs(np.polyfit(np.log(stiffnesses), np.log(shifts[:, k]), 1)[0] + 1) < 0.01
    np.testing.assert_allclose(fe_shifts, shifts, rtol=0.01, atol=3e-10)


def test_a_finite_crack_matches_the_exact_cracked_cantilever_at_order_four():
    beta = _cracked_cantilever(0.25, 2.0, 3)
    assert np.all(beta < CANTILEVER)  # the crack softens every mode
    errors = np.array([EulerBernoulliBeam(n, cracks=[(n // 4, 2)]).modes(3).frequencies / beta**2 - 1 for n in MESHES])
    assert np.all(errors > 0)
    np.testing.assert_allclose(errors[-1], _leading_error(beta, MESHES[-1]), rtol=0.03)
    for k in range(3):
        assert abs(_fitted_order(MESHES, errors[:, k]) - 4) < ORDER_TOLERANCE


def test_a_zero_crack_at_midspan_of_a_clamped_beam_is_the_hinged_beam():
    # the halves: cantilevers of length 1/2 (symmetric modes) and clamped–pinned ones (antisymmetric), β = 2 x
    exact = np.sort(np.r_[2 * CANTILEVER[:2], 2 * _clamped_pinned(2)])
    errors = np.array([EulerBernoulliBeam(n, left="clamped", right="clamped", cracks=[(n // 2, 0)]).modes(4).frequencies
                       / exact**2 - 1 for n in MESHES])
    assert np.all(errors > 0)
    np.testing.assert_allclose(errors[-1], _leading_error(exact, MESHES[-1]), rtol=0.03)
    for k in range(4):
        assert abs(_fitted_order(MESHES, errors[:, k]) - 4) < ORDER_TOLERANCE


@pytest.mark.parametrize("kwargs, fix", [
    (dict(left="free", right="free"), "clamp or pin an end"),
    (dict(left="pinned", right="free"), "1 rigid-body motion"),
    (dict(left="pinned", right="pinned", cracks=[(2, 0)]), "positive k_c"),
    (dict(cracks=[(0, 1)]), "interior node"),
    (dict(cracks=[(1, -1)]), "k_c must be ≥ 0"),
    (dict(cracks=[(1, 1), (1, 2)]), "one crack per node"),
    (dict(cracks=[(1, 1, 2)]), r"direction must be \+1 or -1"),
    (dict(left="fixed"), "one of"),
    (dict(E=0), "E must be positive"),
])
def test_bad_beams_are_refused_naming_the_fix(kwargs, fix):
    with pytest.raises(ProblemError, match=fix):
        EulerBernoulliBeam(4, **kwargs)


# --------------------------------------------------------------------------- modes of sparse models
def test_sparse_modes_equal_the_dense_modes_of_a_chain():
    chain = UnilateralSystem.chain(50)
    sparse = sparse_modes(scipy.sparse.csr_matrix(chain.M), scipy.sparse.csr_matrix(chain.K), 6)
    dense = chain.modes()
    exact = 2 * np.sin(np.arange(1, 7) * np.pi / 102)   # the chain's closed form 2 sin(kπ/(2(N+1)))
    np.testing.assert_allclose(sparse.frequencies, dense.frequencies[:6], rtol=1e-10, atol=0)
    np.testing.assert_allclose(sparse.frequencies, exact, rtol=1e-12, atol=0)
    signs = np.sign(np.sum(sparse.shapes * dense.shapes[:, :6], axis=0))
    np.testing.assert_allclose(sparse.shapes * signs, dense.shapes[:, :6], rtol=0, atol=1e-10)
    np.testing.assert_allclose(sparse.shapes.T @ chain.M @ sparse.shapes, np.eye(6), rtol=0, atol=1e-13)


def test_sparse_modes_of_a_cracked_beam_against_a_30_digit_decomposition():
    mpmath = pytest.importorskip("mpmath")
    beam = EulerBernoulliBeam(12, left="clamped", right="clamped", cracks=[(6, 3)])   # N = 23
    system = beam.system()
    with mpmath.workdps(30):
        def exact(matrix):
            return mpmath.matrix([[mpmath.mpf(v.p) / v.q for v in row] for row in matrix.tolist()])
        inverse = mpmath.inverse(mpmath.cholesky(exact(system.M_exact)))
        values, vectors = mpmath.eigsy(inverse * exact(system.K_exact) * inverse.T)
        shapes = inverse.T * vectors
        order = sorted(range(beam.n_dof), key=lambda i: values[i])
        reference = np.array([float(mpmath.sqrt(values[i])) for i in order])
        reference_shapes = np.array([[float(shapes[r, i]) for i in order] for r in range(beam.n_dof)])
    modes = beam.modes(5)
    np.testing.assert_allclose(modes.frequencies, reference[:5], rtol=1e-10, atol=0)
    signs = np.sign(np.sum(modes.shapes * reference_shapes[:, :5], axis=0))
    scale = np.abs(reference_shapes[:, :5]).max(axis=0)
    np.testing.assert_allclose(modes.shapes * signs / scale, reference_shapes[:, :5] / scale, rtol=0, atol=1e-9)
    np.testing.assert_allclose(modes.shapes.T @ system.M @ modes.shapes, np.eye(5), rtol=0, atol=1e-12)
    # the dense LAPACK modes of the same model, within their own float error (measured ~3e-10 for N = 50)
    np.testing.assert_allclose(system.modes().frequencies[:5], reference[:5], rtol=2e-9, atol=0)


def test_sparse_modes_with_a_shift_return_the_modes_nearest_it():
    beam = EulerBernoulliBeam(16, left="pinned", right="pinned")
    lowest = beam.modes(6).frequencies
    shifted = beam.modes(2, sigma=float((lowest[3] ** 2 + lowest[4] ** 2) / 2)).frequencies
    np.testing.assert_allclose(shifted, lowest[3:5], rtol=1e-12)


@pytest.mark.parametrize("count, sigma, fix", [(24, 0.0, "count must be an integer in 1..23"),
                                               (0, 0.0, "count must be"), (2, float("nan"), "sigma must be")])
def test_sparse_modes_refuse_bad_requests(count, sigma, fix):
    beam = EulerBernoulliBeam(12)
    with pytest.raises(ProblemError, match=fix):
        sparse_modes(beam.M, beam.K, count, sigma=sigma)


def test_sparse_modes_name_a_mechanism():
    K = scipy.sparse.csr_matrix(np.array([[1.0, -1.0, 0.0], [-1.0, 1.0, 0.0], [0.0, 0.0, 1.0]]))  # free pair
    with pytest.raises(ProblemError, match="mechanism"):
        sparse_modes(scipy.sparse.identity(3), K, 1)


# --------------------------------------------------------------------------- readers
@pytest.fixture()
def model():
    beam = EulerBernoulliBeam(6, left="pinned", right="pinned", cracks=[(3, 0.7)])
    rng = np.random.default_rng(25)
    C = rng.standard_normal((beam.n_dof, beam.n_dof))
    return {"M": beam.M, "K": beam.K, "C": scipy.sparse.csr_matrix(C + C.T)}


def _same(read, written):
    assert type(read) is (scipy.sparse.csr_matrix if scipy.sparse.issparse(written) else np.ndarray)
    left = read.toarray() if scipy.sparse.issparse(read) else read
    right = written.toarray() if scipy.sparse.issparse(written) else written
    assert left.dtype == np.float64 and np.array_equal(left, right)   # exact equality, bit for bit


@pytest.mark.parametrize("sparse", [False, True])
def test_round_trips_of_npz_mat_and_mtx_are_exact(tmp_path, model, sparse):
    matrices = {key: (value if sparse else value.toarray()) for key, value in model.items()}
    names = ("M", "K", "C")
    if not sparse:
        np.savez(tmp_path / "model.npz", **matrices)
        for key, value in read_matrices(tmp_path / "model.npz", names).items():
            _same(value, matrices[key])
    scipy.io.savemat(tmp_path / "model.mat", matrices)
    for key, value in read_matrices(str(tmp_path / "model.mat"), names).items():
        _same(value, matrices[key])
    files = {}
    for key, value in matrices.items():
        scipy.io.mmwrite(tmp_path / f"{key}.mtx", value)
        files[key] = tmp_path / f"{key}.mtx"
    for key, value in read_matrices(files, names).items():
        _same(value, matrices[key])
    for key, value in matrices.items():
        if sparse:
            scipy.sparse.save_npz(tmp_path / f"{key}.npz", value)
            files[key] = tmp_path / f"{key}.npz"
        else:
            np.save(tmp_path / f"{key}.npy", value)
            files[key] = tmp_path / f"{key}.npy"
    for key, value in read_matrices(files, names).items():
        _same(value, matrices[key])


def test_read_matrices_feed_a_unilateral_system(tmp_path, model):
    scipy.io.mmwrite(tmp_path / "M.mtx", model["M"])
    scipy.io.mmwrite(tmp_path / "K.mtx", model["K"])
    matrices = read_matrices({"M": tmp_path / "M.mtx", "K": tmp_path / "K.mtx"})
    lam = sparse_modes(matrices["M"], matrices["K"], 2).frequencies
    system = UnilateralSystem(M=matrices["M"].toarray(), K=matrices["K"].toarray())
    np.testing.assert_allclose(lam, system.modes().frequencies[:2], rtol=1e-10)


def test_a_large_sparse_model_is_read_and_checked_by_its_sparse_factorisation(tmp_path):
    beam = EulerBernoulliBeam(1100, cracks=[(550, 1)])   # N = 2201: M checked by the signs of its sparse LDLᵀ
    scipy.sparse.save_npz(tmp_path / "M.npz", beam.M)
    scipy.sparse.save_npz(tmp_path / "K.npz", beam.K)
    matrices = read_matrices({"M": tmp_path / "M.npz", "K": tmp_path / "K.npz"})
    _same(matrices["M"], beam.M)
    _same(matrices["K"], beam.K)
    assert beam == EulerBernoulliBeam(1100, cracks=[(550, "1")]) != EulerBernoulliBeam(1100, cracks=[(550, 2)])


def _indefinite(n: int) -> scipy.sparse.csr_matrix:
    """Positive diagonal, one 2×2 block [[1, 2], [2, 1]] (eigenvalue −1) in the middle."""
    M = scipy.sparse.lil_matrix(scipy.sparse.identity(n))
    M[n // 2, n // 2 + 1] = M[n // 2 + 1, n // 2] = 2.0
    return M.tocsr()


def _write_npz(path, **arrays):
    np.savez(path, **arrays)
    return path


@pytest.mark.parametrize("case, fix", [
    ("missing", r"lacks \['K'\].*numpy.savez\(path, M=M, K=K\)"),
    ("non-square", "non-empty square"),
    ("sizes", "every matrix of one model has one row per degree of freedom"),
    ("non-symmetric", r"not symmetric.*\(K \+ K.T\)/2"),
    ("indefinite", "must be positive definite.*Cholesky"),
    ("indefinite-sparse", "must be positive definite.*(indefinite|not positive)"),
    ("zero-mass", "carries mass.*diagonal entry 1 is 0"),
    ("nan", "non-finite"),
    ("complex", "complex"),
    ("pickle", "cannot read.*numpy.savez"),
    ("garbage-npz", "cannot read.*numpy.savez"),
    ("garbage-mat", "cannot read.*-v7"),
    ("garbage-mtx", "cannot read.*mmwrite"),
    ("suffix", "has the suffix '.txt'"),
    ("missing-file", "check the path"),
    ("directory", "not a regular file"),
    ("too-large", "pass max_bytes="),
])
def test_bad_files_are_refused_naming_the_fix(tmp_path, case, fix):
    eye, K = np.eye(3), np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 2.0]])
    path, kwargs = tmp_path / "model.npz", {}
    if case == "missing":
        _write_npz(path, M=eye)
    elif case == "non-square":
        _write_npz(path, M=eye, K=np.ones((3, 2)))
    elif case == "sizes":
        _write_npz(path, M=eye, K=np.eye(4))
    elif case == "non-symmetric":
        _write_npz(path, M=eye, K=K + np.triu(np.full((3, 3), 1e-9), 1))
    elif case == "indefinite":
        _write_npz(path, M=_indefinite(3).toarray(), K=K)
    elif case == "indefinite-sparse":
        path = tmp_path / "model.mat"
        scipy.io.savemat(path, {"M": _indefinite(3000), "K": scipy.sparse.identity(3000, format="csr")})
    elif case == "zero-mass":
        _write_npz(path, M=np.diag([1.0, 0.0, 1.0]), K=K)
    elif case == "nan":
        _write_npz(path, M=eye, K=np.full((3, 3), np.nan))
    elif case == "complex":
        _write_npz(path, M=eye, K=K * 1j)
    elif case == "pickle":
        _write_npz(path, M=eye, K=np.array([object()] * 9, dtype=object).reshape(3, 3))
    elif case.startswith("garbage"):
        path = tmp_path / ("model." + case.split("-")[1])
        path.write_bytes(b"%%MatrixMarket nonsense\n\x00\x01" * 8 if case == "garbage-mtx" else b"\x00not a matrix" * 50)
        kwargs = {"source": {"M": path, "K": path}} if case == "garbage-mtx" else {}
    elif case == "suffix":
        path = tmp_path / "model.txt"
        path.write_text("1 0\n0 1\n")
    elif case == "missing-file":
        path = tmp_path / "absent.npz"
    elif case == "directory":
        path = tmp_path / "folder.npz"
        path.mkdir()
    elif case == "too-large":
        _write_npz(path, M=np.eye(50), K=np.eye(50))
        kwargs = {"max_bytes": 1000}
    source = kwargs.pop("source", path)
    with pytest.raises(ProblemError, match=fix):
        read_matrices(source, **kwargs)


def test_a_compressed_file_is_bounded_by_what_it_expands_to(tmp_path):
    np.savez_compressed(tmp_path / "zeros.npz", M=np.eye(1000), K=np.eye(1000))   # 16 MB inflated, a few kB on disk
    assert (tmp_path / "zeros.npz").stat().st_size < 100_000
    with pytest.raises(ProblemError, match="expands to .* bytes, more than the limit 1000000"):
        read_matrices(tmp_path / "zeros.npz", max_bytes=1_000_000)


def test_read_matrices_refuses_bad_arguments(tmp_path):
    with pytest.raises(ProblemError, match="names must be"):
        read_matrices(tmp_path / "x.npz", names="MK")
    with pytest.raises(ProblemError, match="not among the names"):
        read_matrices({"M": tmp_path / "M.mtx", "Q": tmp_path / "Q.mtx"})
    with pytest.raises(ProblemError, match="no file is given for K"):
        read_matrices({"M": tmp_path / "M.mtx"})


@pytest.mark.parametrize("elements", [pytest.param(112, marks=pytest.mark.slow), pytest.param(400, marks=pytest.mark.slow)])
# 225 and 801 dof (3 s and 25 s), the crack at L/4
def test_the_nnm_of_a_fine_cracked_beam_starts_from_the_continuous_beams_frequency(elements):
    """Past ~200 dof the modal refinement refused beams (θ_max grows like n⁴) and, at 801 dof, a mode within 4e-4 of
    its harmonic 1.6e6 was called an internal resonance: the order-2 NNM of the first mode now runs, and its ω₀ is
    the continuous cracked cantilever's λ₁ = β₁² (exact determinant) to the FE error (βh)⁴/1440."""
    import lindstedt

    beta = _cracked_cantilever(0.25, 10.0, 1)[0]
    expansion = lindstedt.nnm(EulerBernoulliBeam(elements, cracks=[(elements // 4, 10)]).system(), 1, a0=1, order=2)
    error = float(expansion.omega[0]) / beta**2 - 1
    assert 0 < error < 2 * _leading_error(beta, elements) + 1e-13  # the FE error from above, plus the root's 1e-15
    assert len(expansion.omega) == 3 and all(np.isfinite(float(w)) for w in expansion.omega)
