"""Benchmark (issue 25, item 5 "At FE scale"): strained-coordinates NNMs and forced responses of structural models
against their size N.

Workloads (each measurement in a fresh interpreter; this file is its own worker, ``python -I
bench_structures.py --worker KIND ARGS``, printing one ``@@BENCH-RESULT {json}`` line):

* ``nnm`` — ``lindstedt.nnm(system, 1, a0=1, order=2)`` (30 digits) on

  - the cracked cantilever ``EulerBernoulliBeam(n, cracks=[(n // 4, 10)])`` (EI = ρA = L = 1, a breathing
    crack at x = L/4: a rotational spring k_c = 10 and a unilateral one, gap 0, of stiffness ε), N = 2n + 1;
  - the string-scaled spring–mass chain ``UnilateralSystem.chain(N, [(N // 4, 1/10), (3N // 4, 1/20, −1)],
    mass=1/(N+1), stiffness=N+1)`` (λ₁ → π and the mode shapes → √2 sin πx as N grows, so one ε means the
    same thing at every N), two stops.

  The CPU time (``time.process_time``) of building the model (``beam.system()`` / ``chain``) and of the expansion
  are recorded separately, and the memory as the growth of the peak resident set (``resource.getrusage
  ru_maxrss``) over the baseline after the imports (lindstedt, sympy, mpmath, numpy, scipy) — LAPACK's and
  numpy's buffers included, which ``tracemalloc`` would partly miss, and at no cost to the timing.  Sizes
  grow until one does not finish within the budget (``BUDGET`` CPU seconds; larger sizes are then not run).
  The growth exponents are least-squares slopes of log(time) and log(memory) against log N on the larger half
  of the sizes that finished (small-N overheads excluded).
* accuracy: ``NNMExpansion.frequency(ε)`` against Newton shooting on the exact event-driven flow
  (``lindstedt.nnm_point(system, ε, 1, modal_amplitude=1, initial_guess="expansion")``) at ε = ``EPS`` where
  shooting is affordable; and the FE error of λ₁: the uncracked cantilever's λ₁ by ``sparse_modes`` against
  the closed form (1.8751040687…)², the cracked one's (the 30-digit ω₀ of the expansion, and ``sparse_modes``)
  against the continuous cracked beam (two Euler–Bernoulli segments joined by the rotational spring k_c: an
  8×8 characteristic determinant, solved in mpmath to 30 digits), slopes fitted on the meshes above 8 elements.
* ``phases`` — where the time goes at large N: the sparse assembly and ``sparse_modes`` (1 mode), the exact
  ``beam.system()``, the dense float modes ``system.modes()``, the 30-digit ``system.modal_coupling(30)``, each
  under its own CPU budget; and a ``cProfile`` of ``nnm`` at the first size past the budget, stopped by a CPU
  timer.
* ``forced`` — ``lindstedt.frequency_response(ForcedSystem(system, load, rayleigh=(α, β)), 0.8 λ₁, 1.5 λ₁,
  epsilon=…)`` through the folds of mode 1 on 100-dof models with two contact elements: the cantilever beam
  of 50 elements (N = 100) between two stops at its tip (w_tip > 1, −w_tip > 1), and the string-scaled chain of
  100 masses with the two stops above.
* ``reduced`` — the cracked cantilever reduced by ``lindstedt.ResidualFlexibility(modes=K).reduce(beam)`` (the K
  lowest modes and one residual-flexibility vector per element, computed in multiprecision) and
  ``nnm(reduced.system, 1, a0=1, order=2)``: the CPU time of building the beam, of the reduction and of the
  expansion, the memory (as above), the reduction's ``message`` and iterations, the 30-digit ω₀, ω₁, ω₂.
  Accuracy: against the full model's expansion (worker ``full``) where it is affordable, and the FE error of ω₀
  against the continuous cracked beam at every mesh (the reduction works in multiprecision, so float64 does not
  floor it as it floors ``sparse_modes``).

Issue targets (reported, never asserted): NNM order 2 of a cracked beam with 10⁴ dof in seconds, memory
O(N·elements); the forced response of a 100-dof model with two contact elements through its folds in under a
minute.

Standalone: ``python benchmarks/bench_structures.py [--quick]`` prints the markdown section and writes
``benchmarks/results/structures.json`` (``structures.quick.json`` in quick mode).  ``--only PART`` (``nnm``: the
beam and chain series, the FE errors and the profile; ``phases``; ``forced``; ``reduced``) runs that part alone,
merges its results into the stored ones (the other parts keep theirs) and, outside quick mode, rewrites this
section of ``benchmarks/README.md`` in place.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import RESULTS_DIR, emit, format_error as _e, format_seconds as _t, load_average, run_worker, write_json  # noqa: E402

TITLE = "Structures at FE scale (issue 25): NNM expansion and forced response against N"
SELF = Path(__file__).resolve()
BUDGET = 60.0  # CPU seconds per measurement; a size past it ends its series
MEMORY_LIMIT = 6 << 30  # address-space limit of a worker (bytes): a runaway size fails instead of swapping
EPS = 0.1  # ε of the accuracy check (crack: k_c = 10, so ±1 %; chain: stops of stiffness ε against λ₁² ≈ π²)
K_CRACK = 10
BETA_CANTILEVER = 1.8751040687119611664453082410782141625701117335310699882454137131  # first root of 1 + cos β cosh β
FULL = {
    "beam": [12, 24, 48, 72, 100, 200, 500, 1000, 2500, 5000],  # elements; N = 2n + 1
    "chain": [20, 50, 100, 200, 500, 1000, 2000, 5000, 10000],
    "shoot": {"beam": 50, "chain": 100},  # shooting up to this N
    "fe": [8, 16, 32, 64, 128, 256, 512, 1024, 2048, 5000],
    "phases": [200, 1000, 5000],
    "forced": ["beam", "chain", "beam_reduced4", "beam_reduced8"],
    "reduced": {"elements": [100, 400, 1000, 2500, 5000], "modes": [4, 8], "full_max": 801},  # full model up to N
}
QUICK = {"beam": [12, 24], "chain": [20, 50], "shoot": {"beam": 30, "chain": 20}, "fe": [8, 16, 32],
         "phases": [], "forced": ["chain10"], "reduced": {"elements": [8, 16], "modes": [2, 4], "full_max": 33}}
PARTS = ("nnm", "phases", "forced", "forced_reduced", "reduced")  # what --only can run alone


# --------------------------------------------------------------------------------------------------- workers
def _rss_mb() -> float:
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # Linux: KiB


def _imports() -> Any:
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
    import mpmath  # noqa: F401
    import numpy  # noqa: F401
    import scipy.linalg  # noqa: F401
    import scipy.sparse.linalg  # noqa: F401
    import sympy  # noqa: F401

    import lindstedt

    for name in ("nnm", "nnm_point", "EulerBernoulliBeam", "UnilateralSystem", "ForcedSystem", "frequency_response",
                 "sparse_modes", "ResidualFlexibility"):
        getattr(lindstedt, name)  # the lazy facade's modules, imported before the baseline
    return lindstedt


def _model(lindstedt: Any, kind: str, size: int) -> Any:
    if kind == "beam":
        return lindstedt.EulerBernoulliBeam(size, cracks=[(size // 4, K_CRACK)]).system()
    return lindstedt.UnilateralSystem.chain(size, unilateral=[(size // 4, "1/10"), (3 * size // 4, "1/20", -1)],
                                            mass=f"1/{size + 1}", stiffness=size + 1)


def _omega(expansion: Any) -> float:
    """Σ ω_n ε^n at ε = EPS from the computed coefficients (``expansion.frequency(ε)`` would first derive the order
    n + 1 term for its validity warning: at N = 1000 that takes minutes, far more than the expansion itself)."""
    return float(sum(float(value) * EPS**k for k, value in enumerate(expansion.omega)))


def _worker_nnm(kind: str, size: int) -> dict[str, Any]:
    import time

    lindstedt = _imports()
    baseline = _rss_mb()
    start = time.process_time()
    system = _model(lindstedt, kind, size)
    built = time.process_time()
    expansion = lindstedt.nnm(system, 1, 1.0, order=2)
    done = time.process_time()
    out = {"kind": kind, "size": size, "n_dof": system.n_dof, "build_cpu": built - start, "nnm_cpu": done - built,
           "memory_mb": _rss_mb() - baseline, "baseline_mb": baseline,
           "omega": [str(value) for value in expansion.omega], "omega_eps": _omega(expansion)}
    return out


def _worker_shoot(kind: str, size: int) -> dict[str, Any]:
    import time

    lindstedt = _imports()
    system = _model(lindstedt, kind, size)
    expansion = lindstedt.nnm(system, 1, 1.0, order=2)
    start = time.process_time()
    point = lindstedt.nnm_point(system, EPS, 1, modal_amplitude=1.0, initial_guess="expansion")
    frequency = float(point.frequency)
    return {"shoot_cpu": time.process_time() - start, "shoot_success": bool(point.success), "shoot_message": point.message[:160],
            "shoot_frequency": frequency, "error": abs(_omega(expansion) - frequency) / frequency}


def _worker_reduced(size: int, modes: int) -> dict[str, Any]:
    import time

    lindstedt = _imports()
    baseline = _rss_mb()
    start = time.process_time()
    beam = lindstedt.EulerBernoulliBeam(size, cracks=[(size // 4, K_CRACK)])
    built = time.process_time()
    out: dict[str, Any] = {"size": size, "modes": modes, "n_dof": beam.n_dof, "build_cpu": built - start, "baseline_mb": baseline}
    try:
        reduced = lindstedt.ResidualFlexibility(modes=modes).reduce(beam)
    except lindstedt.LindstedtError as error:
        out.update(status="reduce refused", message=f"{type(error).__name__}: {error}"[:400], reduce_cpu=time.process_time() - built,
                   memory_mb=_rss_mb() - baseline)
        return out
    reduced_at = time.process_time()
    out.update(reduce_cpu=reduced_at - built, reduce_memory_mb=_rss_mb() - baseline, success=bool(reduced.success),
               message=reduced.message, iterations=int(reduced.iterations), solves=int(reduced.solves),
               bandwidth=int(reduced.bandwidth), reduced_dof=int(reduced.system.n_dof))
    try:
        expansion = lindstedt.nnm(reduced.system, 1, 1.0, order=2)
    except lindstedt.LindstedtError as error:  # a ResonanceError of the reduced model, say
        out.update(status="nnm refused", nnm_message=f"{type(error).__name__}: {error}"[:400],
                   nnm_cpu=time.process_time() - reduced_at, memory_mb=_rss_mb() - baseline)
        return out
    out.update(status="ok", nnm_cpu=time.process_time() - reduced_at, memory_mb=_rss_mb() - baseline,
               omega=[str(value) for value in expansion.omega])
    return out


def _worker_full(size: int) -> dict[str, Any]:
    """The reference of ``reduced``: the full cracked cantilever's expansion (all N modes, 30 digits)."""
    import time

    lindstedt = _imports()
    baseline = _rss_mb()
    start = time.process_time()
    expansion = lindstedt.nnm(lindstedt.EulerBernoulliBeam(size, cracks=[(size // 4, K_CRACK)]).system(), 1, 1.0, order=2)
    return {"size": size, "n_dof": 2 * size + 1, "cpu": time.process_time() - start, "memory_mb": _rss_mb() - baseline,
            "omega": [str(value) for value in expansion.omega]}


def _cracked_cantilever_lambda1(position: float, spring: float, digits: int = 30) -> Any:
    """λ₁ = β² of the continuous cantilever (EI = ρA = L = 1) with a rotational spring k_c at x = c: w = Σ a_i
    (cos, sin, cosh, sinh)(βx) on each segment; w(0) = w'(0) = 0, at c continuity of w, w'', w''' and
    w''(c) = k_c (w₂'(c) − w₁'(c)), at L w'' = w''' = 0 — the zero of the 8×8 determinant near the intact root."""
    import mpmath

    with mpmath.workdps(digits + 10):
        c, k = mpmath.mpf(position), mpmath.mpf(spring)

        def basis(beta: Any, x: Any, derivative: int) -> list[Any]:
            s, co, sh, ch = mpmath.sin(beta * x), mpmath.cos(beta * x), mpmath.sinh(beta * x), mpmath.cosh(beta * x)
            rows = [[co, s, ch, sh], [-s, co, sh, ch], [-co, -s, ch, sh], [s, -co, sh, ch]]
            return [beta**derivative * v for v in rows[derivative]]

        def determinant(beta: Any) -> Any:
            zero = [0, 0, 0, 0]
            rows = [basis(beta, 0, 0) + zero, basis(beta, 0, 1) + zero]
            rows += [basis(beta, c, d) + [-v for v in basis(beta, c, d)] for d in (0, 2, 3)]
            rows.append([a + k * b for a, b in zip(basis(beta, c, 2), basis(beta, c, 1))] + [-k * v for v in basis(beta, c, 1)])
            rows += [zero + basis(beta, 1, 2), zero + basis(beta, 1, 3)]
            return mpmath.det(mpmath.matrix(rows))

        # bracket the first root below the intact one (a softer joint lowers it), in steps of 1 %
        upper = mpmath.mpf(BETA_CANTILEVER) * mpmath.mpf("1.0001")
        f_upper = determinant(upper)
        for i in range(1, 100):
            lower = mpmath.mpf(BETA_CANTILEVER) * (1 - mpmath.mpf(i) / 100)
            f_lower = determinant(lower)
            if mpmath.sign(f_upper) != mpmath.sign(f_lower):
                break
            upper, f_upper = lower, f_lower
        beta = mpmath.findroot(determinant, (lower, upper), solver="anderson")
        return beta**2


def _worker_fe(meshes: list[int]) -> dict[str, Any]:
    import time

    import mpmath

    lindstedt = _imports()
    intact_exact = BETA_CANTILEVER**2
    cracked_exact = _cracked_cantilever_lambda1(0.25, K_CRACK)
    rows = []
    for n in meshes:
        t0 = time.process_time()
        intact = float(lindstedt.EulerBernoulliBeam(n).modes(1).frequencies[0])
        cracked = float(lindstedt.EulerBernoulliBeam(n, cracks=[(n // 4, K_CRACK)]).modes(1).frequencies[0])
        rows.append({"n_elements": n, "n_dof_cracked": 2 * n + 1, "intact_error": abs(intact / intact_exact - 1),
                     "cracked_error": float(abs(cracked / cracked_exact - 1)), "cpu": time.process_time() - t0})
    return {"intact_exact": intact_exact, "cracked_exact": mpmath.nstr(cracked_exact, 30), "rows": rows}


def _budgeted(seconds: float, call: Any) -> tuple[Any, float, str]:
    """(value, CPU seconds, status) of call() stopped by a CPU timer after ``seconds``."""
    import signal
    import time

    class _Budget(Exception):
        pass

    def stop(*_: Any) -> None:
        raise _Budget

    signal.signal(signal.SIGPROF, stop)
    signal.setitimer(signal.ITIMER_PROF, seconds)
    start = time.process_time()
    try:
        value, status = call(), "ok"
    except _Budget:
        value, status = None, f"stopped at the budget ({seconds:.0f} s CPU)"
    except MemoryError:
        value, status = None, f"MemoryError (address space limited to {MEMORY_LIMIT >> 30} GiB)"
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
    return value, time.process_time() - start, status


def _worker_phases(size: int, budget: float) -> dict[str, Any]:
    lindstedt = _imports()
    baseline = _rss_mb()
    beam = lindstedt.EulerBernoulliBeam(size, cracks=[(size // 4, K_CRACK)])
    phases: list[dict[str, Any]] = []

    def phase(name: str, call: Any) -> Any:
        value, cpu, status = _budgeted(budget, call)
        phases.append({"phase": name, "cpu": cpu, "status": status, "memory_mb": _rss_mb() - baseline})
        return value

    phase("sparse M, K (float assembly)", lambda: (beam.M, beam.K))
    phase("sparse_modes(M, K, 1) (shift-invert Lanczos)", lambda: beam.modes(1))
    system = phase("beam.system() (exact sympy matrices, dense float copies)", beam.system)
    if system is not None:
        phase("system.modes() (dense float64 eigh, all N modes)", system.modes)
        phase("system.modal_coupling(30) (all N modes to 30 digits)", lambda: system.modal_coupling(30))
    return {"size": size, "n_dof": beam.n_dof, "phases": phases}


def _worker_profile(kind: str, size: int, budget: float) -> dict[str, Any]:
    import cProfile
    import io
    import pstats

    lindstedt = _imports()
    system = _model(lindstedt, kind, size)
    profile = cProfile.Profile()
    _, cpu, status = _budgeted(budget, lambda: profile.runcall(lindstedt.nnm, system, 1, 1.0, order=2))
    text = io.StringIO()
    stats = pstats.Stats(profile, stream=text)
    stats.sort_stats("cumulative").print_stats(18)
    stats.sort_stats("tottime").print_stats(10)
    lines = [line for line in text.getvalue().splitlines() if line.strip() and "/" in line or "ncalls" in line]
    return {"kind": kind, "size": size, "n_dof": system.n_dof, "cpu": cpu, "status": status, "profile": lines}


def _worker_forced(model: str) -> dict[str, Any]:
    import time

    import numpy as np
    import sympy

    lindstedt = _imports()
    reduction = None
    if model.startswith("beam"):  # cantilever, 50 elements (N = 100), stops on both sides of the tip at distance 1
        beam = lindstedt.EulerBernoulliBeam(50)
        exact = beam.system()
        tip = beam.index("w50")
        A = sympy.zeros(2, beam.n_dof)
        A[0, tip], A[1, tip] = 1, -1
        system = lindstedt.UnilateralSystem(M=exact.M_exact, K=exact.K_exact, A=A, b=[1, 1])
        where, epsilon, load_value = tip, 3.0, "1/15"
        if model.startswith("beam_reduced"):  # K modes + the residual vectors of the stops and the load (one: all at the tip)
            start = time.process_time()
            shape = [sympy.Rational(load_value) if i == tip else 0 for i in range(beam.n_dof)]
            reduction = lindstedt.ResidualFlexibility(modes=int(model[len("beam_reduced"):])).reduce(
                (exact.M_exact, exact.K_exact), A=A, b=[1, 1], loads=shape)
            reduction_cpu = time.process_time() - start
            system = reduction.system
    else:  # string-scaled chain of 100 (chain10: 10) masses, the two stops of the nnm workload, gaps 1
        size = 10 if model == "chain10" else 100
        system = lindstedt.UnilateralSystem.chain(size, unilateral=[(size // 4, 1), (3 * size // 4, 1, -1)],
                                                  mass=f"1/{size + 1}", stiffness=size + 1)
        where, epsilon, load_value = size // 2, 10.0, "1/40"
    lam = system.modes().frequencies
    if reduction is not None:
        load = list(reduction.loads[0])
    else:
        load = [0] * system.n_dof
        load[where] = load_value
    zeta = 0.01
    problem = lindstedt.ForcedSystem(system, load, rayleigh=(zeta * float(lam[0]), zeta / float(lam[0])))  # ζ₁ = 1 %
    out: dict[str, Any] = {"model": model, "n_dof": system.n_dof, "epsilon": epsilon, "load": f"{load_value} at dof {where}",
                           "lambda1": float(lam[0]), "lambda_max": float(lam[-1]), "start": 0.8, "stop": 1.5}
    if reduction is not None:
        out.update(n_dof=reduction.n_dof, reduced_dof=system.n_dof, reduction_cpu=reduction_cpu,
                   reduction_message=reduction.message)
    start = time.process_time()
    try:
        response, cpu, status = _budgeted(
            5 * BUDGET, lambda: lindstedt.frequency_response(problem, 0.8 * float(lam[0]), 1.5 * float(lam[0]), epsilon=epsilon))
    except lindstedt.LindstedtError as error:
        out.update(cpu=time.process_time() - start, status="refused", message=str(error)[:600])
        return out
    out.update(cpu=cpu, status=status)
    if response is not None:
        out.update(success=bool(response.success), message=response.message[:200], points=len(response.points),
                   flow_evaluations=int(response.flow_evaluations), newton_iterations=int(response.newton_iterations),
                   bifurcations=[[b.kind, float(b.frequency) / float(lam[0])] for b in response.bifurcations],
                   peak=None if reduction is not None else float(np.max(np.abs(np.asarray(response.amplitudes)[:, where]))))
    return out


def _worker(argv: list[str]) -> None:
    kind = argv[0]
    if kind == "nnm":
        emit(_worker_nnm(argv[1], int(argv[2])))
    elif kind == "shoot":
        emit(_worker_shoot(argv[1], int(argv[2])))
    elif kind == "fe":
        emit(_worker_fe(json.loads(argv[1])))
    elif kind == "phases":
        emit(_worker_phases(int(argv[1]), float(argv[2])))
    elif kind == "profile":
        emit(_worker_profile(argv[1], int(argv[2]), float(argv[3])))
    elif kind == "forced":
        emit(_worker_forced(argv[1]))
    elif kind == "reduced":
        emit(_worker_reduced(int(argv[1]), int(argv[2])))
    elif kind == "full":
        emit(_worker_full(int(argv[1])))
    else:
        raise SystemExit(f"unknown worker {kind!r}")


# ------------------------------------------------------------------------------------------------- orchestration
def _slope(xs: list[float], ys: list[float]) -> float | None:
    """Least-squares slope of log y against log x (None below two points)."""
    pairs = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if x > 0 and y and y > 0]
    if len(pairs) < 2:
        return None
    mx = sum(p[0] for p in pairs) / len(pairs)
    my = sum(p[1] for p in pairs) / len(pairs)
    return sum((p[0] - mx) * (p[1] - my) for p in pairs) / sum((p[0] - mx) ** 2 for p in pairs)


def _top_half_slope(rows: list[dict[str, Any]], key: str, x: str = "n_dof") -> float | None:
    top = sorted(rows, key=lambda r: r[x])[len(rows) // 2:] if len(rows) >= 3 else rows
    return _slope([r[x] for r in top], [r[key] for r in top])


def _log(text: str) -> None:
    print(f"[structures] {text}", file=sys.stderr, flush=True)


def _series(kind: str, sizes: list[int], shoot_max: int) -> tuple[list[dict[str, Any]], dict[str, Any] | None]:
    rows, stopped = [], None
    for size in sizes:
        n_dof = 2 * size + 1 if kind == "beam" else size
        outcome = run_worker(sys.executable, SELF, ["--worker", "nnm", kind, size], timeout=BUDGET + 30)
        if outcome.status != "ok":
            stopped = {"size": size, "n_dof": n_dof, "status": outcome.status, "detail": outcome.detail, "wall": outcome.wall}
            _log(f"{kind} N = {n_dof}: {outcome.status} {outcome.detail}")
            break
        row = outcome.result
        row["cpu"] = row["build_cpu"] + row["nnm_cpu"]
        rows.append(row)
        _log(f"{kind} N = {n_dof}: {row['cpu']:.2f} s, {row['memory_mb']:.0f} MB")
        if n_dof <= shoot_max:  # its own worker and budget: a slow shooting does not end the series
            shot = run_worker(sys.executable, SELF, ["--worker", "shoot", kind, size], timeout=2 * BUDGET + 30)
            row.update(shot.result if shot.status == "ok" else {"shoot_success": False, "shoot_message": f"{shot.status} {shot.detail}"})
        if row["cpu"] > BUDGET:
            stopped = {"size": size, "n_dof": n_dof, "status": "over budget", "detail": f"{row['cpu']:.0f} s CPU", "wall": outcome.wall}
            break
    return rows, stopped


def _relative(value: str, reference: Any) -> float:
    import mpmath

    with mpmath.workdps(40):
        return float(abs(mpmath.mpf(value) / mpmath.mpf(reference) - 1))


def _reduced(plan: dict[str, Any]) -> dict[str, Any]:
    """The ``reduced`` part: the full model's expansion where affordable, then one series per K kept."""
    import mpmath

    out: dict[str, Any] = {"load_average_at_start": load_average(), **plan}
    exact = _cracked_cantilever_lambda1(0.25, K_CRACK)  # mpmath only, in this process
    out["cracked_exact"] = mpmath.nstr(exact, 30)
    full: dict[int, dict[str, Any]] = {}
    for size in plan["elements"]:
        if 2 * size + 1 <= plan["full_max"]:  # its own worker and budget: a slow reference does not end a series
            outcome = run_worker(sys.executable, SELF, ["--worker", "full", size], timeout=2 * BUDGET + 30)
            full[size] = outcome.result if outcome.status == "ok" else {"size": size, "status": outcome.status, "detail": outcome.detail}
            _log(f"full model N = {2 * size + 1}: {outcome.status}" + (f", {outcome.result['cpu']:.1f} s" if outcome.status == "ok" else ""))
    out["full"] = list(full.values())
    out["series"] = []
    for modes in plan["modes"]:
        rows, stopped = [], None
        for size in plan["elements"]:
            n_dof = 2 * size + 1
            outcome = run_worker(sys.executable, SELF, ["--worker", "reduced", size, modes], timeout=3 * BUDGET + 60)
            if outcome.status != "ok":
                stopped = {"size": size, "n_dof": n_dof, "status": outcome.status, "detail": outcome.detail, "wall": outcome.wall}
                _log(f"reduced K = {modes}, N = {n_dof}: {outcome.status} {outcome.detail}")
                break
            row = outcome.result
            row["cpu"] = row["build_cpu"] + row["reduce_cpu"] + row.get("nnm_cpu", 0.0)
            rows.append(row)
            _log(f"reduced K = {modes}, N = {n_dof}: {row['status']}, reduce {row['reduce_cpu']:.2f} s, nnm {row.get('nnm_cpu', 0):.2f} s, "
                 f"{row['memory_mb']:.0f} MB; {row.get('message', '')}")
            if row["status"] != "ok":
                stopped = {"size": size, "n_dof": n_dof, "status": row["status"], "detail": row.get("nnm_message", row.get("message", "")),
                           "wall": outcome.wall}
                break
            row["omega0_fe_error"] = _relative(row["omega"][0], exact)
            reference = full.get(size, {}).get("omega")
            if reference:
                row["errors_vs_full"] = [_relative(a, b) for a, b in zip(row["omega"], reference)]
            if row["cpu"] > BUDGET:
                stopped = {"size": size, "n_dof": n_dof, "status": "over budget", "detail": f"{row['cpu']:.0f} s CPU", "wall": outcome.wall}
                break
        done = [r for r in rows if r["status"] == "ok"]
        out["series"].append({"modes": modes, "rows": rows, "stopped": stopped,
                              "reduce_time_exponent": _top_half_slope(done, "reduce_cpu"),
                              "time_exponent": _top_half_slope(done, "cpu"),
                              "memory_exponent": _top_half_slope(done, "memory_mb"),
                              "fe_slope": _slope([r["size"] for r in done], [r["omega0_fe_error"] for r in done])})
    out["load_average_at_end"] = load_average()
    return out


def run(quick: bool = False, only: str | None = None) -> str:
    """Run every part (or ``only`` that one, merged into the stored results); return the markdown section."""
    plan = QUICK if quick else FULL
    name = "structures" + (".quick" if quick else "") + ".json"
    stored = RESULTS_DIR / name
    data: dict[str, Any] = json.loads(stored.read_text()) if only and stored.exists() else {}
    data.update({"budget_cpu_s": BUDGET, "epsilon": EPS, "k_crack": K_CRACK,
                 "memory": "growth of ru_maxrss over the post-import baseline (MB)"})
    if only is None:
        data["load_average_at_start"] = load_average()
    if only in (None, "nnm"):
        _nnm(plan, data, quick)
    if only in (None, "phases"):
        data["phases"] = []
        for size in plan["phases"]:
            outcome = run_worker(sys.executable, SELF, ["--worker", "phases", size, BUDGET / 2], timeout=3 * BUDGET + 60)
            data["phases"].append(outcome.result if outcome.status == "ok" else {"size": size, "status": outcome.status, "detail": outcome.detail})
            _log(f"phases n = {size}: {outcome.status}")
    if only in (None, "forced", "forced_reduced"):
        kept = [f for f in data.get("forced", []) if not f["model"].startswith("beam_reduced")] if only == "forced_reduced" else []
        data["forced"] = kept
        for model in plan["forced"]:
            if only == "forced_reduced" and not model.startswith("beam_reduced"):
                continue
            outcome = run_worker(sys.executable, SELF, ["--worker", "forced", model], timeout=5 * BUDGET + 60)
            data["forced"].append(outcome.result if outcome.status == "ok" else {"model": model, "status": outcome.status,
                                                                                 "detail": outcome.detail, "wall": outcome.wall})
            _log(f"forced {model}: {outcome.status}")
    if only in (None, "reduced"):
        data["reduced"] = _reduced(plan["reduced"])
    if only is None:
        data["load_average_at_end"] = load_average()
    write_json(name, data)
    return _markdown(data, quick)


def _nnm(plan: dict[str, Any], data: dict[str, Any], quick: bool) -> None:
    """The ``nnm`` part: the beam and chain series, the FE errors of λ₁, the profile past the beam's budget."""
    for kind in ("beam", "chain"):
        rows, stopped = _series(kind, plan[kind], plan["shoot"][kind])
        data[kind] = {"rows": rows, "stopped": stopped, "time_exponent": _top_half_slope(rows, "cpu"),
                      "nnm_time_exponent": _top_half_slope(rows, "nnm_cpu"),
                      "memory_exponent": _top_half_slope(rows, "memory_mb")}
    fe = run_worker(sys.executable, SELF, ["--worker", "fe", json.dumps(plan["fe"])], timeout=600)
    data["fe"] = fe.result if fe.status == "ok" else {"status": fe.status, "detail": fe.detail}
    if fe.status == "ok":
        rows = [r for r in fe.result["rows"] if r["n_elements"] <= 32]  # above, float64 round-off ~eps (L/h)^4
        data["fe"]["intact_slope"] = _slope([r["n_elements"] for r in rows], [r["intact_error"] for r in rows])
        data["fe"]["cracked_slope"] = _slope([r["n_elements"] for r in rows], [r["cracked_error"] for r in rows])
        exact = float(fe.result["cracked_exact"])
        for row in data["beam"]["rows"]:
            row["lambda1_fe_error"] = abs(float(row["omega"][0]) / exact - 1)
        beam_rows = data["beam"]["rows"]
        data["fe"]["cracked_30_digit_slope"] = _slope([(r["n_dof"] - 1) / 2 for r in beam_rows], [r["lambda1_fe_error"] for r in beam_rows])
    data["profile"] = None
    if not quick:
        stopped = data["beam"]["stopped"]
        size = stopped["size"] if stopped else plan["beam"][-1]
        outcome = run_worker(sys.executable, SELF, ["--worker", "profile", "beam", size, BUDGET], timeout=2 * BUDGET + 60)
        data["profile"] = outcome.result if outcome.status == "ok" else {"status": outcome.status, "detail": outcome.detail}


def _fmt_exp(value: float | None) -> str:
    return "—" if value is None else f"{value:.2f}"


def _markdown(data: dict[str, Any], quick: bool) -> str:
    lines = [f"## {TITLE}", ""]
    if quick:
        lines += ["**Quick mode: small sizes only, not the reference numbers.**", ""]
    lines += [
        "Fresh interpreter per measurement; CPU time (`time.process_time`); memory = growth of the peak resident set",
        "(`ru_maxrss`) over the baseline after the imports. A series stops at the first size that does not finish in",
        f"{data['budget_cpu_s']:.0f} s CPU. Exponents: log–log least-squares slopes on the larger half of the sizes that",
        f"finished. Accuracy: |ω_expansion(ε) − ω_shooting| / ω at ε = {data['epsilon']} (shooting on the exact flow,",
        "where affordable). Load average (1, 5, 15 min) at start "
        f"{data['load_average_at_start']}, at end {data['load_average_at_end']}.",
        "",
    ]
    names = {"beam": f"Cracked cantilever `EulerBernoulliBeam(n, cracks=[(n // 4, {data['k_crack']})])`, N = 2n + 1, "
                     "`nnm(system, 1, a0=1, order=2)`",
             "chain": "Chain of N masses (mass 1/(N+1), springs N+1), stops at N/4 (gap 1/10) and 3N/4 (gap 1/20, other side), "
                      "`nnm(system, 1, a0=1, order=2)`"}
    for kind in [kind for kind in ("beam", "chain") if kind in data]:
        part = data[kind]
        lines += [f"**{names[kind]}**", "",
                  "| N | build (s) | nnm (s) | total (s) | memory (MB) | ω₀ | error vs shooting at ε | shooting (s) |"
                  + (" λ₁ FE error |" if kind == "beam" else ""),
                  "|---:|---:|---:|---:|---:|---:|---:|---:|" + ("---:|" if kind == "beam" else "")]
        for r in part["rows"]:
            shoot = _e(r.get("error")) if r.get("shoot_success", True) else "shooting: " + r["shoot_message"][:40]
            lines.append(f"| {r['n_dof']} | {r['build_cpu']:.3g} | {r['nnm_cpu']:.3g} | {r['cpu']:.3g} | {r['memory_mb']:.0f} | "
                         f"{float(r['omega'][0]):.10g} | {shoot} | {_t(r.get('shoot_cpu'))} |"
                         + (f" {_e(r.get('lambda1_fe_error'))} |" if kind == "beam" else ""))
        stopped = part["stopped"]
        if stopped:
            lines.append(f"| {stopped['n_dof']} | — | **{stopped['status']}** ({stopped['detail'].split('Error: ')[-1][:200]}) | | | | | |"
                         + (" |" if kind == "beam" else ""))
        lines += ["", f"Growth exponents (larger half): total time N^{_fmt_exp(part['time_exponent'])}, "
                      f"nnm alone N^{_fmt_exp(part['nnm_time_exponent'])}, memory N^{_fmt_exp(part['memory_exponent'])}.", ""]
    fe = data.get("fe", {})
    if "rows" in fe:
        lines += [f"**FE error of λ₁** (cantilever; intact against (1.8751040687…)² = {fe['intact_exact']:.12g}, cracked "
                  f"(k_c = {data['k_crack']} at L/4) against the continuous cracked beam λ₁ = {float(fe['cracked_exact']):.15g}; "
                  "`sparse_modes`, float64)", "",
                  "| elements | N (cracked) | intact rel. error | cracked rel. error |", "|---:|---:|---:|---:|"]
        lines += [f"| {r['n_elements']} | {r['n_dof_cracked']} | {_e(r['intact_error'])} | {_e(r['cracked_error'])} |" for r in fe["rows"]]
        lines += ["", f"Fitted slopes (float64 `sparse_modes`, n ≤ 32): intact h^{_fmt_num(fe.get('intact_slope'))}, "
                      f"cracked h^{_fmt_num(fe.get('cracked_slope'))}; beyond, float64 round-off ~eps·(L/h)⁴ takes over "
                      "(1e-3 at 10⁴ dof). The 30-digit ω₀ of the expansion (column λ₁ FE error above) follows "
                      f"h^{_fmt_num(fe.get('cracked_30_digit_slope'))} over every mesh that ran.", ""]
    if data.get("reduced"):
        lines += _reduced_markdown(data["reduced"], data["budget_cpu_s"])
    if data.get("phases"):
        lines += ["**Where the time goes on the cracked beam** (each phase under its own CPU budget; memory over the import baseline)", "",
                  "| N | phase | CPU (s) | status | memory (MB) |", "|---:|---|---:|---|---:|"]
        for entry in data["phases"]:
            if "phases" not in entry:
                lines.append(f"| n = {entry['size']} | worker | — | {entry['status']}: {entry['detail'][:100]} | — |")
                continue
            for p in entry["phases"]:
                lines.append(f"| {entry['n_dof']} | {p['phase']} | {p['cpu']:.3g} | {p['status']} | {p['memory_mb']:.0f} |")
        lines.append("")
    profile = data.get("profile")
    if profile and "profile" in profile:
        lines += [f"**cProfile of `nnm` on the cracked beam at N = {profile['n_dof']}** ({profile['status']}, {profile['cpu']:.0f} s CPU; top entries)",
                  "", "```", *profile["profile"][:34], "```", ""]
    if data.get("forced"):
        lines += ["**Forced response through the folds of mode 1** (`frequency_response(ForcedSystem(..., rayleigh=(ζλ₁, ζ/λ₁)), "
                  "0.8 λ₁, 1.5 λ₁, epsilon=ε)`, ζ₁ = 1 %)", "",
                  "`beam_reducedK`: the beam reduced first by `ResidualFlexibility(modes=K).reduce((M, K), A, b, loads=P)` "
                  "(K modes + one residual vector: the stops and the load act on one dof); CPU = reduction + response.", "",
                  "| model | N | ε, load | λ_max/λ₁ | CPU (s) | status | points | flow evaluations | bifurcations (Ω/λ₁) |",
                  "|---|---:|---|---:|---:|---|---:|---:|---|"]
        for f in data["forced"]:
            if "lambda1" not in f:
                lines.append(f"| {f['model']} | — | — | — | — | {f['status']}: {f.get('detail', '')[:120]} | | | |")
                continue
            bif = ", ".join(f"{kind} {value:.4f}" for kind, value in f.get("bifurcations", [])) or "—"
            status = f["status"] if f["status"] != "ok" else ("success" if f.get("success") else "failed: " + f.get("message", ""))
            if f["status"] == "refused":
                status = "refused: " + f["message"][:260]
            size = f"{f['n_dof']} → {f['reduced_dof']}" if "reduced_dof" in f else f"{f['n_dof']}"
            cpu = (f"{f['reduction_cpu']:.3g} + {f['cpu']:.3g}" if "reduction_cpu" in f else f"{f['cpu']:.3g}")
            lines.append(f"| {f['model']} | {size} | {f['epsilon']:g}, {f['load']} | {f['lambda_max'] / f['lambda1']:.3g} | "
                         f"{cpu} | {status} | {f.get('points', '—')} | {f.get('flow_evaluations', '—')} | {bif} |")
        lines.append("")
    lines += _targets(data)
    return "\n".join(lines)


def _reduced_markdown(part: dict[str, Any], budget: float) -> list[str]:
    full = {entry["size"]: entry for entry in part["full"]}
    lines = ["**Cracked cantilever reduced to K modes plus one residual-flexibility vector per element** "
             "(`reduced = ResidualFlexibility(modes=K).reduce(EulerBernoulliBeam(n, cracks=[(n // 4, 10)]))`, then "
             "`nnm(reduced.system, 1, a0=1, order=2)`)", "",
             "The issue's target is the NNM to order 2 of a cracked beam with 10⁴ dof in seconds, with memory "
             "O(N·elements); the full model's expansion needs all N modes to 30 digits"
             + "".join(f" (N = {entry['n_dof']}: {entry['cpu']:.3g} s)" for entry in part["full"][-1:] if "cpu" in entry)
             + ". Here the "
             "beam is first reduced to its K lowest modes and one static vector per element, computed in "
             "multiprecision with O(N·(K + m)) numbers kept, and the NNM of the K + m-dof model is expanded. "
             "Measured per (N, K) in a fresh interpreter: the CPU time of building the beam, of the reduction and of "
             "the expansion; memory as above (its peak is the reduction's); the relative differences of ω₀, ω₁, ω₂ "
             f"from the full model's expansion (N ≤ {part['full_max']}); the FE error of the 30-digit ω₀ against the "
             f"continuous cracked beam λ₁ = {part['cracked_exact'][:22]}… (8×8 determinant). A series stops at the first "
             f"N over {budget:.0f} s CPU. Load average (1, 5, 15 min) at start {part['load_average_at_start']}, at end "
             f"{part['load_average_at_end']}.", "",
             "| N | K | build (s) | reduce (s) | nnm (s) | memory (MB) | reduction | ω₀ | ω₀, ω₁, ω₂ vs full | full nnm (s) | ω₀ FE error |",
             "|---:|---:|---:|---:|---:|---:|---|---:|---|---:|---:|"]
    for series in part["series"]:
        for r in series["rows"]:
            reference = full.get(r["size"], {})
            errors = ", ".join(_e(x) for x in r["errors_vs_full"]) if "errors_vs_full" in r else (
                reference.get("status", "—") if reference else "—")
            if r["status"] != "ok":
                lines.append(f"| {r['n_dof']} | {r['modes']} | {r['build_cpu']:.3g} | {r['reduce_cpu']:.3g} | {_t(r.get('nnm_cpu'))} | "
                             f"{r['memory_mb']:.0f} | **{r['status']}**: {r.get('nnm_message', r.get('message', ''))[:200]} | | | | |")
                continue
            lines.append(f"| {r['n_dof']} | {r['modes']} | {r['build_cpu']:.3g} | {r['reduce_cpu']:.3g} | {r['nnm_cpu']:.3g} | "
                         f"{r['memory_mb']:.0f} | {'' if r['success'] else '**not converged**: '}{r['iterations']} iterations, "
                         f"{r['solves']} solves, b = {r['bandwidth']} | {r['omega'][0][:14]} | {errors} | {_t(reference.get('cpu'))} | "
                         f"{_e(r['omega0_fe_error'])} |")
        stopped = series["stopped"]
        if stopped and stopped["status"] not in ("reduce refused", "nnm refused"):
            lines.append(f"| {stopped['n_dof']} | {series['modes']} | — | **{stopped['status']}** ({stopped['detail'][:200]}) | | | | | | | |")
    lines.append("")
    references = [entry for entry in part["full"] if "omega" in entry]
    if len(references) >= 2:  # ω₂ of the full model against the reduced one's as the mesh is refined
        first, last = references[0], references[-1]
        full_change = _relative(last["omega"][2], first["omega"][2])
        moved = {series["modes"]: _relative(a["omega"][2], b["omega"][2]) for series in part["series"] for a in series["rows"]
                 for b in series["rows"] if a["size"] == last["size"] and b["size"] == first["size"] and "omega" in a and "omega" in b}
        settles = bool(moved) and max(moved.values()) < 1e-2 * full_change
        lines += [f"ω₂ of the full model changes by {_e(full_change)} (relative) from N = {first['n_dof']} to N = {last['n_dof']}, "
                  "that of the reduced model by " + ", ".join(f"{_e(value)} (K = {modes})" for modes, value in moved.items())
                  + (": the reduced ω₂ settles with the mesh; its difference from the full model is the dynamic share of the "
                     "modes above the cut (the residual vector is their static response), which keeps changing as the mesh "
                     "adds modes." if settles else "."), ""]
    for series in part["series"]:
        lines.append(f"- K = {series['modes']}: growth exponents (larger half) reduction time N^{_fmt_exp(series['reduce_time_exponent'])}, "
                     f"total time N^{_fmt_exp(series['time_exponent'])}, memory N^{_fmt_exp(series['memory_exponent'])}; "
                     f"FE error of ω₀ h^{_fmt_num(series['fe_slope'])} over every mesh that ran.")
    lines.append("")
    return lines


def _fmt_num(value: float | None) -> str:
    return "—" if value is None else f"{-value:.2f}"


def _targets(data: dict[str, Any]) -> list[str]:
    if "beam" not in data:
        return []
    beam = data["beam"]
    largest = max((r["n_dof"] for r in beam["rows"]), default=0)
    stopped = beam["stopped"]
    beam_text = (f"largest N within {data['budget_cpu_s']:.0f} s: {largest}"
                 + (f"; N = {stopped['n_dof']}: {stopped['status']}" if stopped else ""))
    forced = [f for f in data.get("forced", []) if f.get("n_dof") == 100]
    forced_text = "; ".join(f"{f['model']}: " + (f"{f['cpu'] + f.get('reduction_cpu', 0.0):.2g} s CPU, {f['status']}"
                                                  if f["status"] != "refused" else "refused before integrating")
                            for f in forced) or "not run"
    return ["**Issue targets, measured:**", "",
            f"- NNM order 2, cracked beam, N = 10⁴, in seconds with memory O(N·elements) — {beam_text} "
            f"(time N^{_fmt_exp(beam['time_exponent'])}, memory N^{_fmt_exp(beam['memory_exponent'])}): **not met**"
            if largest < 10000 else f"- NNM order 2, cracked beam, N = 10⁴ — {beam_text}",
            *_reduced_target(data.get("reduced")),
            f"- forced response of a 100-dof model with two contact elements through its folds in under a minute — {forced_text}",
            ""]


def _reduced_target(part: dict[str, Any] | None) -> list[str]:
    """The target line of the reduced model: its largest N, that row's times and memory, the memory exponent."""
    if not part:
        return []
    out = []
    for series in part["series"]:
        done = [r for r in series["rows"] if r["status"] == "ok"]
        if not done:
            continue
        r = max(done, key=lambda row: row["n_dof"])
        met = r["n_dof"] >= 10000 and r["cpu"] <= BUDGET and (series["memory_exponent"] or 9) < 1.3
        out.append(f"- the same through `ResidualFlexibility(modes={series['modes']})`: N = {r['n_dof']} in {r['cpu']:.0f} s CPU "
                   f"(reduction {r['reduce_cpu']:.0f} s, nnm {r['nnm_cpu']:.2g} s), {r['memory_mb']:.0f} MB, memory "
                   f"N^{_fmt_exp(series['memory_exponent'])}, ω₀ FE error {_e(r['omega0_fe_error'])}"
                   + (": **met** (ω₂ carries the truncation error of the reduced model)" if met else ": **not met**"))
    return out


def _update_readme(section: str) -> None:
    """Replace this file's section of benchmarks/README.md (run.py's output) with ``section``, or append it."""
    path = SELF.parent / "README.md"
    text = path.read_text()
    start = text.find(f"## {TITLE}")
    if start < 0:
        path.write_text(text.rstrip() + "\n\n" + section.rstrip() + "\n")
        return
    end = text.find("\n## ", start)
    rest = "" if end < 0 else "\n" + text[end + 1:]
    path.write_text(text[:start] + section.rstrip() + "\n" + rest)


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        _worker(sys.argv[2:])
        raise SystemExit(0)
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small sizes only (a smoke run)")
    parser.add_argument("--only", choices=PARTS, help="run this part alone, merged into the stored results (and, outside "
                        "--quick, into this section of benchmarks/README.md)")
    args = parser.parse_args()
    section = run(args.quick, args.only)
    if args.only and not args.quick:
        _update_readme(section)
    print(section)
