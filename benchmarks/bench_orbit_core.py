"""Benchmark (issue 24): the periodic-orbit core against a baseline commit, both trees in one run.

The issue asks that the continuation of a free NNM and the forced frequency response run "at the same or
better speed, re-run in one run with the previous commit as the baseline".  Two workloads, each exactly the
call of the benchmark where it was first measured:

* ``continuation`` — ``continue_nnm(chain(20), 1, start=0, stop=0.3, modal_amplitude=1, max_points=200)`` on
  the 20-dof chain with the three unilateral springs ``[(0, 0.1), (N // 2, -0.05), (N - 1, 0.0)]``
  (``bench_performance.py``, ``_worker_continuation``: "continuation, 20-dof chain, 3 springs, mode 1").
* ``forced`` — ``frequency_response(ForcedFlow(problem, 0.5), 0.8, 1.3, tol=1e-10)`` on the forced gap
  oscillator ``u'' + 2ζu' + u + ε(u − b)₊ = εF cos Ωt`` (ζ = 1/100, b = 1/10, F = 1/25, ε = 0.5): the FRC
  with its two folds (``bench_forced.py``, part 1).

Both trees are timed in fresh interpreters (this file is its own worker: ``python -I bench_orbit_core.py
--worker TASK TREE`` puts ``TREE`` first on ``sys.path``, checks that ``lindstedt`` is imported from it and
prints one ``@@BENCH-RESULT {json}`` line).  The baseline tree is ``git archive <rev>`` unpacked into a
temporary directory (removed afterwards, also on failure); the candidate is this working tree (or
``--candidate REV``, archived the same way).  Runs are interleaved (baseline, candidate, baseline, …) so
that a change of the machine's load hits both alike.  Only the call is timed (``time.perf_counter`` and
``time.process_time`` around it, after the imports and the problem's construction).  Both trees must return
the same numbers: the same ``success``, fold frequencies within 1e-8, the end frequency of the NNM branch
within 1e-10.

Standalone: ``python benchmarks/bench_orbit_core.py [--repeats 5] [--baseline 3b0dadc] [--candidate REV]``
prints the markdown section and writes ``benchmarks/results/orbit_core.json``.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import REPO_DIR, emit as _emit, format_error as _e, format_seconds as _t, load_average, run_worker, write_json  # noqa: E402

TITLE = "Periodic-orbit core (issue 24): continuation and forced response against the baseline commit"
SELF = Path(__file__).resolve()
RAW_NAME = "orbit_core.json"
DEFAULT_BASELINE = "3b0dadc"  # main before issue 24's work
TIMEOUT = 900.0  # seconds per worker process
FOLD_TOL = 1e-8  # fold frequencies of the two trees must agree to this
END_FREQUENCY_TOL = 1e-10  # end frequency of the NNM branch

CHAIN = {"size": 20, "mode": 1, "start": 0.0, "stop": 0.3, "modal_amplitude": 1.0, "max_points": 200}
GAP = {"f": "Max(0, u - b)", "b": "1/10", "zeta": "1/100", "forcing": "1/25", "epsilon": 0.5,
       "start": 0.8, "stop": 1.3, "tol": 1e-10}
WORKLOADS = {
    "continuation": "`continue_nnm(chain(20, springs [(0, 0.1), (10, -0.05), (19, 0.0)]), 1, start=0, stop=0.3, "
                    "modal_amplitude=1, max_points=200)` (from `bench_performance.py`)",
    "forced": "`frequency_response(ForcedFlow(ForcedOscillator(\"Max(0, u - b)\", omega0=1, zeta=\"1/100\", "
              "forcing=\"1/25\", params={\"b\": \"1/10\"}), 0.5), 0.8, 1.3, tol=1e-10)` (from `bench_forced.py`, part 1)",
}


def _log(message: str) -> None:
    print(f"[orbit-core] {message}", file=sys.stderr, flush=True)


# =================================================================================================================
# workers (fresh interpreters, one tree each)
# =================================================================================================================
def _import(tree: str) -> Any:
    for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # one BLAS thread, both trees
        os.environ.setdefault(name, "1")
    sys.path.insert(0, tree)
    import lindstedt

    where = Path(lindstedt.__file__).resolve()
    if Path(tree).resolve() not in where.parents:
        raise RuntimeError(f"lindstedt imported from {where}, not from the tree {tree}")
    return lindstedt


def _timed(call: Any) -> tuple[Any, float, float]:
    wall, cpu = time.perf_counter(), time.process_time()
    result = call()
    return result, time.perf_counter() - wall, time.process_time() - cpu


def _counters(result: Any) -> dict[str, Any]:
    names = ("flow_evaluations", "newton_iterations", "rejected_steps", "steps", "evaluations")
    return {name: int(getattr(result, name)) for name in names if getattr(result, name, None) is not None}


def _bifurcations(result: Any) -> list[list[Any]]:
    return [[str(b.kind), float(b.frequency)] for b in getattr(result, "bifurcations", ()) or ()]


def _worker_continuation(tree: str) -> None:
    lindstedt = _import(tree)
    from lindstedt.numerics import continue_nnm

    size = CHAIN["size"]
    system = lindstedt.UnilateralSystem.chain(size, unilateral=[(0, 0.1), (size // 2, -0.05), (size - 1, 0.0)])
    branch, wall, cpu = _timed(lambda: continue_nnm(system, CHAIN["mode"], start=CHAIN["start"], stop=CHAIN["stop"],
                                                    modal_amplitude=CHAIN["modal_amplitude"],
                                                    max_points=CHAIN["max_points"]))
    points = branch.points
    _emit({"wall": wall, "cpu": cpu, "success": bool(branch.success), "message": str(branch.stop_reason),
           "points": len(points), **_counters(branch),
           "reached": float(branch.parameter_values[-1]) if len(points) else None,
           "end_frequency": float(points[-1].frequency) if len(points) else None,
           "jumps": len(getattr(branch, "jumps", ()) or ()), "folds": [int(i) for i in getattr(branch, "folds", ())],
           "bifurcations": _bifurcations(branch), "lindstedt": str(Path(lindstedt.__file__).parent)})


def _worker_forced(tree: str) -> None:
    import numpy as np

    lindstedt = _import(tree)
    from lindstedt.numerics import ForcedFlow, frequency_response

    problem = lindstedt.ForcedOscillator(GAP["f"], omega0=1, zeta=GAP["zeta"], forcing=GAP["forcing"],
                                         params={"b": GAP["b"]})
    flow = ForcedFlow(problem, GAP["epsilon"])
    response, wall, cpu = _timed(lambda: frequency_response(flow, GAP["start"], GAP["stop"], tol=GAP["tol"]))
    bifurcations = _bifurcations(response)
    points = response.points
    _emit({"wall": wall, "cpu": cpu, "success": bool(response.success), "message": str(response.message),
           "points": len(points), **_counters(response), "bifurcations": bifurcations,
           "folds": [frequency for kind, frequency in bifurcations if kind == "fold"],
           "end_frequency": float(points[-1].frequency) if len(points) else None,
           "peak": float(np.max(response.amplitudes)) if len(points) else None,
           "lindstedt": str(Path(lindstedt.__file__).parent)})


WORKERS = {"continuation": _worker_continuation, "forced": _worker_forced}


# =================================================================================================================
# orchestration (no lindstedt import here)
# =================================================================================================================
def _git(*args: str) -> str:
    return subprocess.run(["git", "-C", str(REPO_DIR), *args], check=True, capture_output=True, text=True).stdout.strip()


def _unpack(revision: str, into: Path) -> None:
    """``git archive revision | tar -x`` into ``into`` (no worktree metadata left in the repository)."""
    archive = subprocess.run(["git", "-C", str(REPO_DIR), "archive", "--format=tar", revision],
                             check=True, capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)


def _dirty_files() -> int:
    """Modified or new files under ``lindstedt/`` of the working tree (what the candidate adds to HEAD)."""
    return len([line for line in _git("status", "--porcelain", "--", "lindstedt").splitlines() if line])


def _stats(runs: list[dict[str, Any]], key: str) -> dict[str, float] | None:
    values = [r[key] for r in runs if r.get("status") == "ok" and r.get(key) is not None]
    return {"min": min(values), "median": statistics.median(values), "runs": values} if values else None


def _same_numbers(rows: list[dict[str, Any]]) -> bool:
    """Every ok run of one tree returned the same success, point count and numbers (the runs are deterministic)."""
    keys = ("success", "points", "folds", "end_frequency", "flow_evaluations")
    return len({tuple(repr(r.get(k)) for k in keys) for r in rows}) <= 1


def _agreement(task: str, base: dict[str, Any], cand: dict[str, Any]) -> dict[str, Any]:
    """Compare the first ok run of each tree: success, fold frequencies, the NNM branch's end frequency."""
    checks: dict[str, Any] = {"success": base.get("success") == cand.get("success")}
    folds_b, folds_c = base.get("folds") or [], cand.get("folds") or []
    if task == "forced":
        same_count = len(folds_b) == len(folds_c)
        difference = max((abs(b - c) for b, c in zip(folds_b, folds_c)), default=0.0) if same_count else None
        checks.update(folds_count=same_count, fold_difference=difference,
                      folds=difference is not None and difference <= FOLD_TOL)
    else:
        e_b, e_c = base.get("end_frequency"), cand.get("end_frequency")
        difference = abs(e_b - e_c) if e_b is not None and e_c is not None else None
        checks.update(end_frequency_difference=difference,
                      end_frequency=difference is not None and difference <= END_FREQUENCY_TOL,
                      reached=base.get("reached") == cand.get("reached"))
    checks["agree"] = all(v for k, v in checks.items() if isinstance(v, bool))
    return checks


