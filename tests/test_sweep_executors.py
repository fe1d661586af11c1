"""nnm_sweep on executors: a thread pool, a process pool and a Dask LocalCluster give the serial results.

Reference: the one-dof unilateral spring u'' + u + ε (u)_+ = 0, whose NNM frequency is the exact bilinear
closed form ω = 2√(1+ε) / (1 + √(1+ε)) (half a period at frequency 1, half at √(1+ε)); the sweep must reproduce
it at every ε whatever runs the points, and report progress once per point.
"""

from __future__ import annotations

import multiprocessing
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import pytest

import lindstedt

EPSILONS = [0.05, 0.1, 0.2, 0.4, 0.8]
#: fresh worker processes: forking a process that has loaded a multithreaded library (JAX, by other tests) can deadlock
SPAWN = multiprocessing.get_context("spawn")


def bilinear_frequency(epsilon: float) -> float:
    stiff = (1 + epsilon) ** 0.5
    return 2 * stiff / (1 + stiff)


def check(results) -> None:
    assert [r.success for r in results] == [True] * len(EPSILONS)
    for result, epsilon in zip(results, EPSILONS):
        assert result.frequency == pytest.approx(bilinear_frequency(epsilon), rel=1e-12)


@pytest.fixture(scope="module")
def system():
    return lindstedt.UnilateralSystem.one_dof(1)


def test_serial_sweep_and_progress_callback(system):
    seen = []
    results = lindstedt.nnm_sweep(system, 1, EPSILONS, modal_amplitude=1.0,
                                  progress=lambda index, value, result: seen.append((index, value, result.success)))
    check(results)
    assert seen == [(index, value, True) for index, value in enumerate(EPSILONS)]


def test_thread_pool_reports_every_point_once(system):
    seen = []
    with ThreadPoolExecutor(2) as pool:
        results = lindstedt.nnm_sweep(system, 1, EPSILONS, modal_amplitude=1.0, executor=pool,
                                      progress=lambda index, value, result: seen.append(index))
    check(results)
    assert sorted(seen) == list(range(len(EPSILONS)))


def test_progress_bar_counts_the_points(system, capsys):
    pytest.importorskip("tqdm", reason="the progress bar is optional: pip install 'lindstedt[dask]' (or tqdm)")
    results = lindstedt.nnm_sweep(system, 1, EPSILONS, modal_amplitude=1.0, progress=True)
    check(results)
    assert f"{len(EPSILONS)}/{len(EPSILONS)}" in capsys.readouterr().err


def test_dask_local_cluster(system):
    distributed = pytest.importorskip("distributed", reason="Dask is optional: pip install 'lindstedt[dask]'")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        results = lindstedt.nnm_sweep(system, 1, EPSILONS, modal_amplitude=1.0, executor=client.get_executor())
    check(results)


@pytest.mark.slow
def test_process_pools_pickle_the_task(system):
    # worker processes receive the system and options by pickling: a process pool and a Dask cluster of processes
    distributed = pytest.importorskip("distributed", reason="Dask is optional: pip install 'lindstedt[dask]'")
    with ProcessPoolExecutor(2, mp_context=SPAWN) as pool:
        check(lindstedt.nnm_sweep(system, 1, EPSILONS, modal_amplitude=1.0, executor=pool))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        check(lindstedt.nnm_sweep(system, 1, EPSILONS, modal_amplitude=1.0, executor=client.get_executor()))


# --------------------------------------------------------------------------- backbone on an amplitude grid
AMPLITUDES = [0.5, 1.0, 1.5]


def check_duffing_backbone(curve, epsilon: float = 0.1) -> None:
    """Against the complete-elliptic-integral frequency of u'' + u + ε u³ = 0 (an independent exact reference)."""
    from lindstedt.references import duffing_exact_frequency

    assert curve.success and curve.orders == (1, 2, 3)
    exact = [float(duffing_exact_frequency(epsilon, amplitude=a, precision=30)) for a in AMPLITUDES]
    assert curve.exact_frequencies == pytest.approx(exact, rel=1e-15)
    assert all(estimate < 1e-18 for estimate in curve.exact_error_estimates)
    errors = curve.errors
    assert (errors[2] < errors[1]).all() and (errors[1] < errors[0]).all()  # each order closer to the exact backbone
    # the truncated series at order 1 is 1 + 3ε a0²/8 (textbook)
    assert curve.series_frequencies[0] == pytest.approx([1 + 3 * epsilon * a * a / 8 for a in AMPLITUDES], rel=1e-15)


