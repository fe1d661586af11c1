"""Benchmark (issue 13): performance against the floor — every row of the issue's table, one run, as ratios.

Each measurement is a fresh interpreter (this file is its own worker: ``python -I bench_performance.py --worker
TASK JSON`` prints one ``@@BENCH-RESULT {json}`` line; the worker puts this file's repository first on
``sys.path``, so it measures the tree the benchmark lives in).  Times are ``time.perf_counter`` around the work
only (imports excluded) unless a row says "whole process".  Each row is shown next to its floor or peer measured
in the same run, the ratio is what is compared with the target, and every series of sizes gets a fitted growth
exponent (time ∝ N^p, or a factor per order for exponential growth).  Accuracy is checked in the same run against
independent references (`lindstedt.references`): a row that got faster but lost accuracy is flagged.

Standalone: ``python benchmarks/bench_performance.py [--quick]`` prints the markdown section.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import REPO_DIR, emit as _emit, format_error as _e, format_seconds as _t, load_average, per_call, run_worker, write_json  # noqa: E402

TITLE = "Performance (issue 13): every target as a ratio to its floor, one run"
SELF = Path(__file__).resolve()
RAW_NAME = "performance.json"
CHAIN_SPRINGS = "[(0, 0.1), (N // 2, -0.05), (N - 1, 0.0)]"  # the chain of benchmarks/bench_nnm_scaling.py


def chain_springs(size: int) -> list[tuple[int, float]]:
    """The unilateral springs of the benchmark chain (:data:`CHAIN_SPRINGS`)."""
    return [(0, 0.1), (size // 2, -0.05), (size - 1, 0.0)]


# =================================================================================================================
# workers (fresh interpreters)
# =================================================================================================================
def _import() -> Any:
    sys.path.insert(0, str(REPO_DIR))  # measure this tree, not whatever the venv has installed
    import lindstedt

    return lindstedt


def elliptic_frequency_series(order: int) -> list[Any]:
    """The Duffing floor: exact ω_0…ω_order of u'' + u + ε u³ = 0, u(0) = 1, from the complete elliptic integral.

    ω = sqrt(1 + ε) π / (2 K(m)), m = ε / (2 (1 + ε)), in gmpy2 rationals with O(order²) operations:
    K(m) = (π/2) Σ_j [C(2j, j)/4^j]² m^j, and m^j = (ε/2)^j (1 + ε)^(−j) has binomial coefficients, so
    the ε series of 2K/π is one double sum; then its reciprocal and the product with sqrt(1 + ε).
    """
    from gmpy2 import mpq

    size = order + 1
    weights, weight = [], mpq(1)
    for j in range(size):  # [C(2j, j) / 4^j]² / 2^j
        weights.append(weight)
        weight = weight * mpq((2 * j + 1) ** 2, 8 * (j + 1) ** 2)
    period = [mpq(1)] + [sum(((-1) ** (k - j)) * math.comb(k - 1, k - j) * weights[j] for j in range(1, k + 1)) for k in range(1, size)]
    inverse = [mpq(1)]
    for k in range(1, size):
        inverse.append(-sum((period[i] * inverse[k - i] for i in range(1, k + 1)), mpq(0)))
    root, binomial = [], mpq(1)
    for k in range(size):  # binomial(1/2, k)
        root.append(binomial)
        binomial = binomial * (mpq(1, 2) - k) / (k + 1)
    return [sum((root[i] * inverse[k - i] for i in range(k + 1)), mpq(0)) for k in range(size)]


def _vector(series: dict[int, Any]) -> tuple[list[Any], Any, int]:
    """A cosine series of one harmonic parity ``{n: mpq}`` as ints over one denominator at stride 2."""
    import gmpy2

    denominator = 1
    for value in series.values():
        denominator = gmpy2.lcm(denominator, value.denominator)
    parity = max(series) & 1
    values = [0] * ((max(series) - parity) // 2 + 1)
    for harmonic, value in series.items():
        values[(harmonic - parity) // 2] = value.numerator * (denominator // value.denominator)
    return values, denominator, parity


def _packed(values: list[Any], bits: int) -> Any:
    import gmpy2

    return gmpy2.pack([v if v > 0 else 0 for v in values], bits) - gmpy2.pack([-v if v < 0 else 0 for v in values], bits)


def _product_sum(pairs: list[tuple[dict, dict]], clock: list[float]) -> dict[int, Any]:
    """Σ a·b of cosine series by Kronecker substitution (a convolution and a correlation per pair, as the engine
    does); only the GMP multiplications and their sums are timed (added to ``clock[0]``), packing and reading back
    are not."""
    import gmpy2
    from gmpy2 import mpq

    forms = [(_vector(a), _vector(b)) for a, b in pairs]
    denominator = 1
    for (_, first, _), (_, second, _) in forms:
        denominator = gmpy2.lcm(denominator, first * second)
    a_length, b_length = max(len(a[0]) for a, _ in forms), max(len(b[0]) for _, b in forms)
    bits = max(max(map(abs, a[0])).bit_length() + max(map(abs, b[0])).bit_length() + (denominator // (a[1] * b[1])).bit_length()
               for a, b in forms) + (a_length + b_length).bit_length() + len(forms).bit_length() + 2
    packed = [(_packed(a[0], bits), _packed(b[0], bits), _packed(b[0][::-1], bits), len(b[0]), denominator // (a[1] * b[1]))
              for a, b in forms]
    sums = mirrored = 0
    start = time.process_time()
    for first, second, reversed_second, length, scale in packed:
        term, correlation = first * second, first * reversed_second
        if scale != 1:
            term, correlation = term * scale, correlation * scale
        sums += term
        mirrored += correlation << (bits * (b_length - length)) if length != b_length else correlation
    clock[0] += time.process_time() - start
    half, count = 1 << (bits - 1), a_length + b_length - 1
    lift = gmpy2.pack([half] * count, bits)
    a_parity, b_parity = forms[0][0][2], forms[0][1][2]
    result: dict[int, Any] = {}
    for index, digit in enumerate(gmpy2.unpack(sums + lift, bits)):
        if digit != half:
            harmonic = 2 * index + a_parity + b_parity
            result[harmonic] = result.get(harmonic, 0) + digit - half
    for index, digit in enumerate(gmpy2.unpack(mirrored + lift, bits)):
        if digit != half:
            harmonic = abs(2 * (index - b_length + 1) + a_parity - b_parity)
            result[harmonic] = result.get(harmonic, 0) + digit - half
    return {harmonic: mpq(value, 2 * denominator) for harmonic, value in result.items() if value}


def duffing_products_floor(waveforms: list[dict[int, Any]]) -> tuple[float, int]:
    """The GMP multiplications alone of the Lindstedt–Poincaré recurrence of u'' + u + ε u³ = 0 to order N.

    ``waveforms`` are the exact v_0 … v_N (``{harmonic: mpq}``); the products the recurrence needs are
    ``[δ²]_n = Σ_{i+j=n} v_i v_j`` (each unordered pair once) and ``[δ³]_n = Σ_j v_j [δ²]_{n−j}`` for n < N.  Each
    sum is one Kronecker-packed convolution and correlation per pair, operands packed untimed (:func:`_product_sum`).
    Returns (CPU seconds of the multiplications, products).
    """
    order = len(waveforms) - 1
    clock, squares, count = [0.0], {}, 0
    for n in range(2, order):
        pairs = [(waveforms[i], waveforms[n - i]) for i in range(1, (n + 1) // 2)]
        total = {h: 2 * v for h, v in _product_sum(pairs, clock).items()} if pairs else {}
        if n % 2 == 0:
            for harmonic, value in _product_sum([(waveforms[n // 2],) * 2], clock).items():
                total[harmonic] = total.get(harmonic, 0) + value
        squares[n] = {h: v for h, v in total.items() if v}
        count += len(pairs) + 1 - n % 2
        if n >= 3:
            cubes = [(waveforms[j], squares[n - j]) for j in range(1, n - 1)]
            _product_sum(cubes, clock)
            count += len(cubes)
    return clock[0], count


def _worker_duffing(spec: dict[str, Any]) -> None:
    """ω_0…ω_N of f (default Duffing; then the waveforms), CPU time after the imports; or a floor: ``"elliptic"``
    (Duffing only, :func:`elliptic_frequency_series`), ``"energy"`` (any polynomial f,
    :func:`lindstedt.references.conservative_frequency_series`), ``"products"`` (Duffing: the GMP multiplications of
    the recurrence alone, :func:`duffing_products_floor`)."""
    order, f, floor = spec["order"], spec.get("f", "u**3"), spec["floor"]
    if floor == "elliptic":
        import gmpy2  # noqa: F401  (imported before the clock, as lindstedt's imports are)

        start = time.process_time()
        omega = elliptic_frequency_series(order)
        _emit({"seconds": time.process_time() - start, "omega": [str(w) for w in omega]})
        return
    lindstedt = _import()
    lindstedt.expand("u**2", order=1, a0=1, omega0=1).omega  # imports (sympy, scipy: ~0.6 s) on another problem, untimed
    if floor == "energy":
        from lindstedt.references import conservative_frequency_series

        conservative_frequency_series("u**2", 2)  # its imports, untimed
        start = time.process_time()
        omega = conservative_frequency_series(f, order)
        _emit({"seconds": time.process_time() - start, "omega": [str(w) for w in omega]})
        return
    if floor == "products":
        from gmpy2 import mpq

        waveforms = lindstedt.expand(f, order=order, a0=1, omega0=1).waveforms  # untimed: the operands
        series = [{h: mpq(int(c.p), int(c.q)) for h, c in w.coefficients} for w in waveforms]
        seconds, products = duffing_products_floor(series)
        _emit({"seconds": seconds, "products": products})
        return
    start = time.process_time()
    expansion = lindstedt.expand(f, order=order, a0=1, omega0=1)
    omega = expansion.omega
    seconds = time.process_time() - start
    waveforms = expansion.waveforms
    _emit({"seconds": seconds, "with_waveforms": time.process_time() - start, "omega": [str(w) for w in omega],
           "waveforms": len(waveforms)})


def _worker_expand(spec: dict[str, Any]) -> None:
    """One piecewise expansion to ``order`` (exact, symbolic κ, or float mode), cold; ω_k at 40 digits, sizes."""
    import sympy

    lindstedt = _import()
    kwargs: dict[str, Any] = {"order": spec["order"], "a0": 1, "omega0": 1}
    if spec.get("params"):
        kwargs["params"] = spec["params"]
    if spec["mode"] == "float":
        kwargs.update(numeric=True, precision=30)
    start = time.perf_counter()
    omega = lindstedt.expand(spec["f"], **kwargs).omega
    seconds = time.perf_counter() - start
    out: dict[str, Any] = {"seconds": seconds, "count_ops": [int(sympy.count_ops(w)) for w in omega]}
    values = {name: sympy.Rational(value) for name, value in spec.get("evaluate_at", {}).items()}

    def at(expression: Any) -> Any:  # by name: the expansion's symbols carry assumptions
        expression = sympy.sympify(expression)
        return expression.xreplace({s: values[s.name] for s in expression.free_symbols if s.name in values})

    out["omega"] = [str(sympy.N(at(w), 40)) for w in omega]
    _emit(out)


def _worker_numeric_kappa(spec: dict[str, Any]) -> None:
    """``numeric=True`` ω_1…ω_4 at κ new to a warm process, against the compiled closed form ω_k(κ) (the floor)."""
    import sympy

    lindstedt = _import()
    text, order = "Max(0, u - kappa)", 4
    lindstedt.expand(text, order=order, a0=1, omega0=1, params={"kappa": "1/3"}, numeric=True, precision=spec["precision"]).omega
    rows = []
    for kappa in spec["kappas"]:
        start = time.perf_counter()
        omega = lindstedt.expand(text, order=order, a0=1, omega0=1, params={"kappa": kappa}, numeric=True,
                                 precision=spec["precision"]).omega
        seconds = time.perf_counter() - start
        rows.append({"kappa": kappa, "seconds": seconds, "omega": [str(sympy.N(w, 30)) for w in omega]})
    family = lindstedt.expand(text, order=order, a0=1, omega0=1, params={"kappa": None})  # untimed
    symbolic = family.omega
    family.frequency_coefficients({"kappa": 1 / 3})  # compiles the closed forms (untimed)
    compiled_rows = []
    for kappa in spec["kappas"]:
        value = float(sympy.Rational(kappa))
        start = time.perf_counter()
        coefficients = family.frequency_coefficients({"kappa": value})
        seconds = time.perf_counter() - start
        compiled_rows.append({"kappa": kappa, "seconds": seconds, "omega": [repr(float(c)) for c in coefficients],
                              "double": repr(value)})
    kappa_symbol = next(iter(set().union(*(sympy.sympify(w).free_symbols for w in symbolic))))
    closed = sympy.lambdify(kappa_symbol, list(symbolic[1:]), "math")
    floor = min(per_call(lambda k=float(sympy.Rational(kappa)): closed(k), 3, 0.05)[0] for kappa in spec["kappas"])
    _emit({"rows": rows, "floor_seconds": floor, "compiled": compiled_rows})


def _worker_evaluation(spec: dict[str, Any]) -> None:
    """``Expansion.frequency(ε)``: first call after the expansion, warm per call, against a lambdified call."""
    lindstedt = _import()
    expansion = lindstedt.expand(spec["f"], order=4, a0=1, omega0=1)
    expansion.omega  # untimed: the expansion itself
    start = time.perf_counter()
    expansion.frequency(0.01)
    first = time.perf_counter() - start
    warm = per_call(lambda: expansion.frequency(0.01), 5, 0.05)[0]
    compiled = expansion.lambdify("frequency")
    lambdified = per_call(lambda: compiled(0.01), 5, 0.05)[0]
    _emit({"first": first, "warm": warm, "lambdified": lambdified, "value": float(expansion.frequency(0.01))})


def cauchy_gap_coefficients(kappa: float, order: int, nodes: int = 32) -> Any:
    """The float64 floor of ``frequency_coefficients`` at a new κ: ω_0 … ω_order of u'' + u + ε (u − κ)₊ = 0, u(0) = 1,
    |κ| < 1, by the Cauchy integral ω_k = (1/n) Σ_j ω(r z_j) (r z_j)^−k of the exact period over n = 32 nodes on the
    circle r = ¼ min(1, (1 + κ)/(1 − κ)) (a quarter of the distance to the nearest singularity for κ ≤ 0): the
    contact arc's time arccos((κ − c)/A)/ω and the free arc's π − arccos(κ/√(κ² + v²)), c = εκ/(1 + ε),
    A = 1 − c, ω = √(1 + ε), v² = ω² (A² − (κ − c)²); one FFT."""
    import numpy as np

    radius = 0.25 * min(1.0, (1 + kappa) / (1 - kappa))
    eps = radius * np.exp(2j * np.pi * np.arange(nodes) / nodes)
    omega = np.sqrt(1 + eps)
    center = eps * kappa / (1 + eps)
    amplitude = 1 - center
    contact = np.arccos((kappa - center) / amplitude) / omega
    speed2 = omega**2 * (amplitude**2 - (kappa - center) ** 2)
    free = np.pi - np.arccos(kappa / np.sqrt(kappa**2 + speed2))
    coefficients = np.fft.fft(np.pi / (contact + free)) / nodes
    return coefficients[: order + 1].real / radius ** np.arange(order + 1)


def cauchy_gap_coefficients_mp(kappa: Any, order: int, precision: int = 30, ratio: float = 4.0) -> list[Any]:
    """The same-digit floor of ``numeric=True`` at a new κ: ω_0 … ω_order of u'' + u + ε (u − κ)₊ = 0, u(0) = 1,
    |κ| < 1 (κ exact: an int, a ``sympy.Rational`` or a ``"p/q"`` string), each to ``precision`` significant
    digits, by the Cauchy integral of the exact period in mpmath.

    With p = 1 − κ the period is 2π/ω = 2 (π − arccos(κ/√(1 + p² ε))) + 2 arccos(κ/(1 + p ε))/√(1 + ε) (the
    contact ellipse's P = (1 + p ε)² is a square).  Nearest singularity R = min(1, (1 + κ)/(1 − κ)): √(1 + ε) at
    ε = −1 and the grazing point (arccos at ±1) at ε = −(1 + κ)/(1 − κ); the others (ε = −1/p, −1/p²) are farther.
    Nodes on the circle r = R/ρ (ρ = ``ratio``; ω(ε̄) = conj ω(ε), so ⌊n/2⌋ + 1 samples).  For D digits of the
    scale R^−k: the aliasing error ω_{k+n} r^n ~ ρ^−n R^−k gives n = ⌈D/log10 ρ⌉ (at least order + 1), and the
    samples' rounding, magnified by r^−k, gives D + order·log10 ρ working digits.  D = ``precision`` + 3 guard
    digits + the digits by which the smallest |ω_k| falls below R^−k (measured on the result, and recomputed with
    them when they exceed the previous pass's allowance, e.g. κ → 1 where ω_k ~ (1 − κ)^(k+1/2)).
    """
    from fractions import Fraction

    import mpmath

    exact = Fraction(str(kappa))
    if not -1 < exact < 1:
        raise ValueError(f"kappa = {kappa}: the crossing regime |kappa| < 1 only")
    extra = 0.0
    for _ in range(4):
        digits = precision + 3 + extra
        count = max(order + 1, math.ceil(digits / math.log10(ratio)))
        with mpmath.mp.workdps(math.ceil(digits + order * math.log10(ratio))):
            k = mpmath.mpf(exact.numerator) / exact.denominator
            p = 1 - k
            big = min(mpmath.mpf(1), (1 + k) / p)
            radius = big / ratio
            samples = []
            for j in range(count // 2 + 1):
                eps = radius * mpmath.expjpi(mpmath.mpf(2 * j) / count)
                free = mpmath.pi - mpmath.acos(k / mpmath.sqrt(1 + p * p * eps))
                contact = mpmath.acos(k / (1 + p * eps)) / mpmath.sqrt(1 + eps)
                samples.append(mpmath.pi / (free + contact))
            coefficients = []
            for power in range(order + 1):
                total = samples[0].real
                for j in range(1, count // 2 + 1):
                    term = (samples[j] * mpmath.expjpi(mpmath.mpf(-2 * j * power) / count)).real
                    total += term if 2 * j == count else 2 * term
                coefficients.append(total / count / radius**power)
            deficit = max(float(mpmath.log10(big**-power / abs(c))) if c else 0.0 for power, c in enumerate(coefficients))
        if deficit <= extra + 0.5:
            break
        extra = deficit + 1
    with mpmath.mp.workdps(precision):
        return [+c for c in coefficients]


def _worker_numeric_floor(spec: dict[str, Any]) -> None:
    """The floor of the ``numeric=True`` row: :func:`cauchy_gap_coefficients_mp` per κ, warm (one untimed call at
    κ = 1/3), on r = R/4 (the radius of the float64 floor and of the issue's audit) and on r = R/10^7 (six nodes,
    the cheapest radius); each checked against ``piecewise_linear_frequency_taylor`` (45 digits + precision)."""
    import mpmath
    import sympy
    from lindstedt.references import piecewise_linear_frequency_taylor

    order, precision = spec["order"], spec["precision"]
    out: dict[str, Any] = {}
    for name, ratio in (("quarter", 4.0), ("cheapest", 1e7)):
        cauchy_gap_coefficients_mp("1/3", order, precision, ratio)
        times, worst = [], 0.0
        for kappa in spec["kappas"]:
            start = time.perf_counter()
            values = cauchy_gap_coefficients_mp(kappa, order, precision, ratio)
            times.append(time.perf_counter() - start)
            reference = piecewise_linear_frequency_taylor(order, a=1, b=sympy.Rational(kappa), a0=1, precision=precision + 15)
            with mpmath.mp.workdps(precision + 15):
                worst = max(worst, *(float(abs(v - r) / abs(r)) for v, (r, _) in zip(values, reference) if r))
        out[name] = {"ratio": ratio, "times": times, "median": statistics.median(times), "worst": max(times),
                     "relative_error": worst, "agrees": worst <= 10.0 ** -precision}
    _emit(out)


def _worker_new_kappa(spec: dict[str, Any]) -> None:
    """A symbolic-κ expansion re-evaluated at new κ (each value new to the process) against its lambdified ω(ε; κ);
    then ``frequency_coefficients`` at κ + 2^−30 (new again) against :func:`cauchy_gap_coefficients`."""
    import sympy

    lindstedt = _import()
    expansion = lindstedt.expand("Max(0, u - kappa)", order=spec["order"], a0=1, omega0=1, params={"kappa": None})
    expansion.omega  # untimed
    start = time.perf_counter()
    expansion.frequency(0.05, values={"kappa": 1 / 3})  # the first evaluation compiles the closed forms
    first = time.perf_counter() - start
    times, values = [], []
    for kappa in [float(sympy.Rational(value)) for value in spec["kappas"]]:  # read outside the timed call
        start = time.perf_counter()
        values.append(float(expansion.frequency(0.05, values={"kappa": kappa})))
        times.append(time.perf_counter() - start)
    symbols = sorted(sympy.sympify(expansion.frequency_expr()).free_symbols, key=str)
    compiled = sympy.lambdify(symbols, expansion.frequency_expr(), "math")
    arguments = {str(s): s for s in symbols}
    order_of = [next(name for name in arguments if name.startswith(prefix)) for prefix in ("eps", "kappa")]
    call = (lambda k: compiled(*(0.05 if str(s) == order_of[0] else k for s in symbols)))
    lambdified = min(per_call(lambda k=float(sympy.Rational(v)): call(k), 3, 0.05)[0] for v in spec["kappas"])
    reference = [call(float(sympy.Rational(v))) for v in spec["kappas"]]
    coefficient_times, tables = [], []
    kappas = [float(sympy.Rational(value)) + 2.0**-30 for value in spec["kappas"]]
    for kappa in kappas:  # all calls first, then the floor's loops (interleaved, they leave the caches cold)
        start = time.perf_counter()
        tables.append(expansion.frequency_coefficients({"kappa": kappa}))
        coefficient_times.append(time.perf_counter() - start)
    floors = [per_call(lambda k=kappa: cauchy_gap_coefficients(k, spec["order"]), 3, 0.02)[0] for kappa in kappas]
    difference = max(float(abs(table - cauchy_gap_coefficients(kappa, spec["order"])).max()) for kappa, table in zip(kappas, tables))
    _emit({"first": first, "times": times, "values": values, "lambdified": lambdified, "reference": reference,
           "coefficient_times": coefficient_times, "cauchy": statistics.median(floors), "cauchy_difference": difference})


#: the elements of the "any law" chain: a Hertz contact on a mass a third along and a cubic spring between the first two
CHAIN_LAWS = '[(N // 3, None, "Max(0, u)**(3/2)", "1/100"), (0, 1, "u**3")]'


def chain_laws(size: int) -> list[tuple[Any, ...]]:
    """The elements of the "any law" benchmark chain (:data:`CHAIN_LAWS`): the Hertz gap 1/100 keeps the contact
    engaged around the release point for every N (with 1/10 it disengages beyond ~100 dof at a0 = 1)."""
    return [(size // 3, None, "Max(0, u)**(3/2)", "1/100"), (0, 1, "u**3")]


def _worker_nnm(spec: dict[str, Any]) -> None:
    """``nnm`` of the benchmark chain (with :func:`chain_laws` if ``spec["laws"]``):
    wall time, and the peak resident memory over the baseline after the imports and the system's construction;
    with ``spec["reduce"] = K`` the chain goes through ``ResidualFlexibility(K)`` first (its time included)."""
    import resource

    lindstedt = _import()
    size, mode = spec["size"], spec["mode"]
    springs = chain_springs(size)
    elements = chain_laws(size) if spec.get("laws") else []
    system = lindstedt.UnilateralSystem.chain(size, unilateral=springs, elements=elements)
    baseline = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB on Linux
    start = time.perf_counter()
    if spec.get("reduce"):
        reduced = lindstedt.ResidualFlexibility(modes=spec["reduce"], digits=30).reduce(
            (system.M, system.K), A=system.A, b=system.b, W=system.W, laws=list(system.laws))
        system = reduced.system
    result = lindstedt.nnm(system, mode=mode, a0=1.0, order=spec.get("order", 2))
    omega = [float(value) for value in result.omega]
    seconds = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    _emit({"seconds": seconds, "omega": omega, "memory_mb": (peak - baseline) / 1024, "dof": system.n_dof})


def _worker_continuation(spec: dict[str, Any]) -> None:
    lindstedt = _import()
    size = spec["size"]
    springs = chain_springs(size)
    system = lindstedt.UnilateralSystem.chain(size, unilateral=springs)
    start = time.perf_counter()
    branch = lindstedt.continue_nnm(system, spec["mode"], start=spec["start"], stop=spec["stop"],
                                    modal_amplitude=spec["modal_amplitude"], max_points=spec["max_points"])
    seconds = time.perf_counter() - start
    reached = float(branch.parameter_values[-1]) if len(branch.parameter_values) else None
    _emit({"seconds": seconds, "success": bool(branch.success), "message": str(branch.stop_reason),
           "points": len(branch.points), "flows": int(branch.flow_evaluations), "rejected": int(branch.rejected_steps),
           "reached": reached, "jumps": len(branch.jumps)})


def _worker_cauchy(spec: dict[str, Any]) -> None:
    """The floor of issue 26 for the piecewise engines: ω_0…ω_N of (u − κ)₊ by the Cauchy integral of the exact
    closed-form period (``piecewise_linear_frequency_taylor``) at ``precision`` digits, per κ, warm (one untimed call)."""
    import sympy
    from lindstedt.references import piecewise_linear_frequency_taylor

    piecewise_linear_frequency_taylor(spec["order"], a=1, b=sympy.Rational(1, 3), a0=1, precision=spec["precision"])
    times = []
    for kappa in spec["kappas"]:
        b = sympy.Rational(kappa)
        start = time.perf_counter()
        piecewise_linear_frequency_taylor(spec["order"], a=1, b=b, a0=1, precision=spec["precision"])
        times.append(time.perf_counter() - start)
    _emit({"times": times, "median": statistics.median(times), "worst": max(times)})


WORKERS = {
    "duffing": _worker_duffing, "expand": _worker_expand, "numeric-kappa": _worker_numeric_kappa,
    "evaluation": _worker_evaluation, "new-kappa": _worker_new_kappa, "nnm": _worker_nnm,
    "continuation": _worker_continuation, "cauchy": _worker_cauchy, "numeric-floor": _worker_numeric_floor,
}


def _call(task: str, spec: dict[str, Any], timeout: float) -> dict[str, Any]:
    outcome = run_worker(sys.executable, SELF, ["--worker", task, json.dumps(spec)], timeout=timeout)
    result = dict(outcome.result or {})
    result.update(status=outcome.status, detail=outcome.detail, process_wall=outcome.wall, load=load_average())
    return result


def _median_of(task: str, spec: dict[str, Any], runs: int, timeout: float, key: str = "seconds") -> dict[str, Any]:
    results = [_call(task, spec, timeout) for _ in range(runs)]
    good = [r for r in results if r["status"] == "ok"]
    if not good:
        return results[0]
    best = dict(good[0])
    best["runs"] = [r[key] for r in good]
    best[key] = statistics.median(best["runs"])
    return best


def _whole_process(code: str, runs: int) -> list[float]:
    """Wall time of ``python -I -c code`` (this tree first on sys.path), ``runs`` times."""
    prefix = f"import sys; sys.path.insert(0, {str(REPO_DIR)!r}); "
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-I", "-c", prefix + code], check=True, capture_output=True)
        times.append(time.perf_counter() - start)
    return times


# =================================================================================================================
# formatting
# =================================================================================================================
def _power_fit(sizes: list[float], times: list[float]) -> float | None:
    """Least-squares slope of log t against log N (time ∝ N^p)."""
    points = [(math.log(n), math.log(t)) for n, t in zip(sizes, times) if t and t > 0]
    if len(points) < 2:
        return None
    mean_x = sum(x for x, _ in points) / len(points)
    mean_y = sum(y for _, y in points) / len(points)
    return sum((x - mean_x) * (y - mean_y) for x, y in points) / sum((x - mean_x) ** 2 for x, _ in points)


def _factor_fit(orders: list[int], times: list[float]) -> float | None:
    """Least-squares growth factor per order (time ∝ q^N)."""
    slope = _power_fit([math.e ** n for n in orders], times)
    return None if slope is None else math.exp(slope)


def _verdict(met: bool | None) -> str:
    return "—" if met is None else ("**met**" if met else "**MISSED**")


def _relative_errors(values: list[str], reference: list[tuple[Any, Any]]) -> tuple[float, float]:
    """Largest |value − ref| / max|ref| over k ≥ 1, and the reference's own largest estimate (same scale)."""
    import mpmath

    with mpmath.workdps(50):
        scale = max(abs(mpmath.mpf(ref)) for ref, _ in reference[1:])
        error = max(abs(mpmath.mpf(value) - mpmath.mpf(ref)) for value, (ref, _) in zip(values[1:], reference[1:]))
        estimate = max(mpmath.mpf(err) for _, err in reference[1:])
        return float(error / scale), float(estimate / scale)


# =================================================================================================================
# the benchmark
# =================================================================================================================
def duffing_section(quick: bool = False) -> tuple[list[tuple[str, str, str, str, str]], str, list[dict[str, Any]]]:
    """Issue 26 row: Duffing ω_0…ω_N exact against the gmpy2 elliptic floor and against the GMP multiplications of
    its own recurrence; an asymmetric polynomial against the energy-series floor. CPU time, best of 3 fresh processes."""
    orders = [10, 25, 50] if quick else [10, 25, 50, 70, 100]
    runs = 1 if quick else 3
    rows = []
    for order in orders:
        mine = _best_of("duffing", {"order": order, "floor": None}, runs, 600)
        floor = _best_of("duffing", {"order": order, "floor": "elliptic"}, runs, 600)
        products = _best_of("duffing", {"order": order, "floor": "products"}, runs, 900)
        exact = mine.get("omega") == floor.get("omega") and mine["status"] == "ok"
        ratio = mine.get("seconds", math.nan) / floor.get("seconds", math.nan)
        rows.append({"order": order, "mine": mine, "floor": floor, "products": products, "exact": exact, "ratio": ratio})
    lines = ["| order | ω (CPU) | ω + waveforms (CPU) | floor: elliptic series, gmpy2 (CPU) | ratio ω / floor | "
             "GMP products of the recurrence alone (CPU) | ratio ω / products | ω_k = floor |",
             "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |"]
    for row in rows:
        products = row["products"].get("seconds")
        lines.append(f"| {row['order']} | {_t(row['mine'].get('seconds'))} | {_t(row['mine'].get('with_waveforms'))} | "
                     f"{_t(row['floor'].get('seconds'))} | {row['ratio']:.1f}× | {_t(products)} | "
                     f"{row['mine'].get('seconds', math.nan) / (products or math.nan):.1f}× | "
                     f"{'✅ identical' if row['exact'] else '❌ ' + str(row['mine'].get('detail') or 'differs')} |")
    top = [row for row in rows if row["order"] >= orders[-1] // 2]  # the top half of the range
    fit_mine = _power_fit([r["order"] for r in top], [r["mine"].get("seconds") for r in top])
    fit_floor = _power_fit([r["order"] for r in top], [r["floor"].get("seconds") for r in top])
    fit_products = _power_fit([r["order"] for r in top], [r["products"].get("seconds") for r in top])
    # an asymmetric polynomial (even and odd harmonics) against the exact energy series of any polynomial f
    asymmetric = []
    for order in ([25, 50] if quick else [25, 50, 100]):
        mine = _best_of("duffing", {"order": order, "floor": None, "f": "u**2 + u**3"}, runs, 900)
        floor = _best_of("duffing", {"order": order, "floor": "energy", "f": "u**2 + u**3"}, runs, 600)
        asymmetric.append({"order": order, "mine": mine, "floor": floor, "exact": mine.get("omega") == floor.get("omega"),
                           "ratio": mine.get("seconds", math.nan) / floor.get("seconds", math.nan)})
    summary = []
    last = rows[-1]
    summary.append((f"Duffing ω_0…ω_{last['order']} exact", _t(last["mine"].get("seconds")), _t(last["floor"].get("seconds")) +
                    " (elliptic series, gmpy2)", f"{last['ratio']:.1f}×", _verdict(last["ratio"] <= 20 and last["exact"])))
    if fit_mine is not None:
        summary.append((f"Duffing growth, orders {top[0]['order']}–{last['order']}", f"N^{fit_mine:.2f}", f"N^{fit_floor:.2f}",
                        "—", _verdict(fit_mine <= 2.5)))
    summary.append((f"Duffing ω_0…ω_{last['order']}: the recurrence's own GMP products", _t(last["mine"].get("seconds")),
                    _t(last["products"].get("seconds")) + " (its multiplications alone)",
                    f"{last['mine'].get('seconds', math.nan) / (last['products'].get('seconds') or math.nan):.1f}×; "
                    f"the products alone {(last['products'].get('seconds') or math.nan) / last['floor'].get('seconds', math.nan):.0f}× "
                    "the elliptic floor", "—"))
    top_asymmetric = asymmetric[-1]
    summary.append((f"u² + u³ ω_0…ω_{top_asymmetric['order']} exact", _t(top_asymmetric["mine"].get("seconds")),
                    _t(top_asymmetric["floor"].get("seconds")) + " (energy series, gmpy2)", f"{top_asymmetric['ratio']:.1f}×",
                    "—" if top_asymmetric["exact"] else "❌ differs"))
    asymmetric_lines = ["| order | lindstedt ω (CPU) | floor: energy series (CPU) | ratio | ω_k = floor |", "| ---: | ---: | ---: | ---: | --- |"]
    for row in asymmetric:
        asymmetric_lines.append(f"| {row['order']} | {_t(row['mine'].get('seconds'))} | {_t(row['floor'].get('seconds'))} | "
                                f"{row['ratio']:.1f}× | {'✅ identical' if row['exact'] else '❌ differs'} |")
    part = ("### 1. Duffing to high order (`expand(\"u**3\", order=N, a0=1, omega0=1).omega`, then `.waveforms`)\n\n"
            "Floors: the exact frequency series from the complete elliptic integral in gmpy2 rationals, O(N²) operations "
            "(`elliptic_frequency_series` in this file; ω only, no waveforms); and the GMP multiplications alone of the "
            "recurrence the engine solves — [δ²]_n and [δ³]_n = Σ v_j [δ²]_{n−j} for n < N as Kronecker-packed convolutions "
            "and correlations of the exact waveforms, operands packed untimed (`duffing_products_floor`). CPU time "
            "(`time.process_time`) around the work, best of "
            f"{runs} fresh processes; lindstedt's imports are excluded (an untimed expansion of another problem first).\n\n"
            + "\n".join(lines) +
            (f"\n\nGrowth over the top half of the orders: lindstedt ∝ N^{fit_mine:.2f}, elliptic floor ∝ N^{fit_floor:.2f}, "
             f"the recurrence's GMP products ∝ N^{fit_products:.2f}. " if fit_mine is not None and fit_products is not None else "\n\n") +
            "Targets (issue 26): order 100 ≤ 20× the floor, growth ≤ N^2.5 between 50 and 100, ω_k identical. "
            "The recurrence needs ~N²/2 products of waveforms of ~N/2 harmonics and ~5N bits each; their multiplications "
            "alone cost more than 20× the elliptic series at order 100 and grow faster than N^2.5 — the targets are "
            "below the arithmetic of the Lindstedt–Poincaré recurrence itself, which the engine runs within the ratio "
            "of the last column.\n\n"
            "**u² + u³** (even and odd harmonics, an asymmetric orbit) against the exact energy-integral series of any "
            "polynomial f (`lindstedt.references.conservative_frequency_series`, O(N² deg f) rationals):\n\n"
            + "\n".join(asymmetric_lines))
    return summary, part, rows + [dict(row, f="u**2 + u**3") for row in asymmetric]


def _best_of(task: str, spec: dict[str, Any], runs: int, timeout: float) -> dict[str, Any]:
    results = [_call(task, spec, timeout) for _ in range(runs)]
    good = [r for r in results if r["status"] == "ok"]
    if not good:
        return results[0]
    best = dict(min(good, key=lambda r: r["seconds"]))
    best["runs"] = [r["seconds"] for r in good]
    return best



def run(quick: bool = False) -> str:
    import sympy

    sys.path.insert(0, str(REPO_DIR))
    from lindstedt.references import frequency_taylor_coefficients, piecewise_linear_frequency_taylor

    started, load_start = time.perf_counter(), load_average()
    raw: dict[str, Any] = {"load_start": load_start}
    summary: list[tuple[str, str, str, str, str]] = []  # work, measured, floor, ratio, verdict
    parts: list[str] = []
    runs = 1 if quick else 3

    # -- 1. Duffing ------------------------------------------------------------------------------------------
    summary_rows, part, raw["duffing"] = duffing_section(quick)
    summary += summary_rows
    parts.append(part)

    # -- 2. exact and symbolic contact angles ----------------------------------------------------------------
    reference_310 = piecewise_linear_frequency_taylor(10, a=1, b=sympy.Rational(3, 10), a0=1, precision=45)
    contact_rows = []
    exact_orders = [4, 6] if quick else [4, 6, 8, 10]
    for order in exact_orders:
        exact = _median_of("expand", {"f": "Max(0, u - 3/10)", "order": order, "mode": "exact"}, 1, 900)
        numeric = _median_of("expand", {"f": "Max(0, u - 3/10)", "order": order, "mode": "float"}, runs, 300)
        contact_rows.append({"order": order, "exact": exact, "float": numeric})
    raw["kappa_3_10"] = contact_rows
    lines = ["| order | exact κ = 3/10 (cold) | float mode, 30 digits (cold) | ratio | exact ω_k vs reference (rel.) | reference's estimate |",
             "| ---: | ---: | ---: | ---: | ---: | ---: |"]
    for row in contact_rows:
        error, estimate = (None, None)
        if row["exact"]["status"] == "ok":
            error, estimate = _relative_errors(row["exact"]["omega"], reference_310[: row["order"] + 1])
        row["error"], row["estimate"] = error, estimate
        ratio = row["exact"].get("seconds", math.nan) / row["float"].get("seconds", math.nan)
        lines.append(f"| {row['order']} | {_t(row['exact'].get('seconds')) if row['exact']['status'] == 'ok' else row['exact']['status']} | "
                     f"{_t(row['float'].get('seconds'))} | {ratio:.0f}× | {_e(error)} | {_e(estimate)} |")
    fit_exact = _factor_fit(exact_orders, [r["exact"].get("seconds") for r in contact_rows])
    last = contact_rows[-1]
    accurate = last["error"] is not None and last["error"] <= 10 * max(last["estimate"], 1e-40)
    summary.append((f"(u − 3/10)₊ exact, order {last['order']}", _t(last["exact"].get("seconds")), _t(last["float"].get("seconds")) + " (float mode)",
                    f"{last['exact'].get('seconds', math.nan) / last['float'].get('seconds', math.nan):.0f}× float mode",
                    _verdict(last["order"] == 10 and last["exact"].get("seconds", math.inf) <= 10 and accurate) if not quick else "—"))
    cauchy_10 = _call("cauchy", {"order": last["order"], "precision": 30, "kappas": ["3/10"]}, 300)
    raw["cauchy_order_10"] = cauchy_10
    if cauchy_10["status"] == "ok":
        ratio_cauchy = last["exact"].get("seconds", math.nan) / cauchy_10["median"]
        summary.append((f"(u − 3/10)₊ exact, order {last['order']}, against the 30-digit Cauchy floor", _t(last["exact"].get("seconds")),
                        _t(cauchy_10["median"]) + " (Cauchy integral, 30 digits)", f"{ratio_cauchy:.0f}×",
                        _verdict(ratio_cauchy <= 10) if not quick else "—"))
    parts.append("### 2. Exact contact angles\n\n**(u − 3/10)₊, exact** (`expand(\"Max(0, u - 3/10)\", order=N, a0=1, omega0=1)`; "
                 "floor: the same expansion in float mode, `numeric=True, precision=30`). Reference: "
                 "`piecewise_linear_frequency_taylor` (Cauchy integral of the closed-form period, 45 digits, own estimate).\n\n"
                 + "\n".join(lines) + f"\n\nGrowth of the exact expansion: ×{fit_exact:.2f} per order. Target: order 10 ≤ 10 s.")

    symbolic_orders = [3, 4] if quick else [3, 4, 5, 6]
    symbolic_rows = []
    for order in symbolic_orders:
        result = _median_of("expand", {"f": "Max(0, u - kappa)", "order": order, "mode": "exact", "params": {"kappa": None},
                                       "evaluate_at": {"kappa": "3/10"}}, 1, 900)
        symbolic_rows.append({"order": order, "result": result})
    raw["symbolic_kappa"] = symbolic_rows
    lines = ["| order | cold time | count_ops of ω_1 … ω_N | ω_k at κ = 3/10 vs reference (rel.) |", "| ---: | ---: | --- | ---: |"]
    for row in symbolic_rows:
        result = row["result"]
        error = None
        if result["status"] == "ok":
            error, _ = _relative_errors(result["omega"], reference_310[: row["order"] + 1])
        row["error"] = error
        lines.append(f"| {row['order']} | {_t(result.get('seconds')) if result['status'] == 'ok' else result['status']} | "
                     f"{', '.join(map(str, result.get('count_ops', [])[1:]))} | {_e(error)} |")
    fit_symbolic = _factor_fit(symbolic_orders, [r["result"].get("seconds") for r in symbolic_rows])
    last = symbolic_rows[-1]
    sizes = last["result"].get("count_ops", [])
    summary.append((f"(u − b)₊ symbolic κ, order {last['order']}", _t(last["result"].get("seconds")), "—",
                    f"ω_{last['order']}: {sizes[-1] if sizes else '—'} ops (issue: ω6 41k–66k)",
                    _verdict(last["order"] == 6 and last["result"].get("seconds", math.inf) <= 3 and bool(sizes) and sizes[-1] <= 4100) if not quick else "—"))
    parts.append("**(u − κ)₊, symbolic κ** (`params={\"kappa\": None}`, exact in κ, arccos κ, √(1 − κ²) and π), cold; the "
                 "ω_k are checked at κ = 3/10 against the same reference.\n\n" + "\n".join(lines) +
                 f"\n\nGrowth: ×{fit_symbolic:.2f} per order. Targets: order 6 ≤ 3 s; expressions ≥ 10× smaller than the "
                 "issue's measurement (ω6: 41k–66k operations, so ≤ 4.1k).")

    two_springs = "Max(0, u - 1/4) - 2*Max(0, -u - 1/2)"
    exact_two = _median_of("expand", {"f": two_springs, "order": 4, "mode": "exact"}, runs, 900)
    float_two = _median_of("expand", {"f": two_springs, "order": 4, "mode": "float"}, runs, 300)
    u = sympy.Symbol("u")
    reference_two = frequency_taylor_coefficients(sympy.Max(0, u - sympy.Rational(1, 4)) - 2 * sympy.Max(0, -u - sympy.Rational(1, 2)),
                                                  4, a0=1, precision=40)
    error_two, estimate_two = (_relative_errors(exact_two["omega"], reference_two) if exact_two["status"] == "ok" else (None, None))
    raw["two_springs"] = {"exact": exact_two, "float": float_two, "error": error_two, "estimate": estimate_two}
    ratio_two = exact_two.get("seconds", math.nan) / float_two.get("seconds", math.nan)
    summary.append(("two springs, exact, order 4", _t(exact_two.get("seconds")), _t(float_two.get("seconds")) + " (float mode)",
                    f"{ratio_two:.0f}× float mode", _verdict(exact_two.get("seconds", math.inf) <= 2 and error_two is not None
                                                            and error_two <= 10 * max(estimate_two, 1e-40))))
    parts.append(f"**Two springs** `{two_springs}`, order 4: exact {_t(exact_two.get('seconds'))} (median of {runs}), float mode "
                 f"{_t(float_two.get('seconds'))}; ω_1…ω_4 against `frequency_taylor_coefficients` (quadrature of the exact "
                 f"period, 40 digits): {_e(error_two)} relative (its estimate {_e(estimate_two)}). Target ≤ 2 s.")

    # -- 3. evaluations ----------------------------------------------------------------------------------------
    kappas = ["3/10", "-7/10", "999/1000", "1/7"]
    numeric = {precision: _call("numeric-kappa", {"kappas": kappas, "precision": precision}, 600) for precision in (16, 30)}
    raw["numeric_kappa"] = numeric
    reference_by_kappa = {k: piecewise_linear_frequency_taylor(4, a=1, b=sympy.Rational(k), a0=1, precision=45) for k in kappas}
    lines = ["| κ | precision=16: time | error (rel. to max ω_k) | precision=30: time | error |", "| --- | ---: | ---: | ---: | ---: |"]
    worst: dict[int, tuple[float, float]] = {}
    for index, kappa in enumerate(kappas):
        cells = [kappa]
        for precision in (16, 30):
            result = numeric[precision]
            if result["status"] != "ok":
                cells += [result["status"], "—"]
                continue
            row = result["rows"][index]
            error, _ = _relative_errors(row["omega"], reference_by_kappa[kappa])
            seconds, previous = row["seconds"], worst.get(precision, (0.0, 0.0))
            worst[precision] = (max(previous[0], seconds), max(previous[1], error))
            cells += [_t(seconds), _e(error)]
        lines.append("| " + " | ".join(cells) + " |")
    floor_numeric = numeric[16].get("floor_seconds")
    compiled_worst = (0.0, 0.0)
    compiled_lines = ["| κ (the double nearest) | `frequency_coefficients` time | error (rel. to max ω_k) |", "| --- | ---: | ---: |"]
    for row in numeric[16].get("compiled", []):
        reference = piecewise_linear_frequency_taylor(4, a=1, b=sympy.Float(float(row["double"]), 30), a0=1, precision=45)
        error, _ = _relative_errors(row["omega"], reference)
        compiled_worst = (max(compiled_worst[0], row["seconds"]), max(compiled_worst[1], error))
        compiled_lines.append(f"| {row['kappa']} | {_t(row['seconds'])} | {_e(error)} |")
    summary.append(("ω1…ω4 at a new κ from the compiled symbolic-κ expansion", _t(compiled_worst[0]), _t(floor_numeric) + " (lambdified closed form)",
                    f"{compiled_worst[0] / floor_numeric:.0f}×; error {_e(compiled_worst[1])}",
                    _verdict(compiled_worst[0] <= 1e-3 and compiled_worst[1] <= 1e-14)))
    cauchy_4 = {precision: _call("cauchy", {"order": 4, "precision": precision, "kappas": kappas}, 300) for precision in (16, 30)}
    raw["cauchy_order_4"] = cauchy_4  # the general reference function, timed for comparison only (not the floor)
    floor_4 = {precision: _call("numeric-floor", {"order": 4, "precision": precision, "kappas": kappas}, 300) for precision in (16, 30)}
    raw["numeric_floor_order_4"] = floor_4
    floor_lines = ["| precision | measured (worst κ) | floor r = R/4 (worst κ) | ratio | floor r = R/10⁷ (worst κ) | ratio | "
                   "floors vs reference (rel.) | `piecewise_linear_frequency_taylor` (worst κ, not a floor) |",
                   "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for precision in (16, 30):
        if precision in worst and floor_4[precision]["status"] == "ok":
            quarter, cheapest = floor_4[precision]["quarter"], floor_4[precision]["cheapest"]
            agrees = quarter["agrees"] and cheapest["agrees"]
            ratio_quarter, ratio_cheapest = worst[precision][0] / quarter["worst"], worst[precision][0] / cheapest["worst"]
            general = _t(cauchy_4[precision]["worst"]) if cauchy_4[precision]["status"] == "ok" else cauchy_4[precision]["status"]
            floor_lines.append(f"| {precision} | {_t(worst[precision][0])} | {_t(quarter['worst'])} | {ratio_quarter:.1f}× | "
                               f"{_t(cheapest['worst'])} | {ratio_cheapest:.1f}× | "
                               f"{_e(max(quarter['relative_error'], cheapest['relative_error']))}{'' if agrees else ' (NOT to the digits)'} | {general} |")
            # judged as the issue states it: against the audit's same-digit floor (the Cauchy integral of the exact
            # period on r = R/4); the cheapest rule found (6 nodes on r = R/10⁷) is shown beside it, not judged
            summary.append((f"numeric ω1…ω4 at a new κ (precision={precision}), against the same-digit Cauchy floor of the audit",
                            _t(worst[precision][0]), _t(quarter["worst"]) + f" (Cauchy integral of the exact period, {precision} "
                            "digits, r = R/4 as in the issue's audit)", f"{ratio_quarter:.1f}×", _verdict(ratio_quarter <= 1 and agrees)))
            summary.append((f"numeric ω1…ω4 at a new κ (precision={precision}), against the cheapest Cauchy rule found",
                            _t(worst[precision][0]), _t(cheapest["worst"]) + " (6 nodes on r = R/10⁷, 60–70 working digits)",
                            f"{ratio_cheapest:.1f}×", "— (shown)"))
    if 16 in worst:
        summary.append(("numeric ω1…ω4 at a new κ (precision=16)", _t(worst[16][0]), _t(floor_numeric) + " (compiled closed form)",
                        f"{worst[16][0] / floor_numeric:.0f}× the closed form", _verdict(worst[16][0] <= 1e-3 and worst[16][1] <= 1e-14)))
    parts.append("### 3. Evaluations\n\n**`numeric=True` at a κ new to a warm process** (`expand(\"Max(0, u - kappa)\", order=4, "
                 "params={\"kappa\": K}, numeric=True, precision=P).omega` after one call at κ = 1/3). Floor: the symbolic "
                 f"ω_1…ω_4(κ) lambdified once with `math` and called per κ: {_t(floor_numeric)}. Reference: "
                 "`piecewise_linear_frequency_taylor` at 45 digits.\n\n" + "\n".join(lines) + "\n\nTarget: ≤ 1 ms at 1e-14. "
                 "The float-mode engine re-derives the hierarchy for every κ (parsing, the piecewise decomposition and four "
                 "orders in mpmath floats): it is the route for one κ at high precision. For many κ the same numbers come "
                 "from the symbolic-κ expansion derived once and compiled (`Expansion.frequency_coefficients`, float64 with "
                 "a rounding bound; reference at the exact value of each double):\n\n" + "\n".join(compiled_lines)
                 + "\n\n**The same-digit floor of `numeric=True`** (`cauchy_gap_coefficients_mp` in this file, warm, per κ): ω_0…ω_4 "
                 "of the same problem, each to P significant digits, by the Cauchy integral of its exact closed-form period in mpmath "
                 "on a circle r = R/ρ inside the nearest singularity R = min(1, (1 + κ)/(1 − κ)), ⌈D/log10 ρ⌉ nodes (half of them "
                 "by conjugate symmetry) at D + 4·log10 ρ working digits, D = P + 3 + the digits by which the smallest ω_k falls "
                 "below R^−k; ρ = 4 is the radius of the float64 floor and of the issue's audit, ρ = 10⁷ (5–6 nodes, 60–70 digits) "
                 "the cheapest of ρ = 2.5, 4, 10, 100, 10⁴, 10⁷ (measured 13, 8.4, 5.3, 2.7, 1.5, 1.0 ms at 30 digits). The target "
                 "is judged against the audit's rule (ρ = 4), as the issue states it; the cheapest rule is shown beside it: "
                 "the engine derives the general hierarchy (any piecewise-polynomial law, its waveforms too) in mpmath "
                 "element arithmetic, the rule evaluates this one law's closed-form period at six points. "
                 "Each checked against `piecewise_linear_frequency_taylor` at P + 15 digits; that general reference "
                 "(node doubling from 32 until two rules agree) is timed in the last column for comparison only.\n\n"
                 + "\n".join(floor_lines))

    evaluation = {f: _call("evaluation", {"f": f}, 600) for f in ("u**3", "Max(0, u - 3/10)")}
    raw["evaluation"] = evaluation
    lines = ["| expansion (order 4) | first `.frequency(ε)` | warm `.frequency(ε)` | lambdified | ratio |", "| --- | ---: | ---: | ---: | ---: |"]
    for f, result in evaluation.items():
        ratio = result.get("warm", math.nan) / result.get("lambdified", math.nan)
        lines.append(f"| `{f}` | {_t(result.get('first'))} | {_t(result.get('warm'))} | {_t(result.get('lambdified'))} | {ratio:.2g}× |")
    spring = evaluation["Max(0, u - 3/10)"]
    summary.append(("`Expansion.frequency(ε)` per call", _t(spring.get("warm")), _t(spring.get("lambdified")) + " (lambdify)",
                    f"{spring.get('warm', math.nan) / spring.get('lambdified', math.nan):.2g}×", _verdict(spring.get("warm", math.inf) <= 2e-6)))
    summary.append(("first `.frequency(ε)` on the exact order-4 spring", _t(spring.get("first")), "—", "—",
                    _verdict(spring.get("first", math.inf) <= 0.05)))
    parts.append("**`Expansion.frequency(ε)`** (ε = 0.01), against `expansion.lambdify(\"frequency\")` in the same process.\n\n"
                 + "\n".join(lines) + "\n\nTargets: ≤ 2 µs per call; first call ≤ 50 ms.")

    grid = [f"{n}/40" for n in range(-38, 39, 2)]  # 39 values of κ in [−0.95, 0.95], each new to the process
    new_kappa = {order: _call("new-kappa", {"order": order, "kappas": grid}, 900) for order in (2, 3)}
    raw["new_kappa"] = new_kappa
    lines = ["| symbolic-κ expansion | first evaluation (compiles) | then each new κ: median | slowest 10 % | worst | "
             "lambdified ω(ε; κ) | median / lambdified | values agree with lambdified (1e-13) |",
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |"]
    slowest = 0.0
    for order, result in new_kappa.items():
        times = sorted(result.get("times", [math.nan]))
        median, tail, worst_time = statistics.median(times), times[int(0.9 * len(times))], times[-1]
        slowest = max(slowest, median)
        agree = result["status"] == "ok" and all(abs(a - b) <= 1e-13 * abs(b) for a, b in zip(result["values"], result["reference"]))
        lines.append(f"| order {order} | {_t(result.get('first'))} | {_t(median)} | {_t(tail)} | {_t(worst_time)} | "
                     f"{_t(result.get('lambdified'))} | {median / result.get('lambdified', math.nan):.0f}× | {'yes' if agree else 'NO'} |")
    coefficient_lines = ["| symbolic-κ expansion | `frequency_coefficients` at a new κ: median | worst | float64 Cauchy floor "
                         "(median) | median / floor | max \\|difference\\| |", "| --- | ---: | ---: | ---: | ---: | ---: |"]
    worst_ratio = 0.0
    for order, result in new_kappa.items():
        times = result.get("coefficient_times", [math.nan])
        ratio = statistics.median(times) / result.get("cauchy", math.nan)
        worst_ratio = max(worst_ratio, ratio) if not math.isnan(ratio) else math.inf
        coefficient_lines.append(f"| order {order} | {_t(statistics.median(times))} | {_t(max(times))} | {_t(result.get('cauchy'))} | "
                                 f"{ratio:.2g}× | {_e(result.get('cauchy_difference'))} |")
    summary.append(("`frequency_coefficients` at a new κ (orders 2, 3; median over 39 κ)",
                    _t(max(statistics.median(r.get("coefficient_times", [math.nan])) for r in new_kappa.values())),
                    _t(new_kappa[3].get("cauchy")) + " (float64 Cauchy)", f"{worst_ratio:.2g}×", _verdict(worst_ratio <= 3)))
    summary.append(("a new κ on a symbolic-κ expansion (orders 2, 3; median over 39 κ)", _t(slowest),
                    _t(new_kappa[3].get("lambdified")) + " (lambdified)",
                    f"{slowest / new_kappa[3].get('lambdified', math.nan):.0f}×",
                    _verdict(all(statistics.median(r.get("times", [math.inf])) <= 5 * r.get("lambdified", 0.0)
                                 and max(r.get("times", [math.inf])) <= 5e-3 for r in new_kappa.values()))))
    parts.append("**A new κ on a symbolic-κ expansion**: after one evaluation at κ = 1/3 (which compiles the closed forms), "
                 "each of 39 κ in [−0.95, 0.95] new to the process. The compiled closed forms carry a rounding bound; where it "
                 "exceeds 1e-13 of ω_k (near κ = ±1, where the closed form cancels, and near a root of ω_k) the value comes "
                 "from the coefficient's stable series, generated in the first evaluation for every ω_k that fails the bound "
                 "on the parameter grid; the range of ε is judged from a table of the quiet radius made in the same first "
                 "evaluation (it accepts |ε| below at most half the radius, see lindstedt/results/_evaluators.py), and by the "
                 "orbit's range at κ only where the table cannot tell (here κ ≤ −0.8 and κ = 0.95 at ε = 0.05, κ = −0.95 "
                 "a warning): "
                 "those are the slowest calls.\n\n" + "\n".join(lines)
                 + "\n\nTarget (issue 26): median ≤ 5× the lambdified closed form; worst ≤ 5 ms after the first call.\n\n"
                 "**`frequency_coefficients` at a new κ** (the same expansions, at each κ + 2^−30: new again), against the "
                 "float64 floor that returns the same numbers: the Cauchy integral of the exact period on 32 nodes, one FFT "
                 "(`cauchy_gap_coefficients` in this file), timed per κ (best of 3 loops) and the median over κ taken; the "
                 "difference column is the largest |ω_k − ω_k^Cauchy|: the floor's own error (against the 30-digit reference "
                 "~1e-15, but 2e-10 at κ = −0.95, order 3, where the circle shrinks to r = 0.0064 and rounding grows as "
                 "r^−k; the compiled values are within 6e-17 there).\n\n"
                 + "\n".join(coefficient_lines) + "\n\nTarget (issue 26): ≤ 3× the float64 Cauchy floor.")

    # -- 4. N dof ----------------------------------------------------------------------------------------------
    sizes = [20, 80, 200] if quick else [20, 80, 200, 500, 1000]
    runs_of = (lambda size: 1 if size >= 500 else runs)
    nnm_rows = []
    for size in sizes:
        for mode in (1, size):
            result = _median_of("nnm", {"size": size, "mode": mode}, runs_of(size), 900)
            nnm_rows.append({"size": size, "mode": mode, "kind": "springs", "result": result})
    # any law: the Hertz contact engaged (gap 1/100 below the mode's amplitude there) and the cubic spring
    for size in ([20] if quick else [20, 40, 80]):
        result = _median_of("nnm", {"size": size, "mode": 1, "laws": True}, 1, 900)
        nnm_rows.append({"size": size, "mode": 1, "kind": "laws", "result": result})
    for size in ([200] if quick else [200, 1000, 2000]):
        result = _median_of("nnm", {"size": size, "mode": 1, "laws": True, "reduce": 8}, 1, 900)
        nnm_rows.append({"size": size, "mode": 1, "kind": "reduced", "result": result})
    raw["nnm"] = nnm_rows
    kinds = {"springs": "3 unilateral springs", "laws": "+ Hertz + cubic, all modes",
             "reduced": "+ Hertz + cubic, `ResidualFlexibility(8)` (time included)"}
    lines = ["| N | elements | mode | time (order 2, 30 digits) | memory over the baseline | ω_1 | ω_2 |",
             "| ---: | --- | ---: | ---: | ---: | ---: | ---: |"]
    for row in nnm_rows:
        result = row["result"]
        if result["status"] == "ok":
            omega = result["omega"]
            lines.append(f"| {row['size']} | {kinds[row['kind']]} | {row['mode']} | {_t(result.get('seconds'))} | "
                         f"{result.get('memory_mb', math.nan):.0f} MB | {omega[1]:.9g} | {omega[2]:.9g} |")
        else:
            lines.append(f"| {row['size']} | {kinds[row['kind']]} | {row['mode']} | {result['status']} | — | — | — |")
    def target_size(chosen: list[dict]) -> int:
        """The issue's size, N = 1000, where a kind has it (larger rows are shown, not judged), else its largest."""
        sizes_run = {r["size"] for r in chosen}
        return 1000 if 1000 in sizes_run else max(sizes_run)

    fits = {}
    for kind in kinds:
        chosen = [r for r in nnm_rows if r["mode"] == 1 and r["kind"] == kind]
        top = [r for r in chosen if target_size(chosen) // 5 <= r["size"] <= target_size(chosen)] if chosen else []
        fits[kind] = _power_fit([r["size"] for r in top], [r["result"].get("seconds") for r in top])  # 200…1000
    for kind in kinds:
        chosen = [r for r in nnm_rows if r["kind"] == kind]
        if not chosen:
            continue
        size = target_size(chosen)
        last = [r for r in chosen if r["size"] == size]
        seconds = max(r["result"].get("seconds", math.inf) for r in last)
        memory = max(r["result"].get("memory_mb", math.inf) for r in last)
        verdict = _verdict(seconds <= 2 and memory <= 150) if size == 1000 else "—"
        summary.append((f"`nnm`, chain of {size} dof, {kinds[kind]}, order 2 (slowest mode)", f"{_t(seconds)}, {memory:.0f} MB",
                        "—", "—", verdict))
        if fits[kind] is not None:
            sizes_fitted = sorted({r["size"] for r in chosen if size // 5 <= r["size"] <= size})
            summary.append((f"`nnm` growth, {kinds[kind]}, N = {sizes_fitted[0]}…{size}", f"N^{fits[kind]:.2f}", "—", "—",
                            _verdict(fits[kind] <= 1.2)))
    growth = "; ".join(f"{kinds[kind]} ∝ N^{fit:.2f}" for kind, fit in fits.items() if fit is not None)
    parts.append(f"### 4. N degrees of freedom\n\n`lindstedt.nnm(chain(N, springs {CHAIN_SPRINGS}), mode, a0=1, order=2)`; "
                 f"the second and third kinds add the elements {CHAIN_LAWS} (the Hertz contact engaged around the "
                 "release point for every N). Wall time after the imports; memory = peak resident set over the baseline "
                 "after the imports and the system's construction.\n\n"
                 + "\n".join(lines) + f"\n\nGrowth (mode 1, fitted from N/5 to N = 1000, or to the largest N of a kind without 1000; the 2000-dof reduced row is shown, not judged): {growth}. Targets (issue 26): N = 1000 ≤ 2 s and "
                 "≤ 150 MB over the import baseline, growth ≤ N^1.2 between 200 and 1000, the same with any law. "
                 "With all modes, a Hertz contact arc carries every modal component in stretched time on one Chebyshev grid, "
                 "which must resolve cos(β r_k τ) of the stiffest component (r_N ≈ 2N/π for the chain): O(N) components "
                 "on O(N) nodes, so the arc grows like N² and dominates beyond ~100 dof (the rest of the order solve is "
                 "O(N · elements): the shared right-hand sides c·W and element forces are solved term by term for every "
                 "component) — the reduced model keeps K + m components. "
                 "ω_2 of mode 1 grows and changes sign with N: in a long chain λ_2/λ_1 → 2, so the small divisor "
                 "r_2² − 2² of the second harmonic (which the one-sided springs excite) shrinks like 1/N² "
                 "(2.4e-4 at N = 200, 9.8e-6 at N = 1000): a near 1:2 internal resonance, and the expansion's range in ε "
                 "shrinks with it.")

    # order 3 with the element laws on every mode: shown, not judged (no target; issue 26's rows are order 2)
    third = [(size, _median_of("nnm", {"size": size, "mode": 1, "laws": True, "order": 3}, 1, 900))
             for size in ([20] if quick else [20, 40, 80])]
    raw["nnm_order_3"] = [{"size": size, "result": result} for size, result in third]
    fit_third = _power_fit([size for size, _ in third], [result.get("seconds") for _, result in third]) if len(third) > 2 else None
    parts.append("**Order 3, the same chain with every mode** (`order=3`; shown, not judged): the order-3 forcing of an "
                 "element holds the products of its order-1 deformations, whose O(N) frequencies r_k make O(N²) combination "
                 "tones r_k ± r_l, each solved for every component: "
                 + ", ".join(f"{size} dof {_t(result.get('seconds'))}" if result["status"] == "ok" else f"{size} dof {result['status']}"
                             for size, result in third)
                 + (f" (growth N^{fit_third:.2f} over 20…80)" if fit_third is not None else "") + "; the reduced model is the route "
                 "beyond tens of dof.")

    continuation = _call("continuation", {"size": 20, "mode": 1, "start": 0.0, "stop": 0.3, "modal_amplitude": 1.0,
                                          "max_points": 200}, 900)
    raw["continuation"] = continuation
    met = continuation.get("success") and continuation.get("points", math.inf) <= 60 and (continuation.get("reached") or 0) >= 0.3 - 1e-12
    summary.append(("continuation, 20-dof chain, 3 springs, mode 1", f"ε = {continuation.get('reached')} in {continuation.get('points')} points",
                    "—", "—", _verdict(bool(met))))
    parts.append("**Continuation** `continue_nnm(chain(20), 1, start=0, stop=0.3, modal_amplitude=1)`: "
                 f"{continuation.get('points')} points ({continuation.get('jumps')} jumps across resonance tongues), {continuation.get('flows')} flows, {continuation.get('rejected')} rejected steps, "
                 f"{_t(continuation.get('seconds'))}; reached ε = {continuation.get('reached')}; success {continuation.get('success')} "
                 f"({continuation.get('message')}). Target: ε = 0.3 in ≤ 60 points.")

    # -- 5. start-up ---------------------------------------------------------------------------------------------
    count = 3 if quick else 7
    startup = {
        "floor": _whole_process("import sympy, numpy, mpmath", count),
        "import": _whole_process("import lindstedt", count),
        "help": _whole_process("import contextlib, io, lindstedt.cli\nwith contextlib.suppress(SystemExit), "
                               "contextlib.redirect_stdout(io.StringIO()): lindstedt.cli.main(['--help'])", count),
        "bare": _whole_process("pass", count),
    }
    raw["startup"] = startup
    median = {name: statistics.median(values) for name, values in startup.items()}
    summary.append(("`import lindstedt` (whole process)", _t(median["import"]), _t(median["floor"]) + " (import sympy, numpy, mpmath)",
                    f"{median['import'] / median['floor']:.2f}×", _verdict(median["import"] <= 0.4)))
    summary.append(("`lindstedt --help` (whole process)", _t(median["help"]), _t(median["bare"]) + " (bare interpreter)",
                    f"{median['help'] / median['bare']:.2f}×", _verdict(median["help"] <= 0.3)))
    parts.append(f"### 5. Start-up (whole processes, median of {count})\n\n| process | median | min | max |\n| --- | ---: | ---: | ---: |\n" +
                 "\n".join(f"| {label} | {_t(median[name])} | {_t(min(startup[name]))} | {_t(max(startup[name]))} |" for name, label in
                           (("bare", "`python -c pass`"), ("floor", "`import sympy, numpy, mpmath`"), ("import", "`import lindstedt`"),
                            ("help", "`lindstedt --help` (main(['--help']))"))))

    raw["load_end"] = load_average()
    write_json(RAW_NAME, raw)
    table = ["| work | measured | floor / peer (same run) | ratio | target |", "| --- | --- | --- | --- | --- |"]
    table += [f"| {a} | {b} | {c} | {d} | {e} |" for a, b, c, d, e in summary]
    missed = [a for a, *_, e in summary if "MISSED" in e]
    head = (f"## {TITLE}\n\nProtocol: `benchmarks/bench_performance.py` (docstring); every measurement in a fresh interpreter. "
            f"Load average at start {load_start}, at end {raw['load_end']} (2 cores; load above 2 slows every row). "
            f"Raw data: `results/{RAW_NAME}`. This section took {time.perf_counter() - started:.0f} s.\n\n" + "\n".join(table) +
            ("\n\nTargets missed in this run: " + "; ".join(missed) + "." if missed else "\n\nEvery target met in this run."))
    return head + "\n\n" + "\n\n".join(parts) + "\n"


def main(argv: list[str] | None = None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] == "--worker":
        WORKERS[argv[1]](json.loads(argv[2]))
        return
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer sizes and repeats")
    print(run(quick=parser.parse_args(argv).quick))


if __name__ == "__main__":
    main()
