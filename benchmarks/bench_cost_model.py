"""The cost model of ``lindstedt.expand`` against measurement (issue 23): estimate vs CPU time and memory.

Every request of :data:`CALIBRATION` (each kind of f, orders, breakpoints, symbolic parameters, digits) and a
seeded random sample of requests drawn from the same space runs in a fresh process
(``workers/lindstedt_cost.py``): the CPU seconds and memory growth of deriving every ω_k, α_k, v_k up to the
order, next to ``lindstedt.expansion_cost`` of the same request.  The section reports the ratio
measured / estimated per request and its range, which the docs state as the model's accuracy
(``lindstedt.limits.FACTOR``).

``python benchmarks/bench_cost_model.py --fit`` measures the calibration set and prints the constants of
``lindstedt/_cost.py`` (least squares of log T on the model's features, per kind; memory growth against T).
"""

from __future__ import annotations

import argparse
import json
import math
import random
import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import WORKERS_DIR, load_average, run_worker, write_json  # noqa: E402

ONE = {"a0": 1, "omega0": 1}
GAPS = ["1/3", "-1/2", "3/4", "-1/5", "1/7", "-2/3", "5/6", "-1/9"]


def _gaps(count: int) -> str:
    return " + ".join(f"Max(0, u - ({gap}))" for gap in GAPS[:count])


def _spec(f: str, order: int, **kw: Any) -> dict[str, Any]:
    return {"f": f, "order": order, "kw": {**ONE, **kw}}


#: The requests the constants are fitted on (each kind over its orders and modifiers).
CALIBRATION: list[dict[str, Any]] = [
    *[_spec("u**3", n) for n in (10, 20, 40, 70, 100)],
    *[_spec("u**3 + u**5 + u**7", n) for n in (5, 10, 20, 30)],
    *[_spec(f"u**{d}", n) for d in (5, 9) for n in (10, 20)],
    *[{"f": "u**3", "order": n, "kw": {}} for n in (10, 20, 40)],
    *[_spec("c1*u**3 + c2*u**5 + c3*u**2", n, params={"c1": None, "c2": None, "c3": None}) for n in (2, 4, 6)],
    *[{"f": "u**3", "order": n, "kw": {"u0": "3/5", "v0": "4/5", "omega0": 1}} for n in (8, 16, 30)],
    *[_spec("sin(u)", n) for n in (4, 8, 12, 16, 20)],
    *[_spec("sin(u)", n, precision=p) for p in (100, 300) for n in (2, 4, 8, 12)],
    *[_spec("sin(u)", n, precision=1000) for n in (1, 2, 4)],
    *[_spec("exp(u)", n) for n in (4, 8)],
    *[_spec(_gaps(1), n) for n in (2, 4, 6, 8, 10, 12, 14, 16)],
    *[_spec(_gaps(b), n) for b in (2, 3, 4, 6) for n in (2, 4)],
    _spec(_gaps(2), 6), _spec(_gaps(2), 8), _spec(_gaps(8), 2),
    *[_spec("Max(0, u - b)", n, params={"b": None}) for n in (2, 4, 6, 8)],
    *[{"f": "Max(0, u - 1/3)", "order": n, "kw": {}} for n in (2, 4)],
    *[_spec("Max(0, u)**2", n) for n in (4, 8, 12)],
    *[_spec("Max(0, u + 1)", n) for n in (2, 4)],
    *[{"f": "Max(0, u - 1/3)", "order": n, "kw": {"u0": "3/5", "v0": "4/5", "omega0": 1}} for n in (4, 8)],
    *[_spec(_gaps(1), n, numeric=True) for n in (4, 8, 16, 32)],
    *[_spec(_gaps(1), n, numeric=True, precision=p) for p in (100, 1000) for n in (4, 8)],
    *[_spec(_gaps(3), n, numeric=True) for n in (4, 8)],
    *[_spec("Max(0, u - 1/5)**(3/2)", n, precision=p) for p in (20, 50, 100) for n in (2, 4, 8)],
    *[_spec(f"Max(0, u - 1/5)**{d}", n) for d in (2, 4, 8, 16, 32) for n in (1, 2, 4, 8) if d * n < 256],
    _spec("Max(0, u - 1/5)**32", 6), _spec("Max(0, u - 1/5)**200", 1), _spec("Max(0, u - 1/5)**200", 2),
    *[_spec(law, n) for law in ("Max(0, u)**2 + u**3", "Max(0, u)**3 + u**5") for n in (2, 4, 8)],
    _spec(" + ".join(f"Max(0, u - {k}/17)" for k in range(1, 17)), 2),
    _spec(" + ".join(f"Max(0, u - {k}/35)" for k in range(1, 35)), 2),  # the audit's 34 springs
    {"f": "Max(0, u - 1/3)", "order": 6, "kw": {}}, {"f": "Max(0, u - 1/3)", "order": 8, "kw": {}},
    _spec("sin(u)", 8, precision=1000), _spec("sin(u)", 16, precision=300),
    _spec("Max(0, u - 1/5)**(3/2)", 10, precision=100),  # the audit's Hertz request
    _spec("a*u**3 + b*u**5 + c*u**7", 12, params={"a": None, "b": None, "c": None}),
    {"f": "Max(0, u - 1/3)", "order": 16, "kw": {"u0": "3/5", "v0": "4/5", "omega0": 1}},
    _spec("Max(0, u - b)", 10, params={"b": None}), _spec(_gaps(1), 20),
]


