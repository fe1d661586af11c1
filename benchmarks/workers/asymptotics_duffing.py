"""Worker: one cold Lindstedt expansion by the peer package ``asymptotics`` (run with .peer-venv's python).

Problem: u'' + u + eps*u**3 = 0, u(0) = AMP, u'(0) = 0 (AMP is "1" or a symbol such as "a"). The peer
cannot take a symbolic linear frequency (see the benchmark's README section), so ω0 = 1 always.
Usage: python -I asymptotics_duffing.py ORDER AMP

Timed region (time.perf_counter, after imports and after parsing the ODE): ``eq.expand_lindstedt(order)``
only. The peer's order count: ``order=N`` returns entries 0..N, entry k holding ω_k (``omega_k_val``;
ω_0 is ``sol.omega_0``) and u_k(τ) (``particular_solution``).
Prints one line ``@@BENCH-RESULT {json}`` (the peer's own notices go to a captured buffer).
"""

import contextlib
import io
import gc
import json
import sys
import time

MARKER = "@@BENCH-RESULT "


def main() -> None:
    order = int(sys.argv[1])
    amplitude = sys.argv[2]

    start = time.perf_counter()
    import sympy
    from importlib import metadata

    from asymptotics import ODE

    import_seconds = time.perf_counter() - start

    chatter = io.StringIO()
    with contextlib.redirect_stdout(chatter):
        start = time.perf_counter()
        equation = ODE(
            "u'' + u + eps*u**3",
            small_param="eps",
            conditions=[f"u(0) = {amplitude}", "u'(0) = 0"],
        )
        parse_seconds = time.perf_counter() - start

        gc.collect()  # a collected heap, as for lindstedt: no import-time garbage collected inside the timing
        start = time.perf_counter()
        solution = equation.expand_lindstedt(order=order)
        expand_seconds = time.perf_counter() - start

    omega = [solution.omega_0] + [solution[k].omega_k_val for k in range(1, len(solution))]
    result = {
        "tool": "asymptotics",
        "version": metadata.version("asymptotics"),
        "sympy": sympy.__version__,
        "order": order,
        "amplitude": amplitude,
        "import_seconds": import_seconds,
        "parse_seconds": parse_seconds,
        "seconds": expand_seconds,
        "entries": len(solution),
        "omega": [sympy.sstr(value) for value in omega],
        "omega_expansion": sympy.sstr(solution.omega_expansion),
        "waveforms": [sympy.sstr(solution[k].particular_solution) for k in range(len(solution))],
        "stdout_notices": chatter.getvalue().strip().splitlines(),
    }
    print(MARKER + json.dumps(result), flush=True)


if __name__ == "__main__":
    main()
