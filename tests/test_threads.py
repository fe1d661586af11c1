"""Threads: a fresh expansion of every engine evaluated by 20 threads at once gives the serial values, bit for bit.

The hierarchies are lazy and shared through the process-wide cache (orders are derived on first use), and
mpmath's working precision is one process-wide setting.  Issue 22 measured both races: 20 threads on a fresh
``Max(0, u - kappa)`` all returned 1.0333181 (serial 1.0338187) and the cache stayed poisoned; ``sin(u)``
was wrong in 7 of 20 rounds.  The expectation here is the serial value of the same call after
``lindstedt.clear_cache()`` (what a single-threaded process computes), and that value is checked against an
independent exact reference where one exists.  A thread switch every microsecond (``sys.setswitchinterval``)
makes the races show in every round (before the fix: every thread of every round wrong).
"""

from __future__ import annotations

import sys
import threading
import warnings

import mpmath
import numpy as np
import pytest

import lindstedt
from lindstedt.references import duffing_exact_frequency, piecewise_linear_exact_frequency

THREADS = 20
ROUNDS = 3
EPSILON = 0.1
TIMES = [0.5, 2.0, 7.0]
KAPPA = {"kappa": -0.36}


@pytest.fixture
def eager_switching():
    """A GIL switch every microsecond (default 5 ms), restored afterwards."""
    previous = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)
    yield
    sys.setswitchinterval(previous)


def _together(task, count=THREADS):
    """``task()`` on ``count`` threads released at once by a barrier; their results in thread order."""
    barrier = threading.Barrier(count)
    results: list = [None] * count
    failures: list = []

    def run(index):
        barrier.wait()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                results[index] = task()
        except BaseException as error:  # noqa: BLE001 — reported below, with the thread's index
            failures.append((index, error))

    threads = [threading.Thread(target=run, args=(index,)) for index in range(count)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=600)  # a hang guard only
    assert not any(thread.is_alive() for thread in threads), "a thread did not finish (deadlock?)"
    assert not failures, failures
    return results


def _bits(values) -> bytes:
    return b"".join(np.asarray(value, dtype=float).tobytes() for value in values)


def _serial(make, evaluate):
    lindstedt.clear_cache()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return evaluate(make())


def _check_threads_agree_with_serial(make, evaluate, rounds=ROUNDS):
    """Every round: a fresh cache; 20 threads share one new expansion, or each expands the problem itself (the
    cached hierarchy is then what they share); afterwards the cache must still give the serial values."""
    serial = _serial(make, evaluate)
    expected = _bits(serial)
    for round_ in range(rounds):
        lindstedt.clear_cache()
        if round_ % 2 == 0:
            shared = make()
            results = _together(lambda: evaluate(shared))
        else:
            results = _together(lambda: evaluate(make()))
        wrong = [index for index, result in enumerate(results) if _bits(result) != expected]
        assert not wrong, f"round {round_}: threads {wrong} differ from the serial {serial}: {results[wrong[0]]}"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            assert _bits(evaluate(make())) == expected, "the cached hierarchy was poisoned"
    return serial


def _one_dof(values=None):
    def evaluate(expansion):
        return (expansion.frequency(EPSILON, values=values), expansion.displacement(TIMES, EPSILON, values=values))

    return evaluate


# --------------------------------------------------------------------------- smooth engine
@pytest.mark.parametrize("f", ["u**3", "sin(u)"])
def test_smooth_hierarchy_on_twenty_threads(eager_switching, f):
    serial = _check_threads_agree_with_serial(lambda: lindstedt.expand(f, order=4, a0=1, omega0=1), _one_dof())
    if f == "u**3":  # independent: the exact Duffing frequency (elliptic integral); order 4 leaves O(ε^5)
        exact = float(duffing_exact_frequency(EPSILON, amplitude=1, precision=30))
        assert abs(serial[0] - exact) < 10 * EPSILON**5


