"""Shared helpers of the benchmark suite (no lindstedt import here: the parent process only orchestrates).

* :func:`machine_facts` — CPU, cores, load, Python and library versions, date.
* :func:`ensure_peer_venv` — the cached virtual environment ``benchmarks/.peer-venv`` holding a peer
  package for benchmarking only (never a project dependency).
* :func:`run_worker` — run a worker script in a fresh interpreter, with a timeout, and read the one JSON
  result line it prints; :func:`emit` is the worker's side of it.
* :func:`per_call` — the per-call time of a fast function (a timed loop, minimum over repeats).
* :func:`format_seconds`, :func:`format_error` — the tables' cells.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import platform
import subprocess
import sys
import time
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path
from typing import Any, Callable, Sequence

BENCH_DIR = Path(__file__).resolve().parent
REPO_DIR = BENCH_DIR.parent
WORKERS_DIR = BENCH_DIR / "workers"
RESULTS_DIR = BENCH_DIR / "results"
PEER_VENV = BENCH_DIR / ".peer-venv"
RESULT_MARKER = "@@BENCH-RESULT "


# ---------------------------------------------------------------------------------------------------------------
# machine facts
# ---------------------------------------------------------------------------------------------------------------
def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def _version(package: str) -> str:
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return "not installed"


def load_average() -> str:
    try:
        return ", ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "n/a"


def machine_facts() -> dict[str, str]:
    try:
        affinity = len(os.sched_getaffinity(0))
    except AttributeError:
        affinity = os.cpu_count() or 0
    return {
        "CPU": _cpu_model(),
        "cores (logical, usable by this process)": f"{os.cpu_count()} ({affinity})",
        "OS": f"{platform.system()} {platform.release()} ({platform.machine()})",
        "Python": f"{platform.python_implementation()} {platform.python_version()} ({sys.executable})",
        "lindstedt": _version("lindstedt"),
        "sympy": _version("sympy"),
        "mpmath": _version("mpmath"),
        "numpy": _version("numpy"),
        "scipy": _version("scipy"),
        "gmpy2 (sympy's fast ground types, if present)": _version("gmpy2"),
        "date (UTC)": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S"),
        "load average at start (1, 5, 15 min)": load_average(),
    }


# ---------------------------------------------------------------------------------------------------------------
# peer virtual environment
# ---------------------------------------------------------------------------------------------------------------
def peer_python() -> Path:
    return PEER_VENV / "bin" / "python"


def _venv_versions(python: Path, packages: Sequence[str]) -> dict[str, str] | None:
    code = (
        "import json, sys\nfrom importlib import metadata\nout = {}\n"
        f"for p in {list(packages)!r}:\n"
        "    try:\n        out[p] = metadata.version(p)\n"
        "    except metadata.PackageNotFoundError:\n        out[p] = None\n"
        "print(json.dumps(out))\n"
    )
    try:
        done = subprocess.run([str(python), "-I", "-c", code], capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired):
        return None
    if done.returncode != 0:
        return None
    return json.loads(done.stdout.strip().splitlines()[-1])


def ensure_peer_venv(requirements: dict[str, str], log=print) -> dict[str, str]:
    """Create (once) ``benchmarks/.peer-venv`` with exactly ``requirements`` ({name: version}); return versions.

    The venv is reused when it already holds those versions. It is a benchmark-only environment:
    nothing of the project depends on it, and it is gitignored.
    """
    python = peer_python()
    if python.exists():
        found = _venv_versions(python, list(requirements))
        if found is not None and all(found.get(name) == version for name, version in requirements.items()):
            return _venv_versions(python, ["asymptotics", "sympy", "mpmath", "numpy", "scipy", "matplotlib"]) or {}
        log(f"[peer-venv] {PEER_VENV} is stale ({found}); recreating")
    log(f"[peer-venv] creating {PEER_VENV} with {requirements} (one-off)")
    subprocess.run([sys.executable, "-m", "venv", "--clear", str(PEER_VENV)], check=True)
    pins = [f"{name}=={version}" for name, version in requirements.items()]
    subprocess.run(
        [str(python), "-m", "pip", "install", "--quiet", "--disable-pip-version-check", *pins],
        check=True,
    )
    found = _venv_versions(python, list(requirements))
    if found is None or any(found.get(name) != version for name, version in requirements.items()):
        raise RuntimeError(f"peer venv does not hold {requirements}: {found}")
    return _venv_versions(python, ["asymptotics", "sympy", "mpmath", "numpy", "scipy", "matplotlib"]) or {}


# ---------------------------------------------------------------------------------------------------------------
# workers
# ---------------------------------------------------------------------------------------------------------------
@dataclass
class WorkerOutcome:
    status: str  # "ok" | "timeout" | "error" | "skipped"
    result: dict[str, Any] | None
    wall: float  # wall-clock seconds of the whole subprocess (interpreter start, imports, work, exit)
    detail: str = ""


def run_worker(python: Path | str, script: Path, args: Sequence[Any], timeout: float) -> WorkerOutcome:
    """Run ``python -I script *args`` in a fresh process; parse its ``RESULT_MARKER`` JSON line.

    ``-I`` (isolated mode) keeps PYTHONPATH / user site-packages out, so each tool sees only its own
    environment. On timeout the child (started here) is killed.
    """
    env = dict(os.environ)
    env.setdefault("MPLBACKEND", "Agg")
    env.pop("PYTHONPATH", None)
    command = [str(python), "-I", str(script), *map(str, args)]
    start = time.perf_counter()
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=env, cwd=str(BENCH_DIR))
    except subprocess.TimeoutExpired:
        return WorkerOutcome("timeout", None, time.perf_counter() - start, f"killed after {timeout:.0f} s")
    wall = time.perf_counter() - start
    for line in reversed(done.stdout.splitlines()):
        if line.startswith(RESULT_MARKER):
            return WorkerOutcome("ok", json.loads(line[len(RESULT_MARKER):]), wall)
    tail = (done.stderr or done.stdout).strip().splitlines()[-3:]
    return WorkerOutcome("error", None, wall, f"exit {done.returncode}: " + " | ".join(tail))


def write_json(name: str, data: Any) -> Path:
    RESULTS_DIR.mkdir(exist_ok=True)
    path = RESULTS_DIR / name
    path.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    return path


def emit(result: dict[str, Any]) -> None:
    """A worker's result: one ``RESULT_MARKER`` JSON line on stdout (read by :func:`run_worker`)."""
    print(RESULT_MARKER + json.dumps(result), flush=True)


