"""Threads: a fresh expansion of every engine evaluated by 20 threads at once gives the serial values, bit for bit.

The hierarchies are lazy and shared through the process-wide cache (orders are derived on first use), and
mpmath's working precision is one process-wide setting.  Issue 22 measured both races: 20 threads on a fresh
``Max(0, u - kappa)`` all returned 1.0333181 (serial 1.0338187) and the cache stayed poisoned; ``sin(u)``
was wrong in 7 of 20 rounds.  The expectation here is the serial value of the same call after
``lindstedt.clear_cache()`` (what a single-threaded process computes), and that value is checked against an
independent exact reference where one exists.  A thread switch every microsecond (``sys.setswitchinterval``)
makes the races show in every round (before the fix: every thread of every round wrong).

sympy changes mpmath's precision too (its evaluation of acos(1/3) and the like runs in ``mpmath.workprec``), so every
public call doing sympy or mpmath work holds the package's lock: an instrument records every precision change and
every sympy evaluation made without it over a representative set of public calls (before: 1706 changes and 3658
evaluations from 19 public calls; now none), and a thread exporting sympy-heavy results beside threads doing locked
mpmath work leaves their results bit-identical to the serial ones (before: a 40-digit reference wrong in the 18th digit).
"""

from __future__ import annotations

import contextlib
import sys
import threading
import warnings

import mpmath
import numpy as np
import pytest

import lindstedt
from lindstedt.references import duffing_exact_frequency, piecewise_linear_exact_frequency


@contextlib.contextmanager
def _looping_beside(task, outputs: list):
    """Run ``task`` over and over on a background thread (its results appended to ``outputs``) while the block runs."""
    stop = threading.Event()

    def loop():
        while not stop.is_set():
            outputs.append(task())

    worker = threading.Thread(target=loop)
    worker.start()
    try:
        yield
    finally:
        stop.set()
        worker.join(timeout=600)

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
    highs: list = []
    with _looping_beside(high, highs):
        for _ in range(2):
            lindstedt.clear_cache()
            results = _together(lambda: (evaluate(make()), [low() for _ in range(3)]), count=10)
            assert all(_bits(result) == expected for result, _ in results)
            assert all(value == expected_low for _, values in results for value in values)
    assert highs and all(value == expected_high for value in highs)
    assert mpmath.mp.prec == precision


# --------------------------------------------------------------------------- sympy's own precision changes
# sympy evaluates numbers such as acos(1/3) — in float(), is_positive, comparisons, printing (which orders terms by
# value), collect — inside ``mpmath.workprec(prec)``: it sets mpmath's process-wide precision, down to ~10 bits.  A
# public call that does so without the package's lock can make another thread's locked mpmath block compute at
# the wrong precision, or leave the precision changed.  The instrument below tells a locked change from an unlocked
# one by the package's lock, ``lindstedt.precision_lock()``.
import sympy  # noqa: E402
from mpmath.ctx_mp_python import PythonMPContext  # noqa: E402

from lindstedt import references, validate  # noqa: E402


def _entry_frames(stack) -> str:
    """The outermost and the innermost frame of the package in a stack: the public call and the site."""
    frames = [frame for frame in stack if "/lindstedt/" in frame.filename]
    if not frames:
        return "outside the package"
    outer, inner = frames[0], frames[-1]
    return f"{outer.name} ({outer.filename.rsplit('/lindstedt/', 1)[1]}:{outer.lineno}) → {inner.name} ({inner.lineno})"


@pytest.fixture
def unlocked_changes():
    """Records every assignment to mpmath.mp's ``prec`` or ``dps`` and every numerical evaluation by sympy (the
    gate through which sympy reaches mpmath: ``sympy.core.evalf.evalf``) made by a thread that does not hold the
    package's lock; yields ``{"precision": [...], "evalf": [...]}`` (each entry names the public call and the site)."""
    import traceback

    import sympy.core.evalf as evalf_module

    lock = lindstedt.precision_lock()
    records: dict[str, list[str]] = {"precision": [], "evalf": []}
    originals = {name: PythonMPContext.__dict__[name] for name in ("prec", "dps")}
    evalf = evalf_module.evalf

    def recording(original):
        def setter(context, value):
            if context is mpmath.mp and not lock._is_owned():
                records["precision"].append(f"{value} by {_entry_frames(traceback.extract_stack()[:-1])}")
            original.fset(context, value)

        return property(original.fget, setter)

    def recording_evalf(expression, precision, options):
        if not lock._is_owned():
            records["evalf"].append(_entry_frames(traceback.extract_stack()[:-1]))
        return evalf(expression, precision, options)

    for name, original in originals.items():
        setattr(PythonMPContext, name, recording(original))
    evalf_module.evalf = recording_evalf
    try:
        yield records
    finally:
        evalf_module.evalf = evalf
        for name, original in originals.items():
            setattr(PythonMPContext, name, original)