def measure(repeats: int, baseline: str, candidate: str | None) -> dict[str, Any]:
    """Run both workloads ``repeats`` times per tree, interleaved; return the raw data."""
    started = time.perf_counter()
    temporary = Path(tempfile.mkdtemp(prefix="orbit-core-"))
    try:
        trees: dict[str, dict[str, Any]] = {}
        base_dir = temporary / "baseline"
        base_dir.mkdir()
        _unpack(baseline, base_dir)
        trees["baseline"] = {"path": str(base_dir), "revision": _git("rev-parse", baseline), "spec": baseline}
        if candidate is None:
            trees["candidate"] = {"path": str(REPO_DIR), "revision": _git("rev-parse", "HEAD"), "spec": "working tree",
                                  "dirty_files_in_lindstedt": _dirty_files()}
        else:
            cand_dir = temporary / "candidate"
            cand_dir.mkdir()
            _unpack(candidate, cand_dir)
            trees["candidate"] = {"path": str(cand_dir), "revision": _git("rev-parse", candidate), "spec": candidate}
        load_start = load_average()
        runs: dict[str, dict[str, list[dict[str, Any]]]] = {task: {"baseline": [], "candidate": []} for task in WORKERS}
        for repeat in range(repeats):
            for task in WORKERS:
                for label in ("baseline", "candidate"):
                    outcome = run_worker(sys.executable, SELF, ["--worker", task, trees[label]["path"]], timeout=TIMEOUT)
                    row = dict(outcome.result or {})
                    row.update(status=outcome.status, detail=outcome.detail, process_wall=outcome.wall, load=load_average())
                    runs[task][label].append(row)
                    _log(f"{task} {label} run {repeat + 1}/{repeats}: {outcome.status} "
                         f"{_t(row.get('wall'))} wall, {_t(row.get('cpu'))} CPU, {row.get('points')} points {outcome.detail}")
    finally:
        shutil.rmtree(temporary, ignore_errors=True)
    workloads: dict[str, Any] = {}
    for task, by_tree in runs.items():
        entry: dict[str, Any] = {"call": WORKLOADS[task], "runs": by_tree}
        for label, rows in by_tree.items():
            ok = [r for r in rows if r["status"] == "ok"]
            entry[label] = {"ok": len(ok), "wall": _stats(rows, "wall"), "cpu": _stats(rows, "cpu"),
                            "deterministic": _same_numbers(ok), "first": ok[0] if ok else None}
        base, cand = entry["baseline"], entry["candidate"]
        if base["first"] and cand["first"]:
            entry["agreement"] = _agreement(task, base["first"], cand["first"])
            entry["ratio"] = {key: cand[key]["median"] / base[key]["median"] for key in ("cpu", "wall")}
        workloads[task] = entry
    return {"repeats": repeats, "trees": trees, "load_start": load_start, "load_end": load_average(),
            "seconds": time.perf_counter() - started, "workloads": workloads,
            "tolerances": {"folds": FOLD_TOL, "end_frequency": END_FREQUENCY_TOL}}


