"""Benchmark: run time against error for every method pair, in one run, with figures.

Three problems, each solved by every method lindstedt offers (and an outside baseline), each result compared
with an independent exact reference at high precision:

1. Duffing ``u'' + u + ε u³ = 0``, ``u(0) = 1``, ``u'(0) = 0``: the Lindstedt–Poincaré (LP) frequency truncated
   at order N (``lindstedt.expand("u**3", order=N, a0=1, omega0=1).frequency(ε)``), the elliptic closed form
   (``lindstedt.references.duffing_exact_frequency``) and the energy-integral quadrature
   (``lindstedt.references.conservative_frequency``) at several working precisions, and scipy's DOP853
   measuring the period (event at u' = 0) at several tolerances.
2. Unilateral spring ``u'' + u + ε (u − κ)_+ = 0``, κ = 1/3, ``u(0) = 1``: the expansion (``numeric=True``,
   orders 1…6), the library's closed-form period (``_reference_piecewise``), Newton shooting on the exact
   flow (``lindstedt.nnm_point`` on ``UnilateralSystem.one_dof(1, a=1, b=1/3)`` — force ε (1·u − 1/3)_+, the
   same problem), DOP853 restarted at every contact switch, and DOP853 straight through the kink.
3. A 3-mass chain with three unilateral springs, NNM of mode 1 with modal amplitude 1: the expansion
   ``lindstedt.nnm(order=1, 2, 3)`` against shooting (``nnm_point``) at several Newton tolerances, over
   ε = 1e-5 … 0.3, to show where the expansion's O(ε³) error crosses the shooting accuracy.

Every problem runs in its own fresh interpreter (this file doubles as its worker: ``python -I
bench_method_pairs.py --worker NAME [--quick]`` prints one ``@@BENCH-RESULT {json}`` line).  Timing is
``time.perf_counter`` inside that process, minimum over repeats; what each time covers is stated in the
section.  The figures are SVG files in ``benchmarks/figures/`` drawn on log–log axes with matplotlib
(``_common.loglog_figure``).

Standalone: ``python benchmarks/bench_method_pairs.py [--quick]`` prints the markdown section.
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import sys
import time
from pathlib import Path
from typing import Any, Callable

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import BENCH_DIR, RESULT_MARKER, load_average, run_worker, write_json  # noqa: E402
from _common import loglog_figure  # noqa: E402
from _common import format_seconds as _t, per_call as _warm  # noqa: E402

TITLE = "Method pairs: run time against error (LP expansion, closed forms, quadrature, shooting, DOP853)"
SELF = Path(__file__).resolve()
FIGURES_DIR = BENCH_DIR / "figures"
RAW_NAME = "method_pairs.json"

REFERENCE_DPS = 80  # digits of every reference value
FULL = {
    "repeats": 5,
    "cold_repeats": 7,
    "duffing_eps": [0.05, 0.2],
    "duffing_orders": list(range(1, 13)),
    "duffing_dps": [8, 15, 20, 30, 50],
    "rtols": [1e-3, 1e-5, 1e-7, 1e-9, 1e-11, 1e-13],
    "unilateral_eps": [0.05, 0.2],
    "unilateral_orders": list(range(1, 7)),
    "unilateral_dps": [8, 15, 20, 30, 50],
    "shooting_tols_1dof": [1e-2, 1e-4, 1e-6, 1e-8, 1e-11, 1e-14],
    "nnm_eps": [1e-5, 3e-5, 1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3],
    "nnm_orders": [1, 2, 3],
    "shooting_tols": [1e-2, 1e-4, 1e-6, 1e-11],
}
QUICK = {
    "repeats": 2,
    "cold_repeats": 2,
    "duffing_eps": [0.05, 0.2],
    "duffing_orders": [1, 2, 4, 6, 8],
    "duffing_dps": [15, 30],
    "rtols": [1e-5, 1e-9, 1e-13],
    "unilateral_eps": [0.2],
    "unilateral_orders": [1, 2, 3],
    "unilateral_dps": [15, 30],
    "shooting_tols_1dof": [1e-4, 1e-11],
    "nnm_eps": [1e-5, 1e-4, 1e-3, 1e-2, 0.1, 0.3],
    "nnm_orders": [1, 2, 3],
    "shooting_tols": [1e-4, 1e-11],
}
KAPPA = "1/3"
#: the 3-mass chain of problem 3: springs on mass 0 (gap 0.1), mass 1 (prestress, engaged at rest) and mass 2
NNM_SPRINGS = [(0, "1/10"), (1, "-1/20"), (2, "0")]
NNM_REFERENCE_TOL = 1e-14
DEFAULT_SHOOTING_TOL = 1e-11  # nnm_point's default
PLOT_FLOOR = 1e-17  # errors that are exactly 0 (same double) are drawn here on log axes


# =================================================================================================================
# worker side (runs in a fresh interpreter; imports lindstedt)
# =================================================================================================================
def _clear_lindstedt_caches() -> None:
    """Forget every cached hierarchy and memo so the next expansion is computed from scratch ("cold-ish")."""
    import sympy.core.cache

    import lindstedt

    lindstedt.clear_cache()
    for name, module in list(sys.modules.items()):
        if not name.startswith("lindstedt") or module is None:
            continue
        for value in list(vars(module).values()):
            clear = getattr(value, "cache_clear", None)
            if callable(clear) and getattr(value, "__module__", "").startswith("lindstedt"):
                clear()
    sympy.core.cache.clear_cache()


def _cold(function: Callable[[], Any], repeats: int) -> tuple[float, Any]:
    """Minimum over ``repeats`` of one call, every call after :func:`_clear_lindstedt_caches` (not timed)."""
    best, result = math.inf, None
    for _ in range(repeats):
        _clear_lindstedt_caches()
        gc.collect()
        start = time.perf_counter()
        result = function()
        best = min(best, time.perf_counter() - start)
    return best, result


def _mp_error(value: Any, reference: Any) -> float:
    import mpmath

    with mpmath.workdps(REFERENCE_DPS + 10):
        return float(abs(mpmath.mpf(value) - reference))


def _exact_sum(coefficients: Any, epsilon: float) -> Any:
    """Σ ω_k ε^k from the expansion's exact (or 30-digit) coefficients, in mpmath at the reference precision."""
    import mpmath
    import sympy

    with mpmath.workdps(REFERENCE_DPS + 10):
        total = mpmath.mpf(0)
        for k, coefficient in enumerate(coefficients):
            if isinstance(coefficient, sympy.Rational):
                value = mpmath.mpf(int(coefficient.p)) / int(coefficient.q)
            else:
                value = mpmath.mpf(str(sympy.N(coefficient, REFERENCE_DPS)))
            total += value * mpmath.mpf(epsilon) ** k
        return total