def _summary(records: list[str]) -> str:
    counts: dict[str, int] = {}
    for record in records:
        counts[record] = counts.get(record, 0) + 1
    return "\n".join(f"{count:5d} × {site}" for site, count in sorted(counts.items(), key=lambda item: -item[1])[:15])


def _exact(value):
    """A value as exactly comparable data: mpmath numbers by mantissa and exponent, arrays by their bytes."""
    if isinstance(value, (tuple, list)):
        return tuple(_exact(item) for item in value)
    if isinstance(value, mpmath.mpf):
        return value._mpf_
    if isinstance(value, (float, np.ndarray, np.floating)):
        return np.asarray(value, dtype=float).tobytes()
    return value


def _public_calls() -> list:
    """A representative set of public calls on numbers sympy evaluates through mpmath (acos, asin), every engine."""
    out: list = []
    # problems from strings
    out.append(lindstedt.Oscillator("Max(0, u - acos(1/3)/2) + u**3/7", a0="asin(1/3) + 1", omega0=1).describe())
    out.append(repr(lindstedt.ForcedOscillator("Max(0, u - acos(1/5))", omega0=1, zeta="1/50", forcing="asin(1/4)")))
    system = lindstedt.UnilateralSystem(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 1]], A=[[1, 0], [-1, 0]], b=["acos(1/3)", 1])
    out.append(repr(lindstedt.ForcedSystem(system, [1, 0], modal_damping=["1/50", "1/50"])))
    # expansions: smooth, branch (symbolic and acos gap), grazing, Hertz (stretched arc), N dof
    smooth = lindstedt.expand("sin(u)", order=3, a0="acos(1/3)", omega0=1)
    branch = lindstedt.expand("Max(0, u - kappa)", order=2, a0=1, omega0=1, params={"kappa": None})
    gap = lindstedt.expand("Max(0, u - acos(1/3)/2)", order=1, a0=1, omega0=1)
    grazing = lindstedt.expand("Max(0, u + 1)", order=2, a0=1, omega0=1)
    hertz = lindstedt.expand("Max(0, u)**(3/2)", order=1, a0=1, omega0=1, numeric=True)
    times = [0.5, 2.0]
    for expansion, values in [(smooth, None), (branch, {"kappa": -0.36}), (branch, {"kappa": "-acos(1/3)/5"}),
                              (branch, {"kappa": np.array([-0.3, 0.2])}), (gap, None), (grazing, None), (hertz, None)]:
        out.append(expansion.frequency(0.1, values=values))
        out.append(expansion.displacement(times, 0.1, values=values))
        out.append(expansion.velocity(times, 0.1, values=values))
        out.append(expansion.truncation_error_estimate(0.1, values=values))
    # times and eps given as exact strings: read by the lock-free evaluators' parse_floats (sympy evaluates them)
    out += [smooth.displacement(["acos(1/3)", 2.0], 0.1), smooth.velocity("asin(1/3)", "1/10"), smooth.frequency("acos(1/3)/10")]
    out += [gap.to_latex(waveforms=True), gap.to_json(), repr(gap), gap.summary(), str(gap.phase), branch.to_latex()]
    out += [gap.lambdify("frequency")(0.1), branch.lambdify("frequency")(0.1, -0.36), smooth.displacement_error_estimate(1.0, 0.1)]
    out += [lindstedt.generate_code(gap, "frequency", "c").source, lindstedt.generate_code(branch, "frequency", "numpy").source]
    mode = lindstedt.nnm(system, mode=1, a0="acos(1/3)", order=2)
    out += [mode.frequency(0.1), mode.displacement(times, 0.1), mode.truncation_error_estimate(0.1), mode.to_latex(), mode.to_json()]
    # references, validation, the forced curve and flow
    out.append(references.piecewise_linear_exact_frequency("1/10", a=1, b="acos(1/3)/4", a0=1, precision=30))
    out.append(references.duffing_exact_frequency("1/10", amplitude="asin(1/3)", precision=30))
    out.append(references.conservative_frequency(sympy.Max(0, sympy.Symbol("u") - sympy.acos(sympy.Rational(1, 3)) / 2), "1/10", a0=1))
    out.append(validate.reference_solution(gap, 0.1, times).displacement)
    out.append(validate.exact_period(lindstedt.Oscillator("u**3 * acos(1/3)", a0=1, omega0=1), 0.1).period)
    curve = lindstedt.frequency_response_curve("u**3", omega0=1, zeta="1/100", forcing="acos(1/3)")
    out += [curve.amplitudes(1.1, 0.1), curve.to_latex(), curve.to_json()]
    out.append(type(lindstedt.forced_flow(lindstedt.ForcedOscillator("Max(0, u - acos(1/3)/4)", omega0=1, zeta="1/50"), 0.5)))
    return out


