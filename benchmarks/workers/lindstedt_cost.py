"""Worker of bench_cost_model: one expansion request, measured against its estimate in a fresh process.

Argument: a JSON object ``{"f": ..., "order": N, "kw": {expand's keyword arguments}}``.  After the imports and a
warm-up expansion of another problem (sympy's and mpmath's first-call costs are not the request's), it prices the
request (``lindstedt.expansion_cost``), then derives every ω_k, α_k and v_k up to the order with no budget, and
emits the CPU seconds (``time.process_time``) and the growth of the resident set (peak minus before, MB).
"""

import json
import resource
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from _common import emit  # noqa: E402

import lindstedt  # noqa: E402
from lindstedt import limits  # noqa: E402


def _resident_mb() -> float:
    with open("/proc/self/statm", "rb") as statm:
        return int(statm.read().split()[1]) * 4096 / 2**20


def main() -> None:
    spec = json.loads(sys.argv[1])
    warm = lindstedt.expand("u**2 + Max(0, u - 1/2)", order=2, a0=1, omega0=1)
    _ = warm.omega, warm.waveforms
    estimate = lindstedt.expansion_cost(spec["f"], spec["order"], **spec.get("kw", {}))
    before = _resident_mb()
    start = time.process_time()
    with limits.budget(seconds=None, memory_mb=None):
        expansion = lindstedt.expand(spec["f"], spec["order"], **spec.get("kw", {}))
        _ = expansion.omega, expansion.alpha, expansion.waveforms
    seconds = time.process_time() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    emit({"seconds": seconds, "memory_mb": max(peak - before, 0.0), "estimate_seconds": estimate.seconds,
          "estimate_memory_mb": estimate.memory_mb, "drivers": [[k, v] for k, v in estimate.drivers]})


if __name__ == "__main__":
    main()
