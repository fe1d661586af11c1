"""Worker: one cold lindstedt expansion of the Duffing oscillator u'' + ω0² u + ε u³ = 0, u(0) = a0, u'(0) = 0.

Run in a fresh interpreter (by benchmarks/bench_duffing_orders.py) so no cache of a previous order helps.
Usage: python -I lindstedt_duffing.py ORDER numeric|symbolic

Timed region (time.perf_counter, after all imports and one gc.collect()): ``lindstedt.expand`` plus forcing the lazy results
``.omega`` (ω_0..ω_N) and ``.waveforms`` (v_0..v_N) — the same set of quantities the peer computes eagerly.
A second identical call in the same process is reported as the warm time (lindstedt's caches hot).
Prints one line ``@@BENCH-RESULT {json}``.
"""

import gc
import json
import sys
import time

MARKER = "@@BENCH-RESULT "


def main() -> None:
    order = int(sys.argv[1])
    mode = sys.argv[2]
    if mode not in ("numeric", "symbolic"):
        raise SystemExit("mode must be numeric or symbolic")
    kwargs = {"a0": 1, "omega0": 1} if mode == "numeric" else {}

    start = time.perf_counter()
    import sympy

    import lindstedt
    from lindstedt import __version__ as lindstedt_version

    import_seconds = time.perf_counter() - start
    # Start the timed region from a collected heap: otherwise the first full (generation-2) collection of the
    # ~10^5 objects sympy's import leaves behind (~40 ms) lands in it or not depending on hash randomisation.
    gc.collect()

    start = time.perf_counter()
    expansion = lindstedt.expand("u**3", order=order, normalization="initial", **kwargs)
    omega = expansion.omega
    waveforms = expansion.waveforms
    cold_seconds = time.perf_counter() - start

    start = time.perf_counter()
    again = lindstedt.expand("u**3", order=order, normalization="initial", **kwargs)
    again.omega
    again.waveforms
    warm_seconds = time.perf_counter() - start

    result = {
        "tool": "lindstedt",
        "version": lindstedt_version,
        "sympy": sympy.__version__,
        "order": order,
        "mode": mode,
        "import_seconds": import_seconds,
        "seconds": cold_seconds,
        "warm_seconds": warm_seconds,
        "omega": [sympy.sstr(value) for value in omega],
        "waveforms": [[[h, sympy.sstr(c)] for h, c in w.coefficients] for w in waveforms],
    }
    print(MARKER + json.dumps(result), flush=True)


if __name__ == "__main__":
    main()