def test_no_public_call_changes_mpmaths_precision_without_the_lock(unlocked_changes):
    """The colleague's instrument over the public call set: no precision change, and no sympy evaluation at all,
    outside the lock (with a fresh hierarchy cache and a fresh sympy cache, so that every derivation runs)."""
    lindstedt.clear_cache()
    sympy.core.cache.clear_cache()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _public_calls()
    assert not unlocked_changes["precision"], "mpmath's precision set without the lock:\n" + _summary(unlocked_changes["precision"])
    assert not unlocked_changes["evalf"], "sympy evaluated numbers without the lock:\n" + _summary(unlocked_changes["evalf"])
    # the instrument sees what it is for: sympy's own evaluation of acos(1/7) outside the lock
    float(sympy.acos(sympy.Rational(1, 7)))
    assert unlocked_changes["precision"] and unlocked_changes["evalf"]


def test_the_scalar_fast_path_takes_no_lock():
    """``frequency(float)`` of a compiled expansion without parameters stays lock-free (its cost is ~0.2 µs; the
    lock would double it).  A thread holding the lock does not block it."""
    expansion = lindstedt.expand("u**3", order=4, a0=1, omega0=1)
    expected = expansion.frequency(0.1)
    results: list = []
    with lindstedt.precision_lock():  # held here: another thread's fast path must not wait for it
        worker = threading.Thread(target=lambda: results.append([expansion.frequency(0.1) for _ in range(100)]))
        worker.start()
        worker.join(timeout=60)
        assert not worker.is_alive(), "the fast path waited for the lock"
    assert results[0] == [expected] * 100


def test_sympy_heavy_exports_do_not_disturb_locked_mpmath_work(eager_switching):
    """One thread builds problems with acos/asin numbers and exports expansions (LaTeX, JSON, generated code) in a
    loop while four threads compute mpmath references and derive mpmath-sampled expansions; every result of every
    thread is the serial one, bit for bit (exports compared as text), and mpmath's precision is unchanged."""
    def sympy_heavy():
        problem = lindstedt.Oscillator("Max(0, u - acos(1/3)/2) + u**3 * asin(1/5)", a0="acos(1/4)", omega0=1)
        expansion = lindstedt.expand("Max(0, u - acos(2/7)/2)", order=1, a0=1, omega0=1)
        return (problem.describe(), expansion.to_latex(waveforms=True), expansion.to_json(), repr(expansion),
                lindstedt.generate_code(expansion, "frequency", "numpy").source)

    def mpmath_work():
        return (references.piecewise_linear_exact_frequency("1/10", a=1, b="acos(1/3)/4", a0=1, precision=40),
                references.duffing_exact_frequency("1/10", amplitude=1, precision=60),
                lindstedt.expand("Max(0, u)**(3/2)", order=1, a0=1, omega0=1, numeric=True).displacement([0.5, 2.0], 0.1),
                lindstedt.expand("sin(u)", order=3, a0=1, omega0=1).frequency(0.1, order=3))

    precision = mpmath.mp.prec
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lindstedt.clear_cache()
        expected_exports, expected_work = sympy_heavy(), mpmath_work()
    exports: list = []

    def export_afresh():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sympy.core.cache.clear_cache()  # sympy evaluates afresh each time
            return sympy_heavy()

    with _looping_beside(export_afresh, exports):
        for _ in range(2):
            lindstedt.clear_cache()
            results = _together(mpmath_work, count=4)
            wrong = [index for index, result in enumerate(results) if _exact(result) != _exact(expected_work)]
            assert not wrong, f"threads {wrong}: {results[wrong[0]]} differ from the serial {expected_work}"
    assert exports and all(export == expected_exports for export in exports)
    assert mpmath.mp.prec == precision


def test_a_validity_warning_points_at_the_callers_line():
    """The lock's wrappers add frames between the user and the evaluator: a warning still names the user's line."""
    expansion = lindstedt.expand("u**3", order=2, a0=1, omega0=1)
    mode = lindstedt.nnm(lindstedt.UnilateralSystem.one_dof(1), mode=1, a0=1, order=2)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        expansion.frequency(2.0)  # beyond the radius of convergence (|ε| < 1): every call below warns
        expansion.displacement([1.0], 2.0)
        expansion.truncation_error_estimate(2.0)
        mode.frequency(10.0)
    assert len(caught) == 4 and {warning.filename for warning in caught} == {__file__}