def _random_requests(count: int, seed: int = 23) -> list[dict[str, Any]]:
    """A seeded sample of the request space (law, order, parameters, digits), for validation only."""
    draw = random.Random(seed)
    laws = [
        lambda: ("u**3 + u**5", {}, draw.randint(2, 40)),
        lambda: (f"u**{draw.choice([3, 5, 7])}", {}, draw.randint(2, 30)),
        lambda: ("sin(u)", {"precision": draw.choice([30, 60, 150])}, draw.randint(2, 12)),
        lambda: (_gaps(draw.randint(1, 3)), {}, draw.randint(1, 8)),
        lambda: (_gaps(draw.randint(1, 4)), {"numeric": True, "precision": draw.choice([30, 100])}, draw.randint(2, 16)),
        lambda: ("Max(0, u - 1/5)**(3/2)", {"precision": draw.choice([20, 40])}, draw.randint(2, 6)),
        lambda: ("Max(0, u - b)", {"params": {"b": None}}, draw.randint(2, 6)),
        lambda: ("Max(0, u)**2 + u**3", {}, draw.randint(2, 8)),
    ]
    requests = []
    for _ in range(count):
        f, kw, order = draw.choice(laws)()
        requests.append(_spec(f, order, **kw))
    return requests


def measure(specs: list[dict[str, Any]], timeout: float = 400.0) -> list[dict[str, Any]]:
    rows = []
    for spec in specs:
        outcome = run_worker(sys.executable, WORKERS_DIR / "lindstedt_cost.py", [json.dumps(spec)], timeout)
        row = {"spec": spec, "status": outcome.status, **(outcome.result or {}), "note": outcome.detail}
        rows.append(row)
        if row.get("seconds") is not None:
            print(f"{spec['f'][:40]:40} N={spec['order']:3} {row['seconds']:9.3f} s (est {row['estimate_seconds']:9.3g}) "
                  f"{row['memory_mb']:7.1f} MB (est {row['estimate_memory_mb']:7.3g})", file=sys.stderr, flush=True)
        else:
            print(f"{spec['f'][:40]:40} N={spec['order']:3} {outcome.status} {outcome.detail}", file=sys.stderr, flush=True)
    return rows


def fit(rows: list[dict[str, Any]]) -> tuple[dict[str, dict[str, float]], tuple[float, float]]:
    """θ per kind (least squares of log T on the features the kind uses) and the memory law (c, γ, δ, η) of
    ``growth = c · T^γ · B^δ · (P/30)^η`` MB (B ≥ 1 the breakpoints, P the digits)."""
    import numpy as np

    import lindstedt

    by_kind: dict[str, list[tuple[dict[str, float], float]]] = {}
    memory = []
    for row in rows:
        if row.get("seconds") is None:
            continue
        estimate = lindstedt.expansion_cost(row["spec"]["f"], row["spec"]["order"], **row["spec"]["kw"])
        kind, vector = dict(estimate.drivers)["kind"], dict(estimate.features)
        breakpoints = dict(estimate.drivers).get("breakpoints", 1)
        seconds = max(row["seconds"], 1e-3)
        by_kind.setdefault(kind, []).append((vector, seconds))
        if (row.get("memory_mb") or 0.0) > 2.0 and seconds > 0.2:
            digits = dict(estimate.drivers).get("digits", 30)
            memory.append((math.log(seconds), math.log(breakpoints), math.log(digits / 30), math.log(row["memory_mb"])))
    theta = {}
    for kind, samples in by_kind.items():
        names = list(samples[0][0])
        a = np.array([[vector[name] for name in names] for vector, _ in samples])
        b = np.array([math.log(seconds) for _, seconds in samples])
        solution, *_ = np.linalg.lstsq(a, b, rcond=None)
        theta[kind] = {name: round(float(value), 4) for name, value in zip(names, solution)}
    a = np.array([[1.0, m[0], m[1], m[2]] for m in memory])
    intercept, power, breakpoints, digits = np.linalg.lstsq(a, np.array([m[3] for m in memory]), rcond=None)[0]
    return theta, tuple(round(float(value), 3) for value in (math.exp(intercept), power, breakpoints, digits))


