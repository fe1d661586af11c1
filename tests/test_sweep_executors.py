"""nnm_sweep on executors: a thread pool, a process pool and a Dask LocalCluster give the serial results.

Reference: the one-dof unilateral spring u'' + u + ε (u)_+ = 0, whose NNM frequency is the exact bilinear
closed form ω = 2√(1+ε) / (1 + √(1+ε)) (half a period at frequency 1, half at √(1+ε)); the sweep must reproduce
it at every ε whatever runs the points, and report progress once per point.
"""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import pytest

import lindstedt

EPSILONS = [0.05, 0.1, 0.2, 0.4, 0.8]


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
    with ProcessPoolExecutor(2) as pool:
        check(lindstedt.nnm_sweep(system, 1, EPSILONS, modal_amplitude=1.0, executor=pool))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        check(lindstedt.nnm_sweep(system, 1, EPSILONS, modal_amplitude=1.0, executor=client.get_executor()))