# =================================================================================================================
# formatting
# =================================================================================================================
def _cell(stats: dict[str, float] | None, key: str) -> str:
    return _t(stats[key]) if stats else "—"


def _result_cell(task: str, first: dict[str, Any] | None) -> str:
    if not first:
        return "—"
    counts = f"{first['points']} points, {first.get('flow_evaluations')} flows"
    if task == "forced":
        folds = ", ".join(f"{f:.10f}" for f in first["folds"]) or "none"
        return f"{counts}; folds at Ω = {folds}"
    found = "; ".join(f"{kind} at ω = {frequency:.10f}" for kind, frequency in first.get("bifurcations") or [])
    return (f"{counts}, {first.get('jumps')} jumps; ε reached {first.get('reached')}, "
            f"end ω = {first['end_frequency']:.13f}" + (f"; {found}" if found else ""))


def _section(data: dict[str, Any], command: str) -> str:
    trees = data["trees"]
    cand = trees["candidate"]
    cand_label = (f"working tree at `{cand['revision'][:10]}`"
                  + (f" ({cand['dirty_files_in_lindstedt']} modified file(s) in `lindstedt/`)" if cand.get("dirty_files_in_lindstedt") else "")
                  if cand["spec"] == "working tree" else f"`{cand['revision'][:10]}` ({cand['spec']})")
    out = [f"## {TITLE}", "",
           f"Command: `{command}`; {data['repeats']} run(s) per tree and workload, interleaved (baseline, candidate, …), "
           f"each a fresh interpreter with its tree first on `sys.path`; timed: the call only (`perf_counter`, "
           f"`process_time`), after imports and problem construction. Whole benchmark {data['seconds']:.0f} s; "
           f"load average (1, 5, 15 min) {data['load_start']} at start, {data['load_end']} at end.", "",
           f"* baseline: `{trees['baseline']['revision']}` (`{trees['baseline']['spec']}`, `git archive` into a temporary directory)",
           f"* candidate: {cand_label}" + (f", `{cand['revision']}`" if cand["spec"] == "working tree" else ""), ""]
    for task, entry in data["workloads"].items():
        out += [f"### {task}", "", entry["call"], "",
                "| tree | ok runs | CPU min | CPU median | wall min | wall median | result (first run) |",
                "| --- | --- | --- | --- | --- | --- | --- |"]
        for label in ("baseline", "candidate"):
            tree = entry[label]
            out.append(f"| {label} | {tree['ok']}/{data['repeats']} | {_cell(tree['cpu'], 'min')} | {_cell(tree['cpu'], 'median')} | "
                       f"{_cell(tree['wall'], 'min')} | {_cell(tree['wall'], 'median')} | {_result_cell(task, tree['first'])} |")
        out.append("")
        ratio, agreement = entry.get("ratio"), entry.get("agreement")
        if ratio is None:
            failures = [r["detail"] for rows in entry["runs"].values() for r in rows if r["status"] != "ok"]
            out += [f"**No comparison**: a tree has no successful run ({'; '.join(failures[:2])}).", ""]
            continue
        if task == "forced":
            detail = (f"fold frequencies differ by at most {_e(agreement['fold_difference'])} (tolerance {FOLD_TOL:g}; "
                      f"same number of folds: {agreement['folds_count']})")
        else:
            detail = (f"end frequency differs by {_e(agreement['end_frequency_difference'])} (tolerance "
                      f"{END_FREQUENCY_TOL:g}); same ε reached: {agreement['reached']}")
        same = all(entry[label]["deterministic"] for label in ("baseline", "candidate"))
        out += [f"Ratio candidate / baseline (medians): CPU **{ratio['cpu']:.3f}**, wall **{ratio['wall']:.3f}**. "
                f"Agreement: **{'yes' if agreement['agree'] else 'NO'}** — same success: {agreement['success']}; {detail}. "
                f"Every run of a tree returned the same numbers: {same}.", ""]
    return "\n".join(out).rstrip() + "\n"