def _dop853_half_period_event(system_arrays: dict, epsilon: float, x0: Any, rtol: float, *, restart: bool,
                              mode_vector: Any) -> tuple[float, int, int]:
    """Frequency π / t½ of the orbit released from rest at ``x0``, by DOP853.

    ``t½`` is the first time the modal velocity ``φ_jᵀ M X'`` crosses zero upwards (for these reversible
    orbits released from rest it is the half period).  ``restart=True``: the integration stops at every
    contact switch (event on A X − b with the direction that leaves the current contact state) and
    restarts with the new state, so every segment is smooth; ``restart=False``: straight through the kink
    of (·)_+ with only the period event.  Returns (ω, RHS evaluations, segments).
    """
    import numpy as np
    from scipy.integrate import solve_ivp

    M, K, A, b, W = (system_arrays[key] for key in ("M", "K", "A", "b", "W"))
    m_inverse = np.linalg.inv(M)
    n = M.shape[0]
    projector = mode_vector @ M  # φ_jᵀ M
    y = np.concatenate([np.asarray(x0, float), np.zeros(n)])
    active = (A @ y[:n] - b) > 0
    t, t_end, nfev, segments = 0.0, 20.0 * math.pi, 0, 0

    def period_event(_t, state):
        return float(projector @ state[n:])

    period_event.direction = 1.0
    period_event.terminal = True
    atol = rtol * 1e-3
    while True:
        segments += 1
        if restart:
            mask = active.astype(float)

            def rhs(_t, state, mask=mask):
                x = state[:n]
                force = K @ x + epsilon * (W @ (mask * (A @ x - b)))
                return np.concatenate([state[n:], -(m_inverse @ force)])

            events = [period_event]
            for k in range(A.shape[0]):
                def switch(_t, state, k=k):
                    return float(A[k] @ state[:n] - b[k])

                switch.direction = -1.0 if active[k] else 1.0
                switch.terminal = True
                events.append(switch)
        else:
            def rhs(_t, state):
                x = state[:n]
                force = K @ x + epsilon * (W @ np.maximum(A @ x - b, 0.0))
                return np.concatenate([state[n:], -(m_inverse @ force)])

            events = [period_event]
        solution = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=atol, events=events)
        nfev += solution.nfev
        if solution.t_events[0].size:
            return math.pi / float(solution.t_events[0][0]), nfev, segments
        fired = [k for k in range(1, len(events)) if solution.t_events[k].size]
        if solution.status != 1 or not fired:
            raise RuntimeError(f"DOP853 did not reach the half period: {solution.message}")
        k = fired[0] - 1
        t, y = float(solution.t_events[fired[0]][0]), np.array(solution.y_events[fired[0]][0])
        active = active.copy()
        active[k] = not active[k]


def _arrays(system: Any) -> dict:
    return {"M": system.M, "K": system.K, "A": system.A, "b": system.b, "W": system.W}


def _own_unilateral_frequency(epsilon: float, kappa: Any, precision: int) -> Any:
    """ω of u'' + u + ε (u − κ)_+ = 0, u(0) = 1 > κ, u'(0) = 0, from harmonic arcs (written here, independently).

    Contact arc: u = u* + (1 − u*) cos(ω_c t), u* = εκ/(1+ε), ω_c = √(1+ε), until u = κ at t₁ with velocity
    v₁ < 0; free arc u = κ cos τ + v₁ sin τ = R cos(τ + φ), cos φ = κ/R, back at κ after 2π − 2φ.
    T = 2 t₁ + 2π − 2φ.
    """
    import mpmath

    with mpmath.workdps(precision + 15):
        eps, k = mpmath.mpf(epsilon), mpmath.mpf(kappa.numerator) / kappa.denominator
        rest = eps * k / (1 + eps)
        omega_c = mpmath.sqrt(1 + eps)
        t1 = mpmath.acos((k - rest) / (1 - rest)) / omega_c
        v1 = -(1 - rest) * omega_c * mpmath.sin(omega_c * t1)
        radius = mpmath.sqrt(k**2 + v1**2)
        period = 2 * t1 + 2 * mpmath.pi - 2 * mpmath.acos(k / radius)
        return 2 * mpmath.pi / period


