"""Benchmark (issue 12): piecewise-polynomial contact laws — time to ω4 per class, accuracy, and harmonic balance.

Two measurements, every timing in fresh interpreters (this file doubles as its own worker: ``python -I
bench_contact_laws.py --worker TASK JSON`` prints one ``@@BENCH-RESULT {json}`` line; the worker puts this
file's repository first on ``sys.path``, so it measures the tree the benchmark lives in, whatever lindstedt the
venv has installed):

1. One row per class of law f in ``u'' + u + ε f(u) = 0``, ``u(0) = a0``, ``u'(0) = 0``: the time to ω_0…ω_4
   in exact mode and in float mode (``numeric=True, precision=30``), each a fresh process (imports excluded,
   median over several processes), and the accuracy of ω_1…ω_4 against
   ``lindstedt.references.frequency_taylor_coefficients`` (Taylor coefficients of the exact period's frequency,
   40 digits, with its own error estimate).
2. Harmonic balance (HB) against the truncated series for ``(u)_+²`` and ``(u − 1/3)_+²`` at ε = 0.1, 0.3,
   a0 = 1: a standard autonomous HB with alternating frequency–time (AFT), written here (see
   :func:`hb_system`), H = 1…256 harmonics, solved by Newton and by ``scipy.optimize.root``; and the series
   Σ_{k≤N} ω_k ε^k, N = 1…8. Errors against the exact frequency
   (``lindstedt.references.conservative_frequency``, checked by an own two-arc quadrature here).

Standalone: ``python benchmarks/bench_contact_laws.py [--quick]`` prints the markdown section.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time
from fractions import Fraction
from itertools import pairwise
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import (
    BENCH_DIR,
    REPO_DIR,
    load_average,
    run_worker,
    write_json,
)
from _common import loglog_figure  # noqa: E402
from _common import emit as _emit, format_error as _e, format_seconds as _t, per_call as _warm  # noqa: E402

TITLE = "Contact laws (issue 12): time to ω4 per class, accuracy, and harmonic balance against the series"
SELF = Path(__file__).resolve()
FIGURES_DIR = BENCH_DIR / "figures"
RAW_NAME = "contact_laws.json"

#: one row per class: (label, f as given to lindstedt.expand, a0 as an exact rational string)
CLASSES: list[dict[str, str]] = [
    {"label": "(u)₊² — one-sided quadratic contact, kink at rest", "f": "Max(0, u)**2", "a0": "1"},
    {"label": "(u − 1/3)₊² — quadratic contact with a gap", "f": "Max(0, u - 1/3)**2", "a0": "1"},
    {"label": "u\\|u\\| — two-sided quadratic", "f": "u*Abs(u)", "a0": "1"},
    {"label": "H(u − 1/2) u² — a law that jumps", "f": "Heaviside(u - 1/2)*u**2", "a0": "1"},
    {"label": "H(u − 1/3) — a pure jump", "f": "Heaviside(u - 1/3)", "a0": "1"},
    {"label": "Piecewise, 3 polynomial pieces (continuous, slope jumps at ±1/2)",
     "f": "Piecewise((-u**2/2, u < -1/2), (u**3, u < 1/2), (u/4, True))", "a0": "1"},
    {"label": "polynomial + contact: u³ + (u − 1/3)₊²", "f": "u**3 + Max(0, u - 1/3)**2", "a0": "1"},
    {"label": "Hertz (u)₊^{3/2} — stretched arc (numeric in both modes)", "f": "Max(0, u)**(3/2)", "a0": "1"},
    {"label": "Hertz with a gap (u − 1/5)₊^{3/2}", "f": "Max(0, u - 1/5)**(3/2)", "a0": "1"},
    {"label": "two-sided Hertz with a clearance (u − 1/5)₊^{3/2} + (−u − 1/5)₊^{3/2}",
     "f": "Max(0, u - 1/5)**(3/2) + Max(0, -u - 1/5)**(3/2)", "a0": "1"},
    {"label": "analytic contact law (u − 1/5)₊ eᵘ — stretched arc", "f": "Max(0, u - 1/5)*exp(u)", "a0": "1"},
    {"label": "analytic, pole at u = 1 (orbit reaches 0.99)", "f": "1/(1-u) - 1 - u", "a0": "99/100"},
    {"label": "analytic, branch point at u = −1 (orbit reaches ≈ −0.95)", "f": "log(1+u) - u", "a0": "95/100"},
]
ORDER = 4
FLOAT_PRECISION = 30
REFERENCE_PRECISION = 40  # digits asked of frequency_taylor_coefficients (the brief's value)
CLASS_TIMEOUT = 60.0  # seconds per fresh process (interpreter + import + expansion)

#: part 2: the laws for the HB comparison, as the gap κ of (u − κ)₊²
HB_LAWS = ["0", "1/3"]
HB_EPS = [0.1, 0.3]
EXACT_DPS = 60  # digits of the exact frequency at each ε
PLOT_FLOOR = 1e-17

FULL = {"class_repeats": 3, "hb_laws": HB_LAWS, "hb_eps": HB_EPS,
        "harmonics": [1, 2, 4, 8, 16, 32, 64, 128, 256], "oversampling": [4, 32], "hybr_oversampling": 4,
        "hb_repeats": 5,
        # (κ, mode) -> (orders, fresh processes per order)
        "series": {("0", "float"): (list(range(1, 9)), 3), ("0", "exact"): (list(range(1, 9)), 3),
                   ("1/3", "float"): (list(range(1, 9)), 3), ("1/3", "exact"): (list(range(1, 7)), 1)}}
QUICK = {"class_repeats": 1, "hb_laws": ["0"], "hb_eps": HB_EPS,
         "harmonics": [1, 2, 4, 8, 16], "oversampling": [4, 32], "hybr_oversampling": 4, "hb_repeats": 2,
         "series": {("0", "float"): ([1, 2, 3, 4], 1), ("0", "exact"): ([1, 2, 3, 4], 1)}}


def _log(message: str) -> None:
    print(f"[contact-laws] {message}", file=sys.stderr, flush=True)


def _law(kappa: str) -> str:
    return "Max(0, u)**2" if Fraction(kappa) == 0 else f"Max(0, u - {kappa})**2"


def _law_label(kappa: str) -> str:
    return "(u)₊²" if Fraction(kappa) == 0 else f"(u − {kappa})₊²"


# =================================================================================================================
# harmonic balance with alternating frequency–time (written here; no lindstedt)
# =================================================================================================================
#
# ω² u'' + u + ε f(u) = 0 in τ = ωt, 2π-periodic, even (release from rest): u(τ) = Σ_{k=0}^{H} c_k cos kτ.
# Unknowns z = (ω, c_0, …, c_H); equations: the Galerkin projections on cos kτ, k = 0…H,
#     r_k = (1 − k² ω²) c_k + ε F_k = 0,     F_k = cosine coefficient k of f(u(τ)),
# and the release point Σ c_k = u(0) = a0 (the phase is fixed by the cosine ansatz, the amplitude by a0).
# AFT: u at N equispaced τ_n by an inverse real FFT, f(u_n) sampled there, F_k from a real FFT (the trapezoid
# rule, exact for trigonometric polynomials of degree < N − H). Jacobian by the same FFT: with
#     D_m = (1/N) Σ_n f'(u_n) cos(m τ_n),    ∂F_k/∂c_j = w_k (N/2) (D_{|k−j|} + D_{k+j}),
# w_0 = 1/N, w_k = 2/N (k ≥ 1); needs k + j ≤ 2H < N, i.e. N ≥ 4H is plenty. Start: the linear solution
# ω = 1, c_1 = a0.

def hb_system(epsilon: float, harmonics: int, samples: int, kappa: float, a0: float = 1.0):
    """Residual and Jacobian ``z -> (r, J)`` of the AFT harmonic balance of ``u'' + u + ε (u − κ)₊² = 0``."""
    import numpy as np

    H, N = harmonics, samples
    k = np.arange(H + 1)
    k2 = (k * k).astype(float)
    weights = np.full(H + 1, 2.0 / N)
    weights[0] = 1.0 / N
    minus = np.abs(k[:, None] - k[None, :])
    plus = (k[:, None] + k[None, :]) % N
    scale = weights[:, None] * (N / 2)
    spectrum = np.zeros(N // 2 + 1)

    def function(z):
        omega, c = z[0], z[1:]
        spectrum[0] = c[0] * N
        spectrum[1:H + 1] = c[1:] * (N / 2)
        x = np.fft.irfft(spectrum, n=N)  # u(τ_n)
        d = np.maximum(x - kappa, 0.0)
        forcing = np.fft.rfft(d * d).real[:H + 1] * weights  # F_k
        half = np.fft.rfft(2.0 * d).real / N  # D_m, m = 0…N/2 (f'(u) is even in τ: a cosine series)
        full = np.concatenate([half, half[1:N - half.size + 1][::-1]])  # D_m for m = 0…N−1
        residual = np.empty(H + 2)
        residual[:H + 1] = (1.0 - k2 * omega * omega) * c + epsilon * forcing
        residual[H + 1] = c.sum() - a0
        jacobian = np.zeros((H + 2, H + 2))
        jacobian[:H + 1, 0] = -2.0 * omega * k2 * c
        jacobian[:H + 1, 1:] = epsilon * scale * (full[minus] + full[plus])
        jacobian[np.arange(H + 1), np.arange(1, H + 2)] += 1.0 - k2 * omega * omega
        jacobian[H + 1, 1:] = 1.0
        return residual, jacobian

    return function


def hb_start(harmonics: int, a0: float = 1.0):
    import numpy as np

    z = np.zeros(harmonics + 2)
    z[0], z[2] = 1.0, a0
    return z


def hb_newton(epsilon: float, harmonics: int, samples: int, kappa: float, tol: float = 1e-14,
              max_iterations: int = 40) -> tuple[float, int, bool]:
    """Newton on :func:`hb_system` from the linear solution; stops when the step is ≤ tol (max norm)."""
    import numpy as np

    function = hb_system(epsilon, harmonics, samples, kappa)
    z = hb_start(harmonics)
    for iteration in range(1, max_iterations + 1):
        residual, jacobian = function(z)
        step = np.linalg.solve(jacobian, -residual)
        z += step
        if float(np.max(np.abs(step))) <= tol:
            return float(z[0]), iteration, True
    return float(z[0]), max_iterations, False


def hb_hybr(epsilon: float, harmonics: int, samples: int, kappa: float) -> tuple[float, int, bool]:
    """``scipy.optimize.root(method="hybr")`` (MINPACK Powell hybrid) with the AFT Jacobian, xtol 1e-13."""
    from scipy.optimize import root

    solution = root(hb_system(epsilon, harmonics, samples, kappa), hb_start(harmonics), jac=True, method="hybr",
                    options={"xtol": 1e-13})
    return float(solution.x[0]), int(solution.nfev), bool(solution.success)


# =================================================================================================================
# workers (fresh interpreters)
# =================================================================================================================
def _worker_expand(spec: dict[str, Any]) -> None:
    """One expansion to ``order`` of ``f`` in a fresh process: time (imports excluded), ω_k to 50 digits."""
    sys.path.insert(0, str(REPO_DIR))  # measure this tree, not whatever the venv has installed
    load = load_average()
    start = time.perf_counter()
    import sympy

    import lindstedt

    import_seconds = time.perf_counter() - start
    kwargs: dict[str, Any] = {"order": spec["order"], "a0": sympy.Rational(spec["a0"]), "omega0": 1}
    if spec["mode"] == "float":
        kwargs.update(numeric=True, precision=FLOAT_PRECISION)
    start = time.perf_counter()
    expansion = lindstedt.expand(spec["f"], **kwargs)
    omega = expansion.omega
    seconds = time.perf_counter() - start
    out: dict[str, Any] = {
        "seconds": seconds, "import_seconds": import_seconds, "load": load,
        "lindstedt_file": str(Path(lindstedt.__file__).resolve()),
        "omega": [str(sympy.N(w, 50)) for w in omega],
        "kind": "closed form" if not any(sympy.sympify(w).atoms(sympy.Float) for w in omega) else "floats (no closed form)",
    }
    if spec["mode"] == "exact":
        out["count_ops_last"] = int(sympy.count_ops(omega[-1]))
    if spec.get("eps"):
        floats = [float(w) for w in omega]

        def horner(epsilon: float) -> float:
            value = 0.0
            for coefficient in reversed(floats):
                value = value * epsilon + coefficient
            return value

        out["horner"] = {}
        for epsilon in spec["eps"]:
            t, value = _warm(lambda epsilon=epsilon: horner(epsilon), 5)
            out["horner"][repr(epsilon)] = {"seconds": t, "value": repr(value)}
    _emit(out)


def _worker_hb(spec: dict[str, Any]) -> None:
    """All HB solves in one process (one thread for BLAS, as the series side is single-threaded)."""
    for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[name] = "1"
    load = load_average()
    import numpy as np
    import scipy

    hb_newton(0.2, 8, 32, 0.25)  # warm the code paths (another problem)
    hb_hybr(0.2, 8, 32, 0.25)
    rows = []
    for kappa in spec["laws"]:
        k = float(Fraction(kappa))
        for epsilon in spec["eps"]:
            for harmonics in spec["harmonics"]:
                for oversampling in spec["oversampling"]:
                    samples = oversampling * harmonics
                    seconds, (value, iterations, converged) = _warm(
                        lambda e=epsilon, h=harmonics, n=samples, b=k: hb_newton(e, h, n, b), spec["repeats"])
                    rows.append({"kappa": kappa, "eps": epsilon, "H": harmonics, "N": samples, "solver": "newton",
                                 "seconds": seconds, "omega": repr(value), "iterations": iterations,
                                 "converged": converged})
                samples = spec["hybr_oversampling"] * harmonics
                seconds, (value, evaluations, converged) = _warm(
                    lambda e=epsilon, h=harmonics, n=samples, b=k: hb_hybr(e, h, n, b), spec["repeats"])
                rows.append({"kappa": kappa, "eps": epsilon, "H": harmonics, "N": samples, "solver": "hybr",
                             "seconds": seconds, "omega": repr(value), "iterations": evaluations,
                             "converged": converged})
    _emit({"rows": rows, "load": load, "numpy": np.__version__, "scipy": scipy.__version__})


def _worker(argv: list[str]) -> None:
    task, spec = argv[0], json.loads(argv[1])
    if task == "expand":
        _worker_expand(spec)
    elif task == "hb":
        _worker_hb(spec)
    else:
        raise SystemExit(f"unknown worker task {task!r}")


def _call(task: str, spec: dict[str, Any], timeout: float) -> dict[str, Any]:
    outcome = run_worker(sys.executable, SELF, ["--worker", task, json.dumps(spec)], timeout=timeout)
    result = dict(outcome.result or {})
    result.update(status=outcome.status, detail=outcome.detail, process_wall=outcome.wall)
    return result


# =================================================================================================================
# references (parent process)
# =================================================================================================================
def _use_this_tree() -> None:
    if str(REPO_DIR) not in sys.path[:1]:
        sys.path.insert(0, str(REPO_DIR))


def _taylor_reference(f: str, a0: str) -> dict[str, Any]:
    _use_this_tree()
    import mpmath
    import sympy

    from lindstedt.references import frequency_taylor_coefficients

    u = sympy.Symbol("u")
    expression = sympy.sympify(f, locals={"u": u})
    start = time.perf_counter()
    try:
        pairs = frequency_taylor_coefficients(expression, ORDER, a0=sympy.Rational(a0), omega0=1,
                                              precision=REFERENCE_PRECISION)
    except Exception as error:  # noqa: BLE001 — report, do not hide the other rows
        return {"failure": f"{type(error).__name__}: {str(error)[:200]}", "seconds": time.perf_counter() - start}
    with mpmath.workdps(EXACT_DPS):
        return {"values": [mpmath.nstr(v, 50) for v, _ in pairs], "errors": [mpmath.nstr(e, 5) for _, e in pairs],
                "seconds": time.perf_counter() - start}


def own_two_arc_frequency(epsilon: float, kappa: Fraction, dps: int) -> Any:
    """ω of u'' + u + ε (u − κ)₊² = 0, u(0) = 1 > κ ≥ 0, u'(0) = 0, written here independently of the library.

    Energy E = V(1) = 1/2 + ε(1 − κ)³/3. Free arc (u < κ): harmonic with amplitude R = √(2E), time
    2π − 2 acos(κ/R). Contact arc (u > κ): 2∫_κ^1 du/√(2(E − V(u))); with V(1) − V(u) = (1 − u) g(u),
    g(u) = (1 + u)/2 + ε(d² + d y + y²)/3 (d = 1 − κ, y = u − κ), and u = 1 − s², the integrand
    2/√(2 g(1 − s²)) on [0, √d] is smooth (Gauss–Legendre via mpmath.quad).
    """
    import mpmath

    with mpmath.workdps(dps + 20):
        e = mpmath.mpf(epsilon)
        k = mpmath.mpf(kappa.numerator) / kappa.denominator
        d = 1 - k
        energy = mpmath.mpf(1) / 2 + e * d**3 / 3
        free = 2 * mpmath.pi - 2 * mpmath.acos(k / mpmath.sqrt(2 * energy))

        def g(x):
            y = x - k
            return (1 + x) / 2 + e * (d * d + d * y + y * y) / 3

        contact = 2 * mpmath.quad(lambda s: 2 / mpmath.sqrt(2 * g(1 - s * s)), [0, mpmath.sqrt(d)])
        return 2 * mpmath.pi / (free + contact)


def _exact_frequencies(kappa: str, eps_list: list[float]) -> dict[str, Any]:
    _use_this_tree()
    import mpmath
    import sympy

    from lindstedt.references import conservative_frequency

    u = sympy.Symbol("u")
    f = sympy.sympify(_law(kappa), locals={"u": u})
    out = {}
    for epsilon in eps_list:
        start = time.perf_counter()
        value, estimate = conservative_frequency(f, epsilon, a0=1, precision=EXACT_DPS - 10)
        seconds = time.perf_counter() - start
        own = own_two_arc_frequency(epsilon, Fraction(kappa), EXACT_DPS)
        with mpmath.workdps(EXACT_DPS + 10):
            out[repr(epsilon)] = {"value": mpmath.nstr(value, EXACT_DPS), "estimate": float(estimate),
                                  "own_two_arcs": mpmath.nstr(own, EXACT_DPS),
                                  "disagreement": float(abs(own - value)), "seconds": seconds}
    return out


def _abs_error(value: str, reference: str) -> float:
    import mpmath

    with mpmath.workdps(EXACT_DPS + 10):
        return float(abs(mpmath.mpf(value) - mpmath.mpf(reference)))


def _series_error(omega: list[str], epsilon: float, reference: str) -> float:
    """|Σ_{k≤N} ω_k ε^k − ω_exact|, the sum in mpmath from the 50-digit ω_k (ε = the double given)."""
    import mpmath

    with mpmath.workdps(EXACT_DPS + 10):
        e = mpmath.mpf(epsilon)
        total = mpmath.fsum(mpmath.mpf(w) * e**k for k, w in enumerate(omega))
        return float(abs(total - mpmath.mpf(reference)))


# =================================================================================================================
# formatting
# =================================================================================================================
def _eps_tag(epsilon: float) -> str:
    return repr(epsilon).replace(".", "p")


def _kappa_tag(kappa: str) -> str:
    return "kink" if Fraction(kappa) == 0 else "gap" + kappa.replace("/", "over")


def _rel(path: Path) -> str:
    return path.relative_to(BENCH_DIR).as_posix()


def _fit_power(xs: list[float], ys: list[float]) -> float | None:
    """Least-squares slope of log y against log x."""
    pairs = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if y > 0]
    if len(pairs) < 2:
        return None
    mx = sum(p[0] for p in pairs) / len(pairs)
    my = sum(p[1] for p in pairs) / len(pairs)
    return sum((x - mx) * (y - my) for x, y in pairs) / sum((x - mx) ** 2 for x, _ in pairs)


def _figure(path: Path, curves: list[tuple[list[float], list[float], str]], *, title: str, notes: list[str]) -> None:
    """Error against run time, log–log (matplotlib, ``_common.loglog_figure``)."""
    loglog_figure(path, curves, title=title, x_label="run time (s)", y_label="|ω − ω_exact|", notes=notes,
                  floor=PLOT_FLOOR)


def _tree_description() -> str:
    def git(*args: str) -> str:
        try:
            return subprocess.run(["git", "-C", str(REPO_DIR), *args], capture_output=True, text=True,
                                  timeout=30, check=False).stdout.strip()
        except (OSError, subprocess.TimeoutExpired):
            return ""

    commit = git("rev-parse", "--short", "HEAD") or "unknown"
    dirty = [line[3:] for line in git("status", "--porcelain", "--untracked-files=no").splitlines()
             if line[3:].startswith("lindstedt/")]
    text = f"commit `{commit}`"
    if dirty:
        text += " plus uncommitted changes in " + ", ".join(f"`{p}`" for p in dirty)
    else:
        text += " (no uncommitted changes under `lindstedt/`)"
    return text


# =================================================================================================================
# the benchmark
# =================================================================================================================
def _median(values: list[float]) -> float:
    return statistics.median(values) if values else math.nan


def _run_classes(config: dict[str, Any]) -> list[dict[str, Any]]:
    rows = []
    for spec in CLASSES:
        row: dict[str, Any] = dict(spec)
        for mode in ("exact", "float"):
            runs = []
            for _ in range(config["class_repeats"]):
                _log(f"{spec['f']} ({mode}) …")
                result = _call("expand", {"f": spec["f"], "a0": spec["a0"], "mode": mode, "order": ORDER},
                               timeout=CLASS_TIMEOUT)
                runs.append(result)
                if result["status"] != "ok":
                    break  # a timeout / error is recorded once, not repeated
            row[mode] = runs
        _log(f"{spec['f']}: reference …")
        row["reference"] = _taylor_reference(spec["f"], spec["a0"])
        rows.append(row)
    return rows


def _class_accuracy(row: dict[str, Any], mode: str) -> float | None:
    reference = row["reference"]
    ok = [r for r in row[mode] if r["status"] == "ok"]
    if not ok or "values" not in reference:
        return None
    import mpmath

    worst = 0.0
    with mpmath.workdps(EXACT_DPS + 10):
        for k in range(1, ORDER + 1):
            ref = mpmath.mpf(reference["values"][k])
            for r in ok:  # every process gives the same ω_k; take the worst anyway
                worst = max(worst, float(abs(mpmath.mpf(r["omega"][k]) - ref) / _scale(reference, k)))
    return worst


def _scale(reference: dict[str, Any], k: int) -> Any:
    """|ref_k|, or the largest |ref_j| when ref_k vanishes to 20 digits of it (ω_1 = 0 by symmetry)."""
    import mpmath

    largest = max(abs(mpmath.mpf(reference["values"][j])) for j in range(1, ORDER + 1))
    value = abs(mpmath.mpf(reference["values"][k]))
    return value if value > largest * mpmath.mpf(10) ** -20 else largest


def _reference_relative_estimate(reference: dict[str, Any]) -> float | None:
    if "values" not in reference:
        return None
    import mpmath

    with mpmath.workdps(EXACT_DPS):
        return max(float(mpmath.mpf(reference["errors"][k]) / _scale(reference, k)) for k in range(1, ORDER + 1))


def _time_cell(runs: list[dict[str, Any]]) -> str:
    ok = [r for r in runs if r["status"] == "ok"]
    if not ok:
        r = runs[0]
        if r["status"] == "timeout":
            return f"timeout (> {CLASS_TIMEOUT:.0f} s per process)"
        return f"{r['status']}: {r['detail'][:120]}"
    return f"{_t(_median([r['seconds'] for r in ok]))} ({', '.join(_t(r['seconds']) for r in ok)})"


def _run_series(config: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for (kappa, mode), (orders, repeats) in config["series"].items():
        if kappa not in config["hb_laws"]:
            continue
        entries = []
        for order in orders:
            runs = []
            for _ in range(repeats):
                _log(f"series {_law(kappa)} {mode} N = {order} …")
                runs.append(_call("expand", {"f": _law(kappa), "a0": "1", "mode": mode, "order": order,
                                             "eps": config["hb_eps"]}, timeout=CLASS_TIMEOUT))
                if runs[-1]["status"] != "ok":
                    break
            entries.append({"order": order, "runs": runs})
            if runs[-1]["status"] != "ok":
                break
        out[f"{kappa}|{mode}"] = entries
    return out


def run(quick: bool = False) -> str:
    config = QUICK if quick else FULL
    started = time.perf_counter()
    load_start = load_average()
    tree = _tree_description()

    # ---- 1. one row per class
    class_rows = _run_classes(config)

    # ---- 2. harmonic balance and the series
    _log("harmonic balance (one process) …")
    hb = _call("hb", {"laws": config["hb_laws"], "eps": config["hb_eps"], "harmonics": config["harmonics"],
                      "oversampling": config["oversampling"], "hybr_oversampling": config["hybr_oversampling"],
                      "repeats": config["hb_repeats"]}, timeout=600)
    series = _run_series(config)
    _log("exact frequencies …")
    exact = {kappa: _exact_frequencies(kappa, config["hb_eps"]) for kappa in config["hb_laws"]}
    for row in hb.get("rows", []):
        row["error"] = _abs_error(row["omega"], exact[row["kappa"]][repr(row["eps"])]["value"])
    for key, entries in series.items():
        kappa = key.split("|")[0]
        for entry in entries:
            ok = [r for r in entry["runs"] if r["status"] == "ok"]
            entry["seconds"] = _median([r["seconds"] for r in ok]) if ok else None
            entry["errors"] = {repr(e): _series_error(ok[0]["omega"], e, exact[kappa][repr(e)]["value"]) if ok else None
                               for e in config["hb_eps"]}
            entry["horner_errors"] = {repr(e): _abs_error(ok[0]["horner"][repr(e)]["value"], exact[kappa][repr(e)]["value"])
                                      if ok else None for e in config["hb_eps"]}
            entry["horner_seconds"] = {repr(e): min(r["horner"][repr(e)]["seconds"] for r in ok) if ok else None
                                       for e in config["hb_eps"]}

    elapsed = time.perf_counter() - started
    loads = [r.get("load") for row in class_rows for mode in ("exact", "float") for r in row[mode]]
    loads += [r.get("load") for entries in series.values() for entry in entries for r in entry["runs"]]
    loads = [float(x.split(",")[0]) for x in loads if x and x != "n/a"]
    lindstedt_files = sorted({r.get("lindstedt_file") for row in class_rows for mode in ("exact", "float")
                              for r in row[mode] if r.get("lindstedt_file")})
    raw = {"quick": quick, "tree": tree, "config": {k: (v if k != "series" else {f"{a}|{b}": w for (a, b), w in v.items()})
                                                    for k, v in config.items()},
           "load_average_start": load_start, "classes": class_rows, "hb": hb, "series": series, "exact": exact,
           "elapsed": elapsed, "lindstedt_files": lindstedt_files}
    raw_path = write_json(RAW_NAME.replace(".json", ".quick.json") if quick else RAW_NAME, raw)
    return _markdown(config, quick, tree, class_rows, hb, series, exact, raw_path, elapsed, load_start, loads,
                     lindstedt_files)


def _markdown(config, quick, tree, class_rows, hb, series, exact, raw_path, elapsed, load_start, loads,
              lindstedt_files) -> str:
    lines: list[str] = []
    w = lines.append
    w(f"## {TITLE}")
    w("")
    w(f"Tree measured: {tree}; the workers import lindstedt from "
      + ", ".join(f"`{Path(p).parent.relative_to(REPO_DIR) if Path(p).is_relative_to(REPO_DIR) else p}`"
                  for p in lindstedt_files)
      + " of this repository (put first on `sys.path` by the worker). Problem: `u'' + u + ε f(u) = 0`, "
      "`u(0) = a0`, `u'(0) = 0`, ω(ε) = Σ ω_k ε^k.")
    w("")

    # ---- part 1
    w(f"### 1. One row per class: time to ω_0…ω_{ORDER} and accuracy")
    w("")
    w(f"**How it is measured.** Each time is one fresh interpreter running `lindstedt.expand(f, order={ORDER}, "
      f"a0=a0, omega0=1)` (exact mode) or the same with `numeric=True, precision={FLOAT_PRECISION}` (float mode), "
      "timed with `time.perf_counter` around the expansion and forcing `.omega` (imports excluded; nothing "
      f"computed before in that process); the cell gives the median and every run ({config['class_repeats']} "
      f"fresh process(es) per cell). Time limit {CLASS_TIMEOUT:.0f} s per process (interpreter, import and "
      "expansion), reported as *timeout*. *Accuracy*: max over k = 1…4 of |ω_k − ref_k| / |ref_k| (a ref_k that vanishes to 20 digits of the largest, "
      "such as ω_1 of a symmetric law, is compared relative to the largest |ref_j|), ref = "
      f"`lindstedt.references.frequency_taylor_coefficients(f, {ORDER}, a0=a0, omega0=1, precision={REFERENCE_PRECISION})` "
      "(Taylor coefficients of the exact frequency ω(ε) = 2π/T(ε), T by quadrature of the energy integral, "
      "interpolated on Chebyshev points in ε), with the reference's own error estimate (max over k of "
      "estimate / |ref_k|) in the last column; a difference at or below that estimate is agreement. Exact-mode "
      "ω_k are compared through 50-digit evaluations (`sympy.N(ω_k, 50)`).")
    w("")
    w(f"| class | f (as given to `expand`) | a0 | exact mode: time to ω_0…ω_{ORDER} (median; runs) | exact output "
      f"(count_ops of ω_{ORDER}) | float mode, {FLOAT_PRECISION} digits: time (median; runs) | ratio exact / float | "
      "max rel. diff, exact | max rel. diff, float | reference's own rel. estimate (time) |")
    w("| --- | --- | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: |")
    for row in class_rows:
        exact_ok = [r for r in row["exact"] if r["status"] == "ok"]
        float_ok = [r for r in row["float"] if r["status"] == "ok"]
        kind = "—"
        if exact_ok:
            kind = exact_ok[0]["kind"] + (f" ({exact_ok[0]['count_ops_last']})" if exact_ok[0]["kind"] == "closed form" else "")
        ratio = (f"{_median([r['seconds'] for r in exact_ok]) / _median([r['seconds'] for r in float_ok]):.0f}×"
                 if exact_ok and float_ok else "—")
        reference = row["reference"]
        if "values" in reference:
            ref_cell = f"{_e(_reference_relative_estimate(reference))} ({_t(reference['seconds'])})"
        else:
            ref_cell = f"failed: {reference['failure']}"
        w(f"| {row['label']} | `{row['f']}` | {row['a0']} | {_time_cell(row['exact'])} | {kind} | "
          f"{_time_cell(row['float'])} | {ratio} | {_e(_class_accuracy(row, 'exact'))} | "
          f"{_e(_class_accuracy(row, 'float'))} | {ref_cell} |")
    w("")
    w("ω_1…ω_4 of each class (reference values, 12 digits):")
    w("")
    w("| f | " + " | ".join(f"ω_{k}" for k in range(1, ORDER + 1)) + " |")
    w("| --- | " + " | ".join("---:" for _ in range(ORDER)) + " |")
    import mpmath

    for row in class_rows:
        if "values" in row["reference"]:
            w(f"| `{row['f']}` | " + " | ".join(mpmath.nstr(mpmath.mpf(v), 12) for v in row["reference"]["values"][1:])
              + " |")
    w("")
    floats = [row for row in class_rows if any(r["status"] == "ok" and r["kind"] != "closed form" for r in row["exact"])]
    if floats:
        w("Exact mode returned floats (no closed form) for " + ", ".join(f"`{row['f']}`" for row in floats)
          + "; for those the exact and float columns time the same kind of computation.")
        w("")
    imports = [r["import_seconds"] for row in class_rows for m in ("exact", "float") for r in row[m] if r["status"] == "ok"]
    walls = [r["process_wall"] for row in class_rows for m in ("exact", "float") for r in row[m] if r["status"] == "ok"]
    w(f"`import sympy, lindstedt` in these processes: median {_t(_median(imports))}; a whole process (interpreter "
      f"start, import, expansion, exit) took {_t(min(walls))}…{_t(max(walls))}.")
    w("")

    # ---- part 2
    w("### 2. Harmonic balance (AFT) against the truncated series")
    w("")
    w("**Harmonic balance, written in this benchmark** (`hb_system`): u(τ) = Σ_{k=0}^{H} c_k cos kτ, τ = ωt, "
      "unknowns ω and c_0…c_H; equations: the Galerkin projections (1 − k²ω²) c_k + ε F_k = 0, k = 0…H, and the "
      "release point Σ c_k = u(0) = a0 = 1. F_k by alternating frequency–time: u at N = s·H equispaced τ by an "
      "inverse real FFT, f(u) sampled there, F_k by a real FFT (s = 4 and s = 32); the exact AFT Jacobian from "
      "one more FFT of f'(u). Solved from the linear solution (ω = 1, c_1 = 1) by Newton (stop when the step ≤ "
      "1e-14) and, for N = 4H, by `scipy.optimize.root(method=\"hybr\", jac=True, xtol=1e-13)`. Timing: one "
      "process, BLAS on one thread, one untimed warm-up solve of another problem; each solve (set-up included) "
      f"timed as the minimum over {config['hb_repeats']} repeats of the mean of a loop lasting ≥ 20 ms.")
    w("")
    w("**Series**: `lindstedt.expand(law, order=N, a0=1, omega0=1, numeric=True, precision=30)` (float mode) or "
      "exact mode, forcing `.omega`, one fresh process per run (imports excluded, median over the runs: "
      + "; ".join(f"{_law_label(k)} {m}: {r} process(es) per N, N = {o[0]}…{o[-1]}"
                  for (k, m), (o, r) in config["series"].items() if k in config["hb_laws"])
      + "). Its error: |Σ_{k≤N} ω_k ε^k − ω_exact| with the sum in mpmath from the 50-digit ω_k (the truncation "
      "error alone); *evaluation only*: Σ ω_k ε^k by Horner in doubles from the ω_k already computed (what every "
      "further ε costs), same loop timing as HB.")
    w("")
    w(f"**Exact frequency** ω_exact at each ε (the double nearest the decimal shown, read exactly by every "
      f"method): `lindstedt.references.conservative_frequency(law, ε, a0=1, precision={EXACT_DPS - 10})`; checked "
      "here by an independent two-arc formula (free harmonic arc, T_free = 2π − 2 acos(κ/√(2E)); contact arc "
      "by Gauss–Legendre after u = 1 − s², which removes the turning-point singularity; `own_two_arc_frequency`).")
    w("")
    for kappa in config["hb_laws"]:
        w(f"**Law {_law_label(kappa)}** (`{_law(kappa)}`, a0 = 1). ω_exact: "
          + "; ".join(f"ε = {e}: {exact[kappa][repr(e)]['value'][:24]}… (quadrature's own estimate "
                      f"{_e(exact[kappa][repr(e)]['estimate'])}, two-arc check differs by "
                      f"{_e(exact[kappa][repr(e)]['disagreement'])})" for e in config["hb_eps"]) + ".")
        w("")
        rows = [r for r in hb.get("rows", []) if r["kappa"] == kappa]
        if not rows:
            w(f"HB worker failed: {hb.get('status')} {hb.get('detail')}")
            w("")
        by = {(r["H"], r["N"], r["solver"], r["eps"]): r for r in rows}
        s_hybr = config["hybr_oversampling"]
        for e in config["hb_eps"] if rows else []:
            w(f"HB, ε = {e}:")
            w("")
            w("| H | " + " | ".join(f"Newton, N = {s}H: time | error | iterations" for s in config["oversampling"])
              + f" | hybr, N = {s_hybr}H: time | error | evaluations |")
            w("| ---: | " + " | ".join("---: | ---: | ---:" for _ in range(len(config["oversampling"]) + 1)) + " |")
            for H in config["harmonics"]:
                cells = []
                for s in config["oversampling"]:
                    r = by[(H, s * H, "newton", e)]
                    cells += [_t(r["seconds"]), _e(r["error"]), str(r["iterations"]) + ("" if r["converged"] else " (not converged)")]
                r = by[(H, s_hybr * H, "hybr", e)]
                cells += [_t(r["seconds"]), _e(r["error"]), str(r["iterations"]) + ("" if r["converged"] else " (no success)")]
                w(f"| {H} | " + " | ".join(cells) + " |")
            w("")
        w("Series:")
        w("")
        w("| N | " + " | ".join(f"{m} mode: time to ω_0…ω_N (cold; runs)" for m in ("float", "exact")
                                 if f"{kappa}|{m}" in series)
          + " | " + " | ".join(f"error, ε = {e} | ratio to N − 1" for e in config["hb_eps"])
          + " | evaluation only (doubles): time; error " + ", ".join(f"ε = {e}" for e in config["hb_eps"]) + " |")
        modes = [m for m in ("float", "exact") if f"{kappa}|{m}" in series]
        w("| ---: | " + " | ".join("---:" for _ in modes) + " | "
          + " | ".join("---: | ---:" for _ in config["hb_eps"]) + " | ---: |")
        entries = {m: {entry["order"]: entry for entry in series[f"{kappa}|{m}"]} for m in modes}
        float_entries = entries.get("float", {})
        previous = None
        for order in sorted({o for m in modes for o in entries[m]}):
            cells = []
            for m in modes:
                entry = entries[m].get(order)
                if entry is None:
                    cells.append("not run")
                elif entry["seconds"] is None:
                    r = entry["runs"][-1]
                    cells.append(f"timeout (> {CLASS_TIMEOUT:.0f} s per process)" if r["status"] == "timeout"
                                 else f"{r['status']}: {r['detail'][:80]}")
                else:
                    cells.append(f"{_t(entry['seconds'])} ({', '.join(_t(r['seconds']) for r in entry['runs'])})")
            source = float_entries.get(order) or next(entries[m][order] for m in modes if order in entries[m])
            for e in config["hb_eps"]:
                error = source["errors"][repr(e)]
                ratio = (f"{error / previous['errors'][repr(e)]:.2f}" if previous and error and previous["errors"][repr(e)]
                         else "—")
                cells += [_e(error), ratio]
            cells.append(f"{_t(min(source['horner_seconds'].values()))}; "
                         + ", ".join(_e(source["horner_errors"][repr(e)]) for e in config["hb_eps"]))
            previous = source
            w(f"| {order} | " + " | ".join(cells) + " |")
        w("")
        same = next((row for row in class_rows if row["f"] == _law(kappa)), None)
        repeat = entries.get("float", {}).get(ORDER)
        if same and repeat and repeat["seconds"] is not None and any(r["status"] == "ok" for r in same["float"]):
            first = _median([r["seconds"] for r in same["float"] if r["status"] == "ok"])
            w(f"Consistency within this run: the float-mode order-{ORDER} expansion of this law is timed both in "
              f"part 1 ({_t(first)}) and here ({_t(repeat['seconds'])}), ratio {max(first, repeat['seconds']) / min(first, repeat['seconds']):.1f} "
              "(the same call at two moments of the run; any difference comes from outside the benchmark: machine load, "
              "or the tree changing during the run).")
            w("")
        w(_reading(kappa, config, hb.get("rows", []), series, exact))
        w("")
        for e in config["hb_eps"]:
            path = FIGURES_DIR / f"contact_laws_hb_{_kappa_tag(kappa)}_eps{_eps_tag(e)}.svg"
            curves = []
            for s in config["oversampling"]:
                pts = sorted((r for r in rows if r["N"] == s * r["H"] and r["solver"] == "newton" and r["eps"] == e),
                             key=lambda r: r["H"])
                if pts:
                    curves.append(([r["seconds"] for r in pts], [r["error"] for r in pts],
                                   f"HB Newton, N = {s}H, H = {pts[0]['H']}…{pts[-1]['H']}"))
            pts = sorted((r for r in rows if r["solver"] == "hybr" and r["eps"] == e), key=lambda r: r["H"])
            if pts:
                curves.append(([r["seconds"] for r in pts], [r["error"] for r in pts],
                               f"HB scipy hybr, N = {config['hybr_oversampling']}H"))
            for m in modes:
                done = [entry for entry in series[f"{kappa}|{m}"] if entry["seconds"] is not None]
                if done:
                    curves.append(([entry["seconds"] for entry in done], [entry["errors"][repr(e)] for entry in done],
                                   f"series, {m} mode, cold, N = {done[0]['order']}…{done[-1]['order']}"))
            done = [entry for entry in series[f"{kappa}|{modes[0]}"] if entry["seconds"] is not None]
            if done:
                curves.append(([entry["horner_seconds"][repr(e)] for entry in done],
                               [entry["horner_errors"][repr(e)] for entry in done],
                               "series, evaluation only (ω_k known)"))
            _figure(path, curves, title=f"{_law_label(kappa)}, a0 = 1, ε = {e}: error vs run time"
                    + (" (quick)" if quick else ""),
                    notes=["one point per H or per order N", f"errors 0 drawn at {PLOT_FLOOR:.0e}"])
            w(f"![{_law_label(kappa)}, ε = {e}: error against run time]({_rel(path)})")
            w("")

    max_load = f"{max(loads):.2f}" if loads else "n/a"
    w(f"Raw data: `{raw_path.relative_to(BENCH_DIR).as_posix()}`. This section took {elapsed:.0f} s "
      f"(load average at start: {load_start}; at end: {load_average()}; 1-min load seen by the worker processes: "
      f"≤ {max_load} on this 2-core machine)" + (" — **quick mode: fewer repeats, sizes and laws**" if quick else "")
      + ".")
    return "\n".join(lines) + "\n"


def _reading(kappa: str, config: dict[str, Any], hb_rows: list[dict[str, Any]], series: dict[str, Any],
             exact: dict[str, Any]) -> str:
    """Measured facts for one law: HB's algebraic rate, the series' geometric rate, and who is cheaper for a given error."""
    parts = []
    for e in config["hb_eps"]:
        facts = [f"ε = {e}:"]
        for s in config["oversampling"]:
            pts = sorted((r for r in hb_rows if r["kappa"] == kappa and r["eps"] == e and r["solver"] == "newton"
                          and r["N"] == s * r["H"] and r["H"] >= 4 and r["error"] > 1e-14), key=lambda r: r["H"])
            slope = _fit_power([r["H"] for r in pts], [r["error"] for r in pts])
            if slope is not None:
                facts.append(f"HB (N = {s}H) error ∝ H^{slope:.1f} (least squares over H = {pts[0]['H']}…{pts[-1]['H']}, "
                             "errors above 1e-14)")
        for s in config["oversampling"]:
            pts = sorted((r for r in hb_rows if r["kappa"] == kappa and r["eps"] == e and r["solver"] == "newton"
                          and r["N"] == s * r["H"]), key=lambda r: r["H"])
            stalled = [b["H"] for a, b in pairwise(pts) if b["error"] > 0.5 * a["error"] and a["error"] > 1e-14]
            if stalled:
                facts.append(f"HB (N = {s}H) error not halved when H doubled to H = " + ", ".join(map(str, stalled)))
        float_series = [entry for entry in series.get(f"{kappa}|float", []) if entry["seconds"] is not None]
        if len(float_series) >= 3:
            errors = [entry["errors"][repr(e)] for entry in float_series]
            rate = (errors[-1] / errors[0]) ** (1 / (len(errors) - 1)) if errors[0] and errors[-1] else None
            if rate:
                facts.append(f"series error ratio per order ≈ {rate:.2f} (geometric mean over N = {float_series[0]['order']}…"
                             f"{float_series[-1]['order']}, against ε = {e}: error ≈ C (ε/ρ)^N with ρ = ε / ratio ≈ "
                             f"{e / rate:.2f}, a rough radius of convergence)")
            chosen = {entry["order"]: entry for entry in (float_series[min(3, len(float_series) - 1)], float_series[-1])}
            for entry in chosen.values():
                target = entry["errors"][repr(e)]
                candidates = [r for r in hb_rows if r["kappa"] == kappa and r["eps"] == e and r["error"] <= target]
                if candidates:
                    best = min(candidates, key=lambda r: r["seconds"])
                    evaluation = entry["horner_seconds"][repr(e)]
                    count = math.ceil(entry["seconds"] / max(best["seconds"] - evaluation, 1e-12))
                    facts.append(f"the order-{entry['order']} series' error {_e(target)} ({_t(entry['seconds'])} cold, "
                                 f"float mode) is reached by HB at H = {best['H']}, N = {best['N']} ({best['solver']}) "
                                 f"in {_t(best['seconds'])} per ε, so the series is the cheaper route from about "
                                 f"{count} values of ε on (then {_t(evaluation)} per ε)")
                else:
                    facts.append(f"no HB setting run reaches the order-{entry['order']} series' error {_e(target)}")
        parts.append(" ".join([facts[0], "; ".join(facts[1:])]) + ".")
    return "Reading (computed from the tables above): " + " ".join(parts)


def main(argv: list[str] | None = None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] == "--worker":
        _worker(argv[1:])
        return
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats, sizes and laws")
    args = parser.parse_args(argv)
    print(run(quick=args.quick))


if __name__ == "__main__":
    main()