def per_call(function: Callable[[], Any], repeats: int, min_seconds: float = 0.02) -> tuple[float, Any]:
    """Per-call time: minimum over ``repeats`` of the mean of a loop lasting ≥ ``min_seconds`` (one untimed
    call first), and the last result."""
    result = function()
    start = time.perf_counter()
    function()
    single = time.perf_counter() - start
    loops = max(1, int(min_seconds / max(single, 1e-7)))
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(loops):
            result = function()
        best = min(best, (time.perf_counter() - start) / loops)
    return best, result


def _missing(x: Any) -> bool:
    return x is None or (isinstance(x, float) and math.isnan(x))


def format_seconds(seconds: float | None) -> str:
    """3 significant digits in µs, ms or s; "—" when there is no value."""
    if _missing(seconds):
        return "—"
    if seconds < 1e-3:
        return f"{seconds * 1e6:.3g} µs"
    if seconds < 1:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds:.3g} s"


def format_error(x: float | None) -> str:
    """An error as 1.2e-05 ("0" when exact, "—" when there is no value)."""
    if _missing(x):
        return "—"
    return "0" if x == 0 else f"{x:.1e}"


def loglog_figure(path: Path, curves: Sequence[tuple[Sequence[float], Sequence[float], str]], *, title: str,
                  x_label: str, y_label: str, notes: Sequence[str] = (), floor: float = 1e-17) -> None:
    """A log–log figure (SVG, PNG... by the suffix of ``path``) on matplotlib: one line with a marker at every
    point per curve (a one-point curve stays visible), dashed from the fifth curve on, the legend and ``notes``
    in a panel right of the axes so that they never hide data; values below ``floor`` are drawn at ``floor``."""
    from matplotlib.figure import Figure  # no pyplot: files only

    figure = Figure(figsize=(10.5, 4.8), layout="constrained")
    ax = figure.subplots()
    markers = "osD^vPX*"
    for index, (x, y, label) in enumerate(curves):
        xs = [float(v) for v in x]
        ys = [max(float(v), floor) for v in y]
        ax.loglog(xs, ys, marker=markers[index % len(markers)], markersize=4, linewidth=1.4,
                  linestyle="--" if index >= 4 else "-", label=label)
    ax.set_title(title, fontsize=10)
    ax.set_xlabel(x_label)
    ax.set_ylabel(y_label)
    ax.grid(True, which="major", linewidth=0.4, alpha=0.6)
    legend = ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, frameon=False)
    if notes:
        legend.set_title("\n".join(notes), prop={"size": 8})
        legend._legend_box.align = "left"
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, metadata={"Date": None} if path.suffix == ".svg" else None)  # reproducible files