# --------------------------------------------------------------------------- branch engine
def test_branch_hierarchy_with_a_symbolic_gap_on_twenty_threads(eager_switching):
    """The issue's reproducer: ``Max(0, u - kappa)``, kappa symbolic, evaluated at kappa = -0.36."""
    make = lambda: lindstedt.expand("Max(0, u - kappa)", order=3, a0=1, omega0=1, params={"kappa": None})  # noqa: E731
    serial = _check_threads_agree_with_serial(make, _one_dof(KAPPA))
    # independent: the closed-form period of the piecewise-linear orbit; order 3 leaves O(ε^4)
    exact = float(piecewise_linear_exact_frequency(EPSILON, a=1, b="-9/25", a0=1, precision=30))
    assert abs(serial[0] - exact) < 10 * EPSILON**4


def test_branch_hierarchy_with_a_numeric_gap_on_twenty_threads(eager_switching):
    serial = _check_threads_agree_with_serial(lambda: lindstedt.expand("Max(0, u - 1/3)", order=3, a0=1, omega0=1), _one_dof())
    exact = float(piecewise_linear_exact_frequency(EPSILON, a=1, b="1/3", a0=1, precision=30))
    assert abs(serial[0] - exact) < 10 * EPSILON**4


def test_grazing_hierarchy_on_twenty_threads(eager_switching):
    """A breakpoint at the far turning point: the series in ε^{1/2}, shifts learnt one order late."""
    make = lambda: lindstedt.expand("Max(0, u + 1)", order=3, a0=1, omega0=1)  # noqa: E731
    serial = _check_threads_agree_with_serial(make, _one_dof())
    exact = float(piecewise_linear_exact_frequency(EPSILON, a=1, b=-1, a0=1, precision=30))
    assert abs(serial[0] - exact) < 10 * EPSILON**3.5


# --------------------------------------------------------------------------- stretched contact arc (Hertz)
def test_stretched_arc_on_twenty_threads(eager_switching):
    """``Max(0, u)**(3/2)``: the contact arc is solved on a stretched interval (mpmath, refined on demand)."""
    make = lambda: lindstedt.expand("Max(0, u)**(3/2)", order=2, a0=1, omega0=1, numeric=True)  # noqa: E731
    _check_threads_agree_with_serial(make, _one_dof(), rounds=2)


# --------------------------------------------------------------------------- N degrees of freedom
def test_nnm_on_twenty_threads(eager_switching):
    """The NNM of a 3-dof chain with a stop: one shared system (its modal coupling is memoised per precision)."""
    system = lindstedt.UnilateralSystem.chain(3, unilateral=[(0, 0.0)])

    def make():
        return lindstedt.nnm(system, mode=1, a0=1.0, order=2)

    def evaluate(mode):  # ω, its next term (derived on first use) and the waveform of every component
        return (mode.frequency(EPSILON), mode.truncation_error_estimate(EPSILON), mode.displacement(TIMES, EPSILON))

    _check_threads_agree_with_serial(make, evaluate)


# --------------------------------------------------------------------------- mpmath's process-wide precision
def test_a_high_precision_thread_does_not_change_another_threads_result(eager_switching):
    """One thread computes at 300 digits (the Duffing reference) while ten others compute at 40 digits (the
    piecewise-linear reference) and derive ``sin(u)`` (its Taylor coefficients sampled with mpmath): every
    result, at either precision, is the serial one to the last digit, and mpmath's precision is unchanged."""
    make = lambda: lindstedt.expand("sin(u)", order=4, a0=1, omega0=1)  # noqa: E731
    evaluate = _one_dof()

    def low():
        return piecewise_linear_exact_frequency("1/10", a=1, b="1/3", a0=1, precision=40)

    def high():
        return duffing_exact_frequency("1/10", amplitude=1, precision=300)

    expected, expected_low, expected_high = _bits(_serial(make, evaluate)), low(), high()
    precision = mpmath.mp.prec
    stop = threading.Event()
    highs: list = []

    def busy():
        while not stop.is_set():
            highs.append(high())

    worker = threading.Thread(target=busy)
    worker.start()
    try:
        for _ in range(2):
            lindstedt.clear_cache()
            results = _together(lambda: (evaluate(make()), [low() for _ in range(3)]), count=10)
            assert all(_bits(result) == expected for result, _ in results)
            assert all(value == expected_low for _, values in results for value in values)
    finally:
        stop.set()
        worker.join(timeout=600)
    assert highs and all(value == expected_high for value in highs)
    assert mpmath.mp.prec == precision