def _options(kw: dict[str, Any]) -> str:
    text = [f"{k}={v}" for k, v in kw.items() if k not in ("a0", "omega0") or v != 1]
    if "a0" not in kw and "u0" not in kw:
        text.insert(0, "symbolic a0, omega0")
    return ", ".join(text)


def _ratio_table(rows: list[dict[str, Any]]) -> tuple[str, tuple[float, float], tuple[float, float]]:
    """The markdown table and the ranges of measured/estimated time and memory (above the noise: 0.05 s, 5 MB)."""
    lines = ["| f | order | options | measured s | estimated s | ratio | memory MB | estimated MB |", "|---|---|---|---|---|---|---|---|"]
    ratios, memory = [], []
    for row in rows:
        spec = row["spec"]
        options = _options(spec["kw"])
        if row.get("seconds") is None:
            lines.append(f"| `{spec['f']}` | {spec['order']} | {options} | {row['status']} | | | | |")
            continue
        ratio = row["seconds"] / row["estimate_seconds"]
        if row["seconds"] > 0.05 or row["estimate_seconds"] > 0.05:  # below that, process noise
            ratios.append(ratio)
        if row["memory_mb"] > 5:
            memory.append(row["memory_mb"] / row["estimate_memory_mb"])
        lines.append(f"| `{spec['f']}` | {spec['order']} | {options} | {row['seconds']:.3g} | {row['estimate_seconds']:.3g} | "
                     f"{ratio:.2f} | {row['memory_mb']:.0f} | {row['estimate_memory_mb']:.0f} |")
    return "\n".join(lines), (min(ratios), max(ratios)), (min(memory), max(memory))


def run(quick: bool = False) -> str:
    load = load_average()
    calibration = measure(CALIBRATION[::3] if quick else CALIBRATION)
    sample = measure(_random_requests(8 if quick else 30))
    data = {"calibration": calibration, "random": sample, "load": load}
    write_json("cost_model.json", data)
    return section(data)


def section(data: dict[str, Any]) -> str:
    """The README section of a run's data (``results/cost_model.json``)."""
    table, (low, high), (memory_low, memory_high) = _ratio_table(data["calibration"])
    random_table, (random_low, random_high), (random_memory_low, random_memory_high) = _ratio_table(data["random"])
    return "\n".join([
        "## Cost model of `expand`: estimate vs measurement",
        "",
        "Each request runs in a fresh process after a warm-up expansion of another problem; measured is the CPU time",
        "(`time.process_time`) and the growth of the resident set of deriving every ω_k, α_k and v_k up to the order,",
        "next to `lindstedt.expansion_cost` of the same request (the estimate `expand` checks against the budget).",
        f"Load average at start: {data['load']}.",
        "",
        f"Calibration set (the constants of `lindstedt/_cost.py` are fitted on it): measured / estimated time in "
        f"[{low:.2f}, {high:.2f}] over the requests above 0.05 s, memory in [{memory_low:.2f}, {memory_high:.2f}] "
        "over those above 5 MB.",
        "",
        table,
        "",
        f"Seeded random requests (not fitted on): measured / estimated time in [{random_low:.2f}, {random_high:.2f}], "
        f"memory in [{random_memory_low:.2f}, {random_memory_high:.2f}].",
        "",
        random_table,
        "",
    ])


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fit", action="store_true", help="measure the calibration set and print the model's constants")
    parser.add_argument("--from-json", help="fit on the calibration rows of a previous run (results/cost_model.json)")
    arguments = parser.parse_args()
    if arguments.fit:
        rows = json.loads(Path(arguments.from_json).read_text())["calibration"] if arguments.from_json else measure(CALIBRATION)
        if not arguments.from_json:
            write_json("cost_model_calibration.json", {"calibration": rows, "load": load_average()})
        theta, memory = fit(rows)
        print("_THETA =", json.dumps(theta, indent=4))
        print("_MEMORY =", memory)
    else:
        print(run())