def _measure_and_write(repeats: int, baseline: str, candidate: str | None, command: str) -> tuple[str, dict[str, Any]]:
    data = measure(repeats, baseline, candidate)
    data["command"] = command
    write_json(RAW_NAME, data)
    return _section(data, command), data


def run(quick: bool = False) -> str:
    """The markdown section (``quick``: one run per tree, else 5); writes ``benchmarks/results/orbit_core.json``."""
    command = "python benchmarks/run.py --only orbit-core" + (" --quick" if quick else "")
    return _measure_and_write(1 if quick else 5, DEFAULT_BASELINE, None, command)[0]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="runs per tree and workload (default 5)")
    parser.add_argument("--baseline", default=DEFAULT_BASELINE, help=f"baseline revision (default {DEFAULT_BASELINE})")
    parser.add_argument("--candidate", default=None, help="candidate revision (default: this working tree)")
    parser.add_argument("--worker", nargs=2, metavar=("TASK", "TREE"), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        task, tree = args.worker
        WORKERS[task](tree)
        return 0
    command = " ".join(["python benchmarks/bench_orbit_core.py", *(argv if argv is not None else sys.argv[1:])])
    section, data = _measure_and_write(args.repeats, args.baseline, args.candidate, command)
    print(section)
    agree = all(entry.get("agreement", {}).get("agree") for entry in data["workloads"].values())
    return 0 if agree else 1


if __name__ == "__main__":
    raise SystemExit(main())