def test_backbone_serial_and_on_executors_agree_with_the_elliptic_reference():
    from lindstedt.validate import backbone

    serial = backbone("u**3", AMPLITUDES, 0.1, order=3)
    check_duffing_backbone(serial)
    seen = []
    with ThreadPoolExecutor(2) as pool:
        threaded = backbone("u**3", AMPLITUDES, 0.1, order=3, executor=pool, progress=lambda i, a, outcome: seen.append(i))
    check_duffing_backbone(threaded)
    assert sorted(seen) == [0, 1, 2]
    assert (threaded.series_frequencies == serial.series_frequencies).all()


def test_backbone_of_the_bilinear_spring_is_flat_at_the_closed_form():
    from lindstedt.validate import backbone

    curve = backbone("Max(0, u)", AMPLITUDES, 0.4, order=2)
    assert curve.exact_frequencies == pytest.approx([bilinear_frequency(0.4)] * 3, rel=1e-15)


def test_backbone_bad_input_names_the_fix():
    from lindstedt.validate import backbone

    with pytest.raises(lindstedt.ProblemError, match="positive finite release amplitudes"):
        backbone("u**3", [0.0, 1.0], 0.1)
    with pytest.raises(lindstedt.ProblemError, match="epsilon"):
        backbone("u**3", [1.0], -0.1)
    with pytest.raises(lindstedt.ProblemError, match="order"):
        backbone("u**3", [1.0], 0.1, order=0)


def test_backbone_on_a_dask_cluster_of_processes():
    # the amplitude task is pickled to worker processes
    distributed = pytest.importorskip("distributed", reason="Dask is optional: pip install 'lindstedt[dask]'")
    from lindstedt.validate import backbone

    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        check_duffing_backbone(backbone("u**3", AMPLITUDES, 0.1, order=3, executor=client.get_executor()))


def test_backbone_table():
    pytest.importorskip("pandas", reason="tables are optional: pip install 'lindstedt[pandas]'")
    from lindstedt.validate import backbone

    table = backbone("u**3", AMPLITUDES, 0.1, order=3).to_dataframe()
    assert list(table["a0"]) == AMPLITUDES and len(table.columns) == 6


def test_fitted_orders_on_a_process_pool_equal_the_serial_fits():
    # the per-ε reference solves are independent tasks; a pool must give the same numbers and counters
    from lindstedt.validate import fitted_convergence_order, fitted_validity_exponent

    expansion = lindstedt.expand("Max(0, u - 1/3)", order=1, a0=1, omega0=1)
    serial = fitted_convergence_order(expansion, [0.04, 0.02, 0.01])
    seen = []
    with ProcessPoolExecutor(2, mp_context=SPAWN) as pool:
        pooled = fitted_convergence_order(expansion, [0.04, 0.02, 0.01], executor=pool, progress=lambda i, w, r: seen.append(i))
        grazing = lindstedt.expand("Max(0, u - 1)", order=1, a0=1, omega0=1)
        validity_serial = fitted_validity_exponent(grazing, [0.02, 0.01, 0.005], a1=1.0)
        validity_pooled = fitted_validity_exponent(grazing, [0.02, 0.01, 0.005], a1=1.0, executor=pool)
    assert sorted(seen) == [0, 1, 2]
    assert serial.success and pooled.success and abs(serial.slope - 2) < 0.15  # order 1: slope N + 1 = 2
    assert (pooled.max_errors == serial.max_errors).all() and pooled.n_reference_solves == serial.n_reference_solves == 3
    assert validity_serial.success and abs(validity_serial.exponent + 0.5) < 0.15  # grazing: T ~ ε^(-1/2)
    assert (validity_pooled.validity_times == validity_serial.validity_times).all()
    assert validity_pooled.n_reference_solves == validity_serial.n_reference_solves


def test_backbone_in_the_sqrt_eps_gauge_of_grazing():
    # a0 = 1 with f = (u + 1)_+: the far turning point touches the breakpoint (ω(ε) in powers of √ε); the series of
    # each order approaches the quadrature reference
    from lindstedt.validate import backbone

    curve = backbone("Max(0, u + 1)", [1.0], 0.01, order=2)
    assert curve.success, curve.message
    errors = curve.errors[:, 0]
    assert errors[1] < errors[0] < 1e-2