def _worker_duffing(config: dict) -> dict:
    import warnings

    import mpmath
    import numpy as np
    import sympy
    from scipy.integrate import solve_ivp

    import lindstedt
    from lindstedt.references import conservative_frequency, duffing_exact_frequency

    u = sympy.Symbol("u")
    repeats = config["repeats"]
    lindstedt.expand("u**3 + u**5", order=3, a0=1, omega0=1).frequency(0.1)  # warm the code paths (another f)
    out: dict[str, Any] = {"eps": {}}
    for epsilon in config["duffing_eps"]:
        ref_elliptic = duffing_exact_frequency(epsilon, amplitude=1, precision=REFERENCE_DPS)
        ref_quadrature, ref_quadrature_estimate = conservative_frequency(u**3, epsilon, a0=1, precision=REFERENCE_DPS - 10)
        entry: dict[str, Any] = {
            "reference_elliptic": mpmath.nstr(ref_elliptic, 40),
            "reference_quadrature": mpmath.nstr(ref_quadrature, 40),
            "reference_disagreement": _mp_error(ref_quadrature, ref_elliptic),
            "quadrature_reference_estimate": float(ref_quadrature_estimate),
            "lp": [], "elliptic": [], "quadrature": [], "dop853": [],
        }
        for order in config["duffing_orders"]:
            def expand_only(order=order):
                expansion = lindstedt.expand("u**3", order=order, a0=1, omega0=1)
                expansion.omega  # noqa: B018 — force ω_0…ω_N (lazy)
                return expansion

            def expand_and_evaluate(order=order):
                expansion = lindstedt.expand("u**3", order=order, a0=1, omega0=1)
                return expansion, expansion.frequency(epsilon)

            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                t_expand, _ = _cold(expand_only, config["cold_repeats"])
                t_cold, (expansion, value) = _cold(expand_and_evaluate, config["cold_repeats"])
                t_eval, value_warm = _warm(lambda expansion=expansion: expansion.frequency(epsilon), repeats)
            assert value == value_warm
            omega_function = expansion.lambdify("frequency")
            t_lambdified, value_lambdified = _warm(lambda: float(omega_function(epsilon)), repeats)
            entry["lp"].append({
                "order": order, "seconds_expand_only": t_expand, "seconds_cold": t_cold, "seconds_eval": t_eval,
                "seconds_lambdified": t_lambdified, "error_lambdified": _mp_error(value_lambdified, ref_elliptic),
                "value": value, "error": _mp_error(value, ref_elliptic),
                "truncation_error": _mp_error(_exact_sum(expansion.omega, epsilon), ref_elliptic),
                "validity_warning": any("converging" in str(w.message) for w in caught),
            })
        for precision in config["duffing_dps"]:
            seconds, value = _warm(lambda precision=precision: duffing_exact_frequency(epsilon, amplitude=1, precision=precision), repeats)
            entry["elliptic"].append({"precision": precision, "seconds": seconds, "value": mpmath.nstr(value, precision + 5),
                                      "error": _mp_error(value, ref_quadrature)})
        for precision in config["duffing_dps"]:
            seconds, (value, estimate) = _warm(
                lambda precision=precision: conservative_frequency(u**3, epsilon, a0=1, precision=precision), max(2, repeats // 2), 0.0)
            entry["quadrature"].append({"precision": precision, "seconds": seconds, "value": mpmath.nstr(value, precision + 5),
                                        "error": _mp_error(value, ref_elliptic), "own_estimate": float(estimate)})
        for rtol in config["rtols"]:
            def dop853(rtol=rtol):
                def rhs(_t, y):
                    return [y[1], -y[0] - epsilon * y[0] ** 3]

                def turning(_t, y):
                    return y[1]

                turning.direction, turning.terminal = 1.0, True
                solution = solve_ivp(rhs, (0.0, 20.0), [1.0, 0.0], method="DOP853", rtol=rtol, atol=rtol * 1e-3,
                                     events=turning)
                return math.pi / float(solution.t_events[0][0]), solution.nfev

            seconds, (value, nfev) = _warm(dop853, repeats)
            entry["dop853"].append({"rtol": rtol, "seconds": seconds, "value": value, "nfev": int(nfev),
                                    "error": _mp_error(value, ref_elliptic)})
        out["eps"][repr(epsilon)] = entry
    del np
    return out


def _worker_unilateral(config: dict) -> dict:
    import warnings
    from fractions import Fraction

    import mpmath

    import lindstedt
    from lindstedt.references import piecewise_linear_exact_frequency

    repeats = config["repeats"]
    kappa = Fraction(KAPPA)
    f = f"Max(0, u - {KAPPA})"
    lindstedt.expand("Max(0, u - 1/4)", order=2, a0=1, omega0=1, numeric=True).frequency(0.1)  # warm (another κ)
    system = lindstedt.UnilateralSystem.one_dof(1, a=1, b=KAPPA)  # u'' + u + ε (1·u − 1/3)_+ = 0
    arrays = _arrays(system)
    import numpy as np

    out: dict[str, Any] = {"eps": {}, "system": system.to_json_dict()}
    for epsilon in config["unilateral_eps"]:
        reference = _own_unilateral_frequency(epsilon, kappa, REFERENCE_DPS)
        library = piecewise_linear_exact_frequency(epsilon, a=1, b=kappa, a0=1, precision=REFERENCE_DPS)
        entry: dict[str, Any] = {
            "reference_own_arcs": mpmath.nstr(reference, 40),
            "reference_library": mpmath.nstr(library, 40),
            "reference_disagreement": _mp_error(library, reference),
            "expansion": [], "closed_form": [], "shooting": [], "dop853_restart": [], "dop853_through": [],
        }
        for order in config["unilateral_orders"]:
            def expand_only(order=order):
                expansion = lindstedt.expand(f, order=order, a0=1, omega0=1, numeric=True)
                expansion.omega  # noqa: B018
                return expansion

            def expand_and_evaluate(order=order):
                expansion = lindstedt.expand(f, order=order, a0=1, omega0=1, numeric=True)
                return expansion, expansion.frequency(epsilon)

            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                t_expand, _ = _cold(expand_only, config["cold_repeats"])
                t_cold, (expansion, value) = _cold(expand_and_evaluate, config["cold_repeats"])
                t_eval, _ = _warm(lambda expansion=expansion: expansion.frequency(epsilon), repeats)
            omega_function = expansion.lambdify("frequency")
            t_lambdified, value_lambdified = _warm(lambda: float(omega_function(epsilon)), repeats)
            entry["expansion"].append({
                "order": order, "seconds_expand_only": t_expand, "seconds_cold": t_cold, "seconds_eval": t_eval,
                "seconds_lambdified": t_lambdified, "error_lambdified": _mp_error(value_lambdified, reference),
                "value": value, "error": _mp_error(value, reference),
                "truncation_error": _mp_error(_exact_sum(expansion.omega, epsilon), reference),
                "validity_warning": any("converging" in str(w.message) for w in caught),
            })
        for precision in config["unilateral_dps"]:
            seconds, value = _warm(
                lambda precision=precision: piecewise_linear_exact_frequency(epsilon, a=1, b=kappa, a0=1, precision=precision), repeats)
            entry["closed_form"].append({"precision": precision, "seconds": seconds, "value": mpmath.nstr(value, precision + 5),
                                         "error": _mp_error(value, reference)})
        for tol in config["shooting_tols_1dof"]:
            seconds, result = _warm(
                lambda tol=tol: lindstedt.nnm_point(system, epsilon, 1, modal_amplitude=1.0, tol=tol, verify_tol=1.0),
                repeats)
            entry["shooting"].append({
                "tol": tol, "seconds": seconds, "value": result.frequency, "error": _mp_error(result.frequency, reference),
                "residual": result.residual, "iterations": result.newton_iterations,
                "flows": result.flow_evaluations, "verified_1e-8": bool(result.residual <= 1e-8),
                "n_switches": result.n_switches,
            })
        for restart, key in ((True, "dop853_restart"), (False, "dop853_through")):
            for rtol in config["rtols"]:
                seconds, (value, nfev, segments) = _warm(
                    lambda rtol=rtol, restart=restart: _dop853_half_period_event(
                        arrays, epsilon, [1.0], rtol, restart=restart, mode_vector=np.array([1.0])), repeats)
                entry[key].append({"rtol": rtol, "seconds": seconds, "value": value, "nfev": int(nfev),
                                   "segments": segments, "error": _mp_error(value, reference)})
        out["eps"][repr(epsilon)] = entry
    return out


def _worker_nnm(config: dict) -> dict:
    import warnings

    import numpy as np

    import lindstedt

    repeats = config["repeats"]

    def chain():
        return lindstedt.UnilateralSystem.chain(3, unilateral=NNM_SPRINGS)

    system = chain()
    lindstedt.nnm(lindstedt.UnilateralSystem.chain(2, unilateral=[(0, "1/10")]), mode=1, a0=1, order=2)  # warm-up
    mode_vector = system.modes().shapes[:, 0]
    out: dict[str, Any] = {"system": system.to_json_dict(), "lambda_1": float(system.modes().frequencies[0]),
                           "mode_shape": mode_vector.tolist(), "expansion": {}, "points": []}
    expansions = {}
    for order in config["nnm_orders"]:
        # fresh system objects (no cached modes), built outside the timing
        systems = [chain() for _ in range(config["cold_repeats"])]
        seconds, expansion = _cold(lambda: lindstedt.nnm(systems.pop(), mode=1, a0=1, order=order),
                                   config["cold_repeats"])
        t_eval, _ = _warm(lambda expansion=expansion: expansion.frequency(0.01), repeats)
        expansions[order] = expansion
        out["expansion"][str(order)] = {"seconds_cold": seconds, "seconds_eval": t_eval,
                                        "omega": [float(w) for w in expansion.omega],
                                        "spring_roots": list(expansion.spring_roots),
                                        "validity_exponent": str(expansion.validity_exponent)}
    for epsilon in config["nnm_eps"]:
        t_ref, reference = _warm(
            lambda: lindstedt.nnm_point(system, epsilon, 1, modal_amplitude=1.0, tol=NNM_REFERENCE_TOL), 1, 0.0)
        point: dict[str, Any] = {"eps": epsilon, "reference": reference.frequency, "reference_success": reference.success,
                                 "reference_message": reference.message, "reference_residual": reference.residual,
                                 "reference_seconds": t_ref, "n_switches": reference.n_switches,
                                 "expansion": {}, "shooting": []}
        check_seconds, (check_value, check_nfev, check_segments) = _warm(
            lambda: _dop853_half_period_event(_arrays(system), epsilon, reference.release_position, 1e-13,
                                              restart=True, mode_vector=mode_vector), 1, 0.0)
        point["dop853_check"] = {"rtol": 1e-13, "value": check_value, "difference": abs(check_value - reference.frequency),
                                 "seconds": check_seconds, "nfev": check_nfev, "segments": check_segments}
        for order, expansion in expansions.items():
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                value = float(expansion.frequency(epsilon))
            point["expansion"][str(order)] = {"value": value, "error": abs(value - reference.frequency)}
        for tol in config["shooting_tols"]:
            seconds, result = _warm(
                lambda tol=tol: lindstedt.nnm_point(system, epsilon, 1, modal_amplitude=1.0, tol=tol, verify_tol=1.0),
                repeats, 0.0)
            point["shooting"].append({
                "tol": tol, "seconds": seconds, "value": result.frequency,
                "error": abs(result.frequency - reference.frequency), "residual": result.residual,
                "iterations": result.newton_iterations, "flows": result.flow_evaluations,
                "verified_1e-8": bool(result.residual <= 1e-8), "success": result.success,
            })
        out["points"].append(point)
    del np
    return out


WORKERS = {"duffing": _worker_duffing, "unilateral": _worker_unilateral, "nnm": _worker_nnm}


def _worker_main(name: str, quick: bool) -> None:
    config = QUICK if quick else FULL
    start = time.perf_counter()
    result = WORKERS[name](config)
    result["worker_seconds"] = time.perf_counter() - start
    print(RESULT_MARKER + json.dumps(result))


# =================================================================================================================
# parent side: figures (matplotlib) and markdown (no lindstedt import)
# =================================================================================================================
def _figure(path: Path, curves: list[tuple[list[float], list[float], str]], *, title: str, x_label: str,
            y_label: str, notes: list[str] = ()) -> None:
    """Log–log figure (matplotlib, ``_common.loglog_figure``)."""
    loglog_figure(path, curves, title=title, x_label=x_label, y_label=y_label, notes=notes, floor=PLOT_FLOOR)


def _floored(values: list[float], floor: float = 1e-300) -> list[float]:
    """|v|, drawn at ``floor`` when it is 0 (log axes)."""
    return [max(abs(v), floor) for v in values]


def _span(values: list[Any], fmt: Callable[[Any], str] = str) -> str:
    return f"{fmt(values[0])}…{fmt(values[-1])}" if len(values) > 1 else fmt(values[0])


def _e0(value: float) -> str:
    return f"{value:.0e}".replace("e-0", "e-")


def _g(value: float, digits: int = 2) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "—"
    if value == 0:
        return "0"
    return f"{value:.{digits}g}" if 1e-3 <= abs(value) < 1e4 else f"{value:.{digits - 1}e}"


def _eps_tag(epsilon: float) -> str:
    return repr(epsilon).replace(".", "p").replace("-", "m")


def _rel(path: Path) -> str:
    return path.relative_to(BENCH_DIR).as_posix()


def _section_duffing(data: dict, quick: bool, figures: list[Path]) -> list[str]:
    w: list[str] = []
    w += ["### 1. Duffing frequency: LP truncation vs elliptic closed form vs quadrature vs DOP853", "",
          "`u'' + u + ε u³ = 0`, `u(0) = 1`, `u'(0) = 0` (a0 = ω0 = 1). ε is the double nearest to the decimal "
          "shown; every method gets that same double (the mpmath references read it exactly).", "",
          "What is timed (each in one fresh interpreter per problem, `time.perf_counter`, minimum over repeats):", "",
          "* **LP, expand + frequency (cold)**: `lindstedt.expand(\"u**3\", order=N, a0=1, omega0=1).frequency(ε)` "
          "after dropping every cached hierarchy, lindstedt's memo caches and sympy's cache (the interpreter, "
          "imports and code paths are warm: one untimed expansion of another f ran first). `frequency()` also "
          "computes ω_{N+1} for its validity warning, so this costs about one order more than the expansion itself "
          "(*expand alone* = forcing ω_0…ω_N, also cold, in the notes).",
          "* **LP, frequency (warm)**: `expansion.frequency(ε)` on an expansion already computed (sympy rationals "
          "→ floats → `polyval`, plus the ω_{N+1} ε^{N+1} warning check); *lambdified*: a call of "
          "`expansion.lambdify(\"frequency\")` (sympy-generated Python, built once untimed), ε → float.",
          "* **elliptic**: `lindstedt.references.duffing_exact_frequency(ε, amplitude=1, precision=d)` (π√(1+ε)/(2K(m))), "
          "one call.",
          "* **quadrature**: `lindstedt.references.conservative_frequency(u**3, ε, a0=1, precision=d)` (period from the "
          "energy integral by a refined trapezoid rule), one call; its own error estimate in the notes.",
          "* **DOP853**: `scipy.integrate.solve_ivp(method=\"DOP853\", rtol, atol = rtol·1e-3)` from (1, 0) with a "
          "terminal event at u' = 0 (upward crossing: the turning point u = −1 at t = T/2), ω = π / t½; one call.",
          "",
          "Error = |ω − ω_ref| in mpmath. ω_ref: the elliptic closed form at "
          f"{REFERENCE_DPS} digits, except for the elliptic rows themselves, which are compared with the "
          f"quadrature at {REFERENCE_DPS - 10} digits (an independent route); the two references agree to the "
          "figure given under each table. *Truncation* = the error of Σ_{k≤N} ω_k ε^k summed exactly from the "
          "expansion's rational ω_k (what the LP truncation costs without double rounding).", ""]
    for key, entry in data["eps"].items():
        epsilon = float(key)
        w += [f"**ε = {key}** (ω_ref = {entry['reference_elliptic'][:22]}…)", "",
              "| method | setting | time | evaluation only: `.frequency(ε)` | evaluation only: lambdified | "
              "\\|ω − ω_ref\\| | notes |",
              "| --- | --- | ---: | ---: | ---: | ---: | --- |"]
        for r in entry["lp"]:
            note = f"expand alone {_t(r['seconds_expand_only'])}; truncation {_g(r['truncation_error'])}"
            if r["validity_warning"]:
                note += "; validity warning"
            if r["error_lambdified"] != r["error"]:
                note += f"; lambdified error {_g(r['error_lambdified'])}"
            w.append(f"| LP expand + frequency (cold) | N = {r['order']} | {_t(r['seconds_cold'])} | "
                     f"{_t(r['seconds_eval'])} | {_t(r['seconds_lambdified'])} | {_g(r['error'])} | {note} |")
        for r in entry["elliptic"]:
            w.append(f"| elliptic closed form | precision = {r['precision']} | {_t(r['seconds'])} | — | — | {_g(r['error'])} | "
                     "vs quadrature reference |")
        for r in entry["quadrature"]:
            w.append(f"| quadrature | precision = {r['precision']} | {_t(r['seconds'])} | — | — | {_g(r['error'])} | "
                     f"own estimate {_g(r['own_estimate'])} |")
        for r in entry["dop853"]:
            w.append(f"| DOP853, event u' = 0 | rtol = {r['rtol']:.0e} | {_t(r['seconds'])} | — | — | {_g(r['error'])} | "
                     f"{r['nfev']} RHS evaluations |")
        w += ["", f"References: elliptic ({REFERENCE_DPS} digits) − quadrature ({REFERENCE_DPS - 10} digits) = "
                  f"{_g(entry['reference_disagreement'])} (quadrature's own estimate "
                  f"{_g(entry['quadrature_reference_estimate'])}).", ""]
        path = FIGURES_DIR / f"method_pairs_duffing_eps{_eps_tag(epsilon)}.svg"
        lp = entry["lp"]
        orders = [r["order"] for r in lp]
        curves = [
            (_floored([r["seconds_cold"] for r in lp]), _floored([r["error"] for r in lp]),
             f"LP expand + .frequency, cold, N = {orders[0]}…{orders[-1]}"),
            (_floored([r["seconds_eval"] for r in lp]), _floored([r["error"] for r in lp]),
             f"LP .frequency(ε) only, warm, N = {orders[0]}…{orders[-1]}"),
            (_floored([r["seconds_lambdified"] for r in lp]), _floored([r["error_lambdified"] for r in lp]),
             f"LP lambdified ω(ε), warm, N = {orders[0]}…{orders[-1]}"),
            (_floored([r["seconds"] for r in entry["elliptic"]]), _floored([r["error"] for r in entry["elliptic"]]),
             "elliptic closed form, precision " + _span([r["precision"] for r in entry["elliptic"]])),
            (_floored([r["seconds"] for r in entry["quadrature"]]), _floored([r["error"] for r in entry["quadrature"]]),
             "quadrature, precision " + _span([r["precision"] for r in entry["quadrature"]])),
            (_floored([r["seconds"] for r in entry["dop853"]]), _floored([r["error"] for r in entry["dop853"]]),
             "DOP853, rtol " + _span([r["rtol"] for r in entry["dop853"]], _e0)),
        ]
        _figure(path, curves, title=f"Duffing frequency, ε = {key}: error vs run time" + (" (quick)" if quick else ""),
                x_label="run time (s)", y_label="|ω − ω_ref|",
                notes=["each curve: one point per order / precision / tolerance", "connected in that order"])
        figures.append(path)
        w += [f"![Duffing, ε = {key}: error against run time]({_rel(path)})", ""]
    return w


def _section_unilateral(data: dict, quick: bool, figures: list[Path]) -> list[str]:
    w: list[str] = []
    w += ["### 2. Unilateral spring frequency (κ = 1/3): expansion vs closed form vs shooting vs DOP853", "",
          "`u'' + u + ε (u − 1/3)_+ = 0`, `u(0) = 1`, `u'(0) = 0` (contact while u > 1/3, two switches per period).",
          "", "What is timed (one fresh interpreter, minimum over repeats):", "",
          "* **expansion (cold)**: `lindstedt.expand(\"Max(0, u - 1/3)\", order=N, a0=1, omega0=1, numeric=True)"
          ".frequency(ε)` (30-digit floats), caches dropped as in problem 1 (a warm-up with κ = 1/4 ran first); "
          "*evaluation only* is `.frequency(ε)` on the computed expansion, or a call of its `lambdify(\"frequency\")`; "
          "notes as in problem 1.",
          "* **closed form**: `lindstedt.references.piecewise_linear_exact_frequency(ε, a=1, b=1/3, a0=1, precision=d)`.",
          "* **shooting**: `lindstedt.nnm_point(UnilateralSystem.one_dof(1, a=1, b=\"1/3\"), ε, 1, "
          "modal_amplitude=1.0, tol=…, verify_tol=1.0)` — `one_dof(ω0, a, b)` is `u'' + ω0² u + ε (a u − b)_+`, "
          "so a = 1, b = 1/3 is this problem, and modal amplitude 1 is u(0) = 1 (M = [[1]]). Newton on the exact "
          "(harmonic-arc) flow from the linear guess; `tol` is its tolerance on the scaled residual; "
          "`verify_tol=1.0` makes it return every result (whether the default check 1e-8 would pass is noted). "
          "The system object is built once (untimed).",
          "* **DOP853, restarted**: `solve_ivp(DOP853, rtol, atol = rtol·1e-3)` stopped by a terminal event at "
          "every contact switch u = 1/3 and restarted there with the other linear right-hand side (smooth "
          "segments), ω = π / t½ from the event u' = 0 (upward). **DOP853, through the kink**: the same with "
          "`max(u − 1/3, 0)` in the right-hand side and no switch events.", "",
          f"Error = |ω − ω_ref|; ω_ref is computed in this benchmark from the two harmonic arcs (contact arc "
          f"about u* = εκ/(1+ε) at frequency √(1+ε), free arc of amplitude R; T = 2t₁ + 2π − 2 acos(κ/R)) at "
          f"{REFERENCE_DPS} digits, independently of the library's closed form (which uses the energy; agreement "
          "below each table).", ""]
    for key, entry in data["eps"].items():
        epsilon = float(key)
        w += [f"**ε = {key}** (ω_ref = {entry['reference_own_arcs'][:22]}…)", "",
              "| method | setting | time | evaluation only: `.frequency(ε)` | evaluation only: lambdified | "
              "\\|ω − ω_ref\\| | notes |",
              "| --- | --- | ---: | ---: | ---: | ---: | --- |"]
        for r in entry["expansion"]:
            note = f"expand alone {_t(r['seconds_expand_only'])}; truncation {_g(r['truncation_error'])}"
            if r["validity_warning"]:
                note += "; validity warning"
            if r["error_lambdified"] != r["error"]:
                note += f"; lambdified error {_g(r['error_lambdified'])}"
            w.append(f"| expansion (numeric) + frequency (cold) | N = {r['order']} | {_t(r['seconds_cold'])} | "
                     f"{_t(r['seconds_eval'])} | {_t(r['seconds_lambdified'])} | {_g(r['error'])} | {note} |")
        for r in entry["closed_form"]:
            w.append(f"| closed form (library) | precision = {r['precision']} | {_t(r['seconds'])} | — | — | {_g(r['error'])} | |")
        for r in entry["shooting"]:
            w.append(f"| shooting `nnm_point` | tol = {r['tol']:.0e} | {_t(r['seconds'])} | — | — | {_g(r['error'])} | "
                     f"{r['iterations']} Newton it., {r['flows']} flows, residual {_g(r['residual'])}"
                     f"{'' if r['verified_1e-8'] else ', would fail the default 1e-8 verification'} |")
        for label, name in (("DOP853, restarted at switches", "dop853_restart"),
                            ("DOP853, through the kink", "dop853_through")):
            for r in entry[name]:
                w.append(f"| {label} | rtol = {r['rtol']:.0e} | {_t(r['seconds'])} | — | — | {_g(r['error'])} | "
                         f"{r['nfev']} RHS evaluations, {r['segments']} segment(s) |")
        w += ["", f"References: library closed form − own arcs ({REFERENCE_DPS} digits) = "
                  f"{_g(entry['reference_disagreement'])}.", ""]
        path = FIGURES_DIR / f"method_pairs_unilateral_eps{_eps_tag(epsilon)}.svg"
        ex = entry["expansion"]
        orders = [r["order"] for r in ex]
        shooting = entry["shooting"]
        curves = [
            (_floored([r["seconds_cold"] for r in ex]), _floored([r["error"] for r in ex]),
             f"expansion + .frequency, cold, N = {orders[0]}…{orders[-1]}"),
            (_floored([r["seconds_eval"] for r in ex]), _floored([r["error"] for r in ex]),
             f"expansion .frequency(ε) only, warm, N = {orders[0]}…{orders[-1]}"),
            (_floored([r["seconds_lambdified"] for r in ex]), _floored([r["error_lambdified"] for r in ex]),
             f"expansion lambdified ω(ε), warm, N = {orders[0]}…{orders[-1]}"),
            (_floored([r["seconds"] for r in entry["closed_form"]]), _floored([r["error"] for r in entry["closed_form"]]),
             "closed form, precision " + _span([r["precision"] for r in entry["closed_form"]])),
            (_floored([r["seconds"] for r in shooting]), _floored([r["error"] for r in shooting], PLOT_FLOOR),
             "shooting nnm_point, tol " + _span([r["tol"] for r in shooting], _e0)),
            (_floored([r["seconds"] for r in entry["dop853_restart"]]),
             _floored([r["error"] for r in entry["dop853_restart"]], PLOT_FLOOR), "DOP853 restarted at switches, rtol " + _span([r["rtol"] for r in entry["dop853_restart"]], _e0)),
            (_floored([r["seconds"] for r in entry["dop853_through"]]),
             _floored([r["error"] for r in entry["dop853_through"]], PLOT_FLOOR), "DOP853 through the kink, rtol " + _span([r["rtol"] for r in entry["dop853_through"]], _e0)),
        ]
        _figure(path, curves, title=f"Unilateral spring κ = 1/3, ε = {key}: error vs run time"
                + (" (quick)" if quick else ""), x_label="run time (s)", y_label="|ω − ω_ref|",
                notes=["each curve: one point per order / precision / tolerance", "connected in that order"])
        figures.append(path)
        w += [f"![Unilateral spring, ε = {key}: error against run time]({_rel(path)})", ""]
    return w


def _slope(eps: list[float], errors: list[float], low: float) -> float | None:
    pairs = [(math.log(e), math.log(err)) for e, err in zip(eps, errors) if err > low and e <= 0.03]
    if len(pairs) < 2:
        return None
    mean_x = sum(p[0] for p in pairs) / len(pairs)
    mean_y = sum(p[1] for p in pairs) / len(pairs)
    return sum((x - mean_x) * (y - mean_y) for x, y in pairs) / sum((x - mean_x) ** 2 for x, _ in pairs)


def _section_nnm(data: dict, quick: bool, figures: list[Path]) -> list[str]:
    points = data["points"]
    orders = sorted(data["expansion"], key=int)
    tols = [s["tol"] for s in points[0]["shooting"]]
    springs = ", ".join(f"mass {j} gap {g}" for j, g in NNM_SPRINGS)
    w: list[str] = []
    w += ["### 3. 3-dof NNM frequency: expansion (orders " + ", ".join(orders) + ") vs shooting", "",
          f"`M X'' + K X + ε W (A X − b)_+ = 0`: `UnilateralSystem.chain(3, unilateral=[{', '.join(f'({j}, {g!r})' for j, g in NNM_SPRINGS)}])` "
          f"(unit masses and springs, fixed ends; unilateral springs on {springs} — the one on mass 1 is "
          f"prestressed, engaged at rest; W = Aᵀ). Mode 1 (λ_1 = {data['lambda_1']:.12g}, shape "
          f"{', '.join(f'{v:.4g}' for v in data['mode_shape'])}), modal amplitude u_1(0) = 1.", "",
          "* **expansion**: `lindstedt.nnm(system, mode=1, a0=1, order=k)` gives ω(ε) = Σ ω_n ε^n for every ε at "
          "once; cold = a fresh system object and all caches dropped, minimum over repeats; *evaluation* = "
          "`.frequency(ε)` (float `polyval`). Its release is u_1(0) = a0 = 1, u_k(0) = ε a_k — the same orbit "
          "`nnm_point(modal_amplitude=1.0)` finds.",
          "* **shooting**: `lindstedt.nnm_point(system, ε, 1, modal_amplitude=1.0, tol=…, verify_tol=1.0)` "
          f"(symmetric half-period Newton on the exact flow, from the linear-mode guess; {DEFAULT_SHOOTING_TOL:.0e} is "
          "the default tol), one call per ε, minimum over repeats, the system object built once.",
          f"* **reference**: `nnm_point(..., tol={NNM_REFERENCE_TOL:.0e})` with the default 1e-8 verification; "
          "checked independently by DOP853 (rtol 1e-13, restarted at every switch) from the reference release state: "
          "the ω from its half-period event is in the column *DOP853 check*.", "",
          "Error = |ω − ω_ref| in doubles (0 = the same double).", "",
          "| ε | switches / T | " + " | ".join(f"expansion order {k}" for k in orders) + " | "
          + " | ".join(f"shooting tol {t:.0e}" for t in tols) + " | DOP853 check |",
          "| ---: | ---: | " + " | ".join("---:" for _ in orders) + " | " + " | ".join("---:" for _ in tols) + " | ---: |"]
    for p in points:
        cells = [_g(p["expansion"][k]["error"]) for k in orders]
        shoot = []
        for s in p["shooting"]:
            mark = "" if s["verified_1e-8"] else " ✗"
            shoot.append(_g(s["error"]) + mark)
        w.append(f"| {p['eps']:g} | {p['n_switches']} | " + " | ".join(cells) + " | " + " | ".join(shoot)
                 + f" | {_g(p['dop853_check']['difference'])} |")
    ok = all(p["reference_success"] for p in points)
    w += ["", "✗: the returned orbit would fail nnm_point's default verification (residual > 1e-8). "
          f"References verified: {'all' if ok else 'NOT all — see raw data'} (largest residual "
          f"{_g(max(p['reference_residual'] for p in points))}).", "",
          "Run times:", "",
          "| ε | " + " | ".join(f"shooting tol {t:.0e}" for t in tols) + " | Newton iterations (per tol) | DOP853 check |",
          "| ---: | " + " | ".join("---:" for _ in tols) + " | --- | ---: |"]
    for p in points:
        w.append(f"| {p['eps']:g} | " + " | ".join(_t(s["seconds"]) for s in p["shooting"]) + " | "
                 + ", ".join(str(s["iterations"]) for s in p["shooting"]) + f" | {_t(p['dop853_check']['seconds'])} |")
    w += ["", "| expansion | cold: `nnm(order=k)` | evaluation `.frequency(ε)` | ω_n |", "| ---: | ---: | ---: | --- |"]
    for k in orders:
        e = data["expansion"][k]
        w.append(f"| order {k} | {_t(e['seconds_cold'])} | {_t(e['seconds_eval'])} | "
                 + ", ".join(f"{v:.10g}" for v in e["omega"]) + " |")
    # convergence orders and the crossing
    eps = [p["eps"] for p in points]
    summary = []
    for k in orders:
        slope = _slope(eps, [p["expansion"][k]["error"] for p in points], 1e-13)
        if slope is not None:
            summary.append(f"order {k}: error ∝ ε^{slope:.2f} (fit over ε ≤ 0.03, errors > 1e-13; expected {int(k) + 1})")
    w += ["", "* Convergence: " + "; ".join(summary) + "."]
    main = "2" if "2" in orders else orders[-1]
    next_omega = abs(data["expansion"][orders[-1]]["omega"][int(main) + 1]) if int(orders[-1]) > int(main) else None
    expansion_errors = [p["expansion"][main]["error"] for p in points]
    for index, tol in enumerate(tols):
        shooting_errors = [p["shooting"][index]["error"] for p in points]
        better = [e for e, a, b in zip(eps, expansion_errors, shooting_errors) if a <= b]
        label = f"shooting at tol {tol:.0e}" + (" (default)" if tol == DEFAULT_SHOOTING_TOL else "")
        if not better:
            text = f"{label} is more accurate than the order-{main} expansion at every ε of the grid"
        elif len(better) == len(eps):
            text = f"the order-{main} expansion is at least as accurate as {label} at every ε of the grid"
        else:
            text = (f"the order-{main} expansion is at least as accurate as {label} at ε = "
                    + ", ".join(f"{e:g}" for e in better) + f" ({len(better)} of {len(eps)} ε), less accurate elsewhere")
        w.append(f"* {text[0].upper() + text[1:]}; {label}: error {_g(min(shooting_errors))}…{_g(max(shooting_errors))}, "
                 f"Newton iterations {min(p['shooting'][index]['iterations'] for p in points)}…"
                 f"{max(p['shooting'][index]['iterations'] for p in points)}.")
    if next_omega:
        default_index = tols.index(DEFAULT_SHOOTING_TOL) if DEFAULT_SHOOTING_TOL in tols else len(tols) - 1
        default_error = max(p["shooting"][default_index]["error"] for p in points)
        check = max(p["dop853_check"]["difference"] for p in points)
        floor = max(default_error, check)
        crossing = (floor / next_omega) ** (1 / 3)
        below = [e for e, a in zip(eps, expansion_errors) if a <= floor]
        above = [e for e, a in zip(eps, expansion_errors) if a > floor]
        observed = (f"in the grid the order-{main} error is ≤ {_g(floor)} up to ε = {max(below):g} and above it from "
                    f"ε = {min(above):g}" if below and above else "")
        w.append(f"* Where the expansion's error crosses the shooting accuracy: the shooting accuracy that can be checked "
                 f"here is ≤ {_g(floor)} (default tol vs tol {NNM_REFERENCE_TOL:.0e}: ≤ {_g(default_error)}; reference vs "
                 f"the independent DOP853 check: ≤ {_g(check)}). The order-{main} error is ≈ |ω_{int(main) + 1}| ε³ "
                 f"(|ω_{int(main) + 1}| = {next_omega:.4g}), which equals {_g(floor)} at ε ≈ {crossing:.2g}; {observed}. "
                 "Below that the two agree to rounding; above it the converged shooting is the more accurate one.")
    exp_cost = data["expansion"][main]["seconds_cold"]
    default_index = tols.index(DEFAULT_SHOOTING_TOL) if DEFAULT_SHOOTING_TOL in tols else len(tols) - 1
    shoot_costs = [p["shooting"][default_index]["seconds"] for p in points]
    w.append(f"* Cost: the order-{main} expansion ({_t(exp_cost)} cold) serves every ε, then {_t(data['expansion'][main]['seconds_eval'])} "
             f"per ε; shooting at the default tol costs {_t(min(shoot_costs))}…{_t(max(shoot_costs))} per ε, so the "
             f"expansion is cheaper from about {math.ceil(exp_cost / (sum(shoot_costs) / len(shoot_costs)))} ε values on "
             "— where its ε³ error is acceptable.")
    path_eps = FIGURES_DIR / "method_pairs_nnm_error_vs_eps.svg"
    curves = [(list(eps), _floored([p["expansion"][k]["error"] for p in points], PLOT_FLOOR),
               f"expansion order {k}") for k in orders]
    curves += [(list(eps), _floored([p["shooting"][i]["error"] for p in points], PLOT_FLOOR),
                f"shooting tol {t:.0e}" + (" (default)" if t == DEFAULT_SHOOTING_TOL else ""))
               for i, t in enumerate(tols)]
    _figure(path_eps, curves, title="3-dof chain, NNM mode 1: frequency error vs ε" + (" (quick)" if quick else ""),
            x_label="ε", y_label="|ω − ω_ref|", notes=[f"errors exactly 0 drawn at {_e0(PLOT_FLOOR)}"])
    figures.append(path_eps)
    path_time = FIGURES_DIR / "method_pairs_nnm_error_vs_time.svg"
    chosen = [p for p in points if p["eps"] in (0.01, 0.1)] or points[-2:]
    curves = []
    for p in chosen:
        curves.append((_floored([data["expansion"][k]["seconds_cold"] for k in orders]),
                       _floored([p["expansion"][k]["error"] for k in orders], PLOT_FLOOR),
                       f"expansion, orders {orders[0]}…{orders[-1]} (cold), ε = {p['eps']:g}"))
    for p in chosen:
        curves.append((_floored([s["seconds"] for s in p["shooting"]]), _floored([s["error"] for s in p["shooting"]], PLOT_FLOOR),
                       f"shooting, tol {_e0(tols[0])}…{_e0(tols[-1])}, ε = {p['eps']:g}"))
    _figure(path_time, curves, title="3-dof chain, NNM mode 1: error vs run time" + (" (quick)" if quick else ""),
            x_label="run time (s)", y_label="|ω − ω_ref|",
            notes=[f"errors exactly 0 drawn at {_e0(PLOT_FLOOR)}", "each curve: orders 1…3 or tolerances, in order"])
    figures.append(path_time)
    w += ["", f"![3-dof NNM: error against ε]({_rel(path_eps)})", "",
          f"![3-dof NNM: error against run time]({_rel(path_time)})", ""]
    return w


def run(quick: bool = False) -> str:
    started = time.perf_counter()
    load_start = load_average()
    results: dict[str, Any] = {}
    failures: list[str] = []
    for name in WORKERS:
        outcome = run_worker(sys.executable, SELF, ["--worker", name] + (["--quick"] if quick else []), timeout=600)
        if outcome.status != "ok":
            failures.append(f"{name}: {outcome.status} {outcome.detail}")
            continue
        results[name] = outcome.result
        results[name]["process_wall_seconds"] = outcome.wall
    figures: list[Path] = []
    config = QUICK if quick else FULL
    w = [f"## {TITLE}", "",
         "Protocol: `benchmarks/bench_method_pairs.py` (docstring). One fresh interpreter per problem; every "
         "error is against an independent reference at high precision. Time = minimum over repeats: cold "
         f"expansions {config['cold_repeats']} repeats of one call (caches dropped and `gc.collect()` before each, "
         f"untimed); everything else {config['repeats']} repeats of a loop of ≥ 20 ms, per-call mean (the quadrature "
         f"and the 3-dof shooting: {max(2, config['repeats'] // 2)} and {config['repeats']} repeats of one call; the 3-dof "
         "reference and DOP853 check: one call). Figures: error against run time (or ε) on log–log axes, one point "
         "per setting (order, digits, tolerance).", ""]
    if "duffing" in results:
        w += _section_duffing(results["duffing"], quick, figures)
    if "unilateral" in results:
        w += _section_unilateral(results["unilateral"], quick, figures)
    if "nnm" in results:
        w += _section_nnm(results["nnm"], quick, figures)
    for failure in failures:
        w += [f"**FAILED** worker {failure}", ""]
    raw = {"quick": quick, "config": QUICK if quick else FULL, "reference_dps": REFERENCE_DPS, "kappa": KAPPA,
           "nnm_springs": NNM_SPRINGS, "load_average_start": load_start, "results": results,
           "figures": [_rel(p) for p in figures], "failures": failures}
    raw_path = write_json(RAW_NAME, raw)
    elapsed = time.perf_counter() - started
    w += [f"Raw data: `{raw_path.relative_to(BENCH_DIR).as_posix()}`; figures: "
          + ", ".join(f"`{_rel(p)}`" for p in figures) + f". This section took {elapsed:.0f} s "
          f"(load average at start: {load_start}; at end: {load_average()}).", ""]
    if failures:
        raise RuntimeError("method-pairs workers failed: " + "; ".join(failures))
    return "\n".join(w)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--worker", choices=sorted(WORKERS))
    arguments = parser.parse_args()
    if arguments.worker:
        _worker_main(arguments.worker, arguments.quick)
    else:
        print(run(arguments.quick))
