"""Shared helper of the worked examples in ``derivations/``: LaTeX and JSON writing, argument parsing, check reporting.

Not a derivation itself (``lindstedt derive --list`` skips files starting with ``_``).
A script builds a :class:`Sheet` in its ``derive(order)`` function — the case's
paragraphs, the ω_k of each variant, its checks against independent references —
and ends with ``sys.exit(common.main(sys.modules[__name__]))``; :func:`run` turns
the sheet into a :class:`Derivation` (LaTeX fragment + JSON dictionary of schema
``lindstedt.derivation/1``) and writes ``<name>.tex`` and ``<name>.json``.

``lindstedt derive`` loads this file and calls :func:`list_derivations`,
:func:`run_script` and :func:`render`.
"""

from __future__ import annotations

import argparse
import ast
import importlib.util
import json
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import ModuleType
from typing import Any

import sympy

import lindstedt

SCHEMA = "lindstedt.derivation/1"
DIRECTORY = Path(__file__).resolve().parent
DEFAULT_OUTPUT = DIRECTORY / "output"
#: Files written: LaTeX fragment and JSON coefficients.
FORMATS = ("latex", "json")
SUFFIXES = {"latex": ".tex", "json": ".json"}
#: What a run prints.
PRINT_FORMATS = ("text", "latex", "json")
#: Waveform terms v_0 … v_WAVEFORM_TERMS written out in LaTeX ("the first terms").
WAVEFORM_TERMS = 2
#: Significant digits of the decimal values written next to exact numbers (JSON).
DECIMAL_DIGITS = 30
#: Digits shown in LaTeX for decimal values.
LATEX_DIGITS = 15
LATEX_NAMES = {"a0": "a_{0}", "omega0": r"\omega_{0}", "epsilon": r"\varepsilon"}
REGIMES = {
    "smooth": "smooth nonlinearity",
    "contact": "crossing contact (simple roots of $v_0 - b$)",
    "no contact": "no contact at order zero",
    "grazing": r"grazing ($v_0 - b$ has a double root)",
}


# --------------------------------------------------------------------------- #
# small formatting helpers
# --------------------------------------------------------------------------- #
def latex(expression: Any) -> str:
    """sympy's LaTeX with a0, omega0, epsilon printed as a_{0}, \\omega_{0}, \\varepsilon."""
    expression = sympy.sympify(expression, strict=True)
    names = {symbol: LATEX_NAMES[symbol.name] for symbol in expression.free_symbols if symbol.name in LATEX_NAMES}
    return sympy.latex(expression, symbol_names=names)


def align(lines: Sequence[str]) -> str:
    return "\\begin{align*}\n" + " \\\\\n".join(lines) + "\n\\end{align*}"


def is_number(expression: Any) -> bool:
    return not sympy.sympify(expression, strict=True).free_symbols


def decimal(expression: Any, digits: int = DECIMAL_DIGITS) -> str | None:
    return str(sympy.N(expression, digits)) if is_number(expression) else None


def sci(value: float, digits: int = 1) -> str:
    """``value`` in LaTeX scientific notation, e.g. ``-8.2\\times 10^{-6}``."""
    if value == 0:
        return "0"
    mantissa, exponent = f"{value:.{digits}e}".split("e")
    return rf"{mantissa}\times 10^{{{int(exponent)}}}"


def omega_range(order: int) -> tuple[str, str]:
    """Plain and LaTeX names of ω_0..ω_order."""
    return f"omega_0..omega_{order}", rf"$\omega_{{0}}, \dots, \omega_{{{order}}}$"


def validity_latex(exponent: Any) -> str:
    return rf"0 \le t \le C\,\varepsilon^{{{sympy.sstr(exponent)}}}"


def validity_json(exponent: Any) -> dict[str, str]:
    return {"exponent": sympy.sstr(exponent), "time_scale": f"0 <= t <= C*epsilon**({sympy.sstr(exponent)})"}


def system_latex(system: lindstedt.UnilateralSystem, springs_text: str) -> str:
    """The N-dof equation with the exact K, A, b of ``system`` (M = I), then ``springs_text``."""
    return (
        rf"$M \ddot X + K X + \varepsilon A^{{T}} (A X - b)_{{+}} = 0$ with $M = I_{{{system.n_dof}}}$ and" + "\n"
        + align([
            rf"K &= {sympy.latex(sympy.Matrix(system.K_exact))}",
            rf"A &= {sympy.latex(sympy.Matrix(system.A_exact))},\quad b = {sympy.latex(sympy.Matrix(system.b_exact).T)}^{{T}}",
        ])
        + "\n" + springs_text
    )


# --------------------------------------------------------------------------- #
# checks and the sheet a derivation fills
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class Check:
    """One comparison with an independent reference: ``difference <= tolerance`` (``None``: exact comparison failed)."""

    variant: str
    quantity: str
    reference: str
    kind: str  # "exact" or "numeric"
    difference: float | None
    tolerance: float
    latex: tuple[str, str, str]  # variant, quantity, reference as LaTeX text

    @property
    def agrees(self) -> bool:
        return self.difference is not None and bool(self.difference <= self.tolerance)

    def to_json(self) -> dict[str, Any]:
        return {
            "variant": self.variant,
            "quantity": self.quantity,
            "reference": self.reference,
            "kind": self.kind,
            "max_abs_difference": None if self.difference is None else float(self.difference),
            "tolerance": float(self.tolerance),
            "agrees": self.agrees,
        }

    def to_latex(self) -> str:
        variant, quantity, reference = self.latex
        if self.kind == "exact":
            verdict = "exact agreement" if self.agrees else "DISAGREEMENT (exact comparison)"
        else:
            verdict = "agreement" if self.agrees else "DISAGREEMENT"
            shown = "n/a" if self.difference is None else sci(self.difference)
            verdict += rf" (largest difference ${shown}$, tolerance ${sci(self.tolerance, 0)}$)"
        return rf"  \item {variant}: {quantity} against {reference}: {verdict}."


@dataclass
class Sheet:
    """What ``derive(order)`` fills: LaTeX paragraphs, ω_k per variant, variants' JSON, checks, case-specific JSON."""

    title: str  # LaTeX, the \subsection* title
    equation: str  # plain text
    body: list[str] = field(default_factory=list)
    omega: dict[str, list[str]] = field(default_factory=dict)
    omega_float: dict[str, list[float | None]] = field(default_factory=dict)
    variants: list[dict[str, Any]] = field(default_factory=list)
    checks: list[Check] = field(default_factory=list)
    extra: dict[str, Any] = field(default_factory=dict)

    def paragraph(self, text: str) -> None:
        """Append LaTeX text."""
        self.body.append(text)

    def check(self, variant: str, quantity: str, reference: str, difference: float, tolerance: float,
              *, latex: tuple[str, str, str] | None = None) -> None:
        """Record a numeric comparison (agrees when ``difference <= tolerance``)."""
        self.checks.append(Check(variant, quantity, reference, "numeric", float(difference), tolerance,
                                 latex or (variant, quantity, reference)))

    def check_exact(self, variant: str, quantity: str, reference: str, equal: bool,
                    *, latex: tuple[str, str, str] | None = None) -> None:
        """Record an exact (symbolic) comparison."""
        self.checks.append(Check(variant, quantity, reference, "exact", 0.0 if equal else None, 0.0,
                                 latex or (variant, quantity, reference)))

    def add_expansion(self, label: str, expansion: lindstedt.Expansion, heading: str = "", note: str = "") -> None:
        """One 1-dof expansion: its own LaTeX (equation, ω_k), decimals, first waveform terms, regime; its own JSON."""
        omegas = expansion.omega
        parts = [rf"\paragraph{{{heading}}}" if heading else "", expansion.to_latex().strip()]
        if all(is_number(value) for value in omegas) and not all(value.is_Rational for value in omegas):
            parts.append("Numerically:\n" + align([rf"\omega_{{{exponent}}} &\approx {decimal(value, LATEX_DIGITS)}"
                                                   for exponent, value in zip(expansion.exponents, omegas) if exponent]))
        waveforms = expansion.waveforms[: min(len(omegas) - 1, WAVEFORM_TERMS) + 1]
        shown = ", ".join(f"$v_{{{w.order}}}$" for w in waveforms)
        extension = " (each given on $[0,\\pi]$, extended evenly and $2\\pi$-periodically)" if expansion.is_piecewise else ""
        gauge = latex(expansion.gauge)
        parts.append(
            rf"Waveform: $u(t) = \sum_{{k=0}}^{{{len(omegas) - 1}}} ({gauge})^{{k}} v_{{k}}(s) + O(\varepsilon^{{{latex(len(omegas) * expansion.gauge.as_base_exp()[1])}}})$"
            rf" with $s = \omega(\varepsilon)\, t$; first terms {shown}{extension}:" + "\n"
            + align([rf"v_{{{w.order}}}(s) &= {w.to_latex()}" for w in waveforms])
        )
        if expansion.stretched_arcs:  # pieces with a non-polynomial contact law: Y_k(τ), expanded in stretched time
            parts.append("\n\n".join(arc.to_latex() for arc in expansion.stretched_arcs))
        angles, exponent = expansion.contact_angles, expansion.validity_exponent
        angle_text = ""
        if angles:
            angle_text = "; contact angle" + ("s " if len(angles) > 1 else " ") + ", ".join(rf"$\beta = {latex(a)}$" for a in angles)
        parts.append(
            rf"Regime: {REGIMES[expansion.regime]}{angle_text}. The expansion is uniformly valid for ${validity_latex(exponent)}$"
            rf" (time scale $T_\varepsilon \sim \varepsilon^{{{sympy.sstr(exponent)}}}$)." + (f" {note}" if note else "")
        )
        self.body.append("\n\n".join(part for part in parts if part))

        data = expansion.to_dict()
        self.omega[label] = data["omega"]
        self.omega_float[label] = data["omega_float"]
        self.variants.append({
            "label": label,
            "regime": expansion.regime,
            "contact_angles": [sympy.sstr(angle) for angle in angles],
            "validity": validity_json(exponent),
            "omega_digits": [decimal(value) for value in omegas],
            "expansion": data,
        })

    def add_nnm(self, label: str, result: lindstedt.NNMExpansion) -> None:
        """One NNM: its own LaTeX (λ_j, ω_n, a_k), first terms, spring roots, validity; its own JSON."""
        shape = result.system.modes().shapes[:, result.mode - 1]
        vector = r"\left(" + ",\\ ".join(f"{value:.6g}" if abs(value) > 1e-14 else "0" for value in shape) + r"\right)^{T}"
        self.body.append(
            rf"\paragraph{{Mode {result.mode}.}}" + "\n" + result.to_latex().strip() + "\n"
            + rf"First terms: $X(t) = a_{{0}} \varphi_{{{result.mode}}} \cos(\omega t) + O(\varepsilon)$ with $a_0 = {float(result.a0):g}$, "
            + rf"$\varphi_{{{result.mode}}} = {vector}$. "
            + rf"Spring roots of $v_0$: {', '.join(result.spring_roots)}; valid for ${validity_latex(result.validity_exponent)}$."
        )
        data = result.to_dict()
        self.omega[label] = list(data["omega_digits"])
        self.omega_float[label] = list(data["omega"])
        self.variants.append({"label": label, "mode_shape": [float(v) for v in shape],
                              "validity": validity_json(result.validity_exponent), "nnm": data})


# --------------------------------------------------------------------------- #
# the finished derivation
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class Derivation:
    """A run of one script: the LaTeX fragment, the JSON dictionary, the files written, the time taken."""

    name: str
    description: str
    order: int
    latex: str
    json: dict[str, Any]
    checks: tuple[Check, ...]
    elapsed: float
    paths: tuple[Path, ...] = ()

    @property
    def agrees(self) -> bool:
        """Every check agrees with its reference."""
        return all(check.agrees for check in self.checks)


def description(module: ModuleType) -> str:
    """First line of the script's docstring."""
    return (module.__doc__ or "").strip().splitlines()[0].strip() if module.__doc__ else ""


def finish(sheet: Sheet, name: str, summary: str, order: int, elapsed: float) -> Derivation:
    """Assemble the LaTeX fragment and the JSON dictionary (schema ``lindstedt.derivation/1``)."""
    version = lindstedt.__version__
    header = (
        f"% lindstedt derive {name} --order {order}  (lindstedt {version}; regenerate with "
        f"`python derivations/{name}.py --order {order}`)\n"
        "% LaTeX fragment: \\input it into a document that loads amsmath.\n"
    )
    pieces = [rf"\subsection*{{{sheet.title}}}", *sheet.body]
    if sheet.checks:
        pieces.append("\\paragraph{Checks.}\n\\begin{itemize}\n" + "\n".join(check.to_latex() for check in sheet.checks)
                      + "\n\\end{itemize}")
    data: dict[str, Any] = {
        "schema": SCHEMA,
        "name": name,
        "description": summary,
        "order": order,
        "lindstedt_version": version,
        "equation": sheet.equation,
        "omega": sheet.omega,
        "omega_float": sheet.omega_float,
        "variants": sheet.variants,
        "checks": [check.to_json() for check in sheet.checks],
        **sheet.extra,
    }
    return Derivation(name, summary, order, header + "\n\n".join(pieces) + "\n", data, tuple(sheet.checks), elapsed)


def write(result: Derivation, directory: str | Path, formats: Sequence[str] = FORMATS) -> Derivation:
    """Write ``<name>.tex`` and/or ``<name>.json`` into ``directory`` (created); the result with its paths."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    texts = {"latex": result.latex, "json": json.dumps(result.json, indent=2, allow_nan=False) + "\n"}
    paths = []
    for item in dict.fromkeys(formats):
        path = directory / f"{result.name}{SUFFIXES[item]}"
        path.write_text(texts[item], encoding="utf-8")
        paths.append(path)
    return replace(result, paths=tuple(paths))


def render(result: Derivation, format: str = "text") -> str:
    """Printable form: ``"latex"`` (the fragment), ``"json"`` (indented) or ``"text"`` (coefficients, checks, paths)."""
    if format == "latex":
        return result.latex.rstrip("\n")
    if format == "json":
        return json.dumps(result.json, indent=2, allow_nan=False)
    if format != "text":
        raise lindstedt.ProblemError(f"unknown format {format!r}; choose among {list(PRINT_FORMATS)}")
    lines = [f"{result.name} (order {result.order}): {result.description}"]
    for label, values in result.json["omega"].items():
        lines.append(f"  {label}: omega = {', '.join(values)}")
    for check in result.checks:
        verdict = "agrees" if check.agrees else "DISAGREES"
        shown = "n/a" if check.difference is None else f"{check.difference:.1e}"
        lines.append(f"  check [{check.variant}] {check.quantity}: {verdict} (max |difference| {shown}, tolerance {check.tolerance:.0e})")
    lines += [f"  wrote {path}" for path in result.paths]
    lines.append(f"  derived in {result.elapsed:.2f} s")
    return "\n".join(lines)


# --------------------------------------------------------------------------- #
# running scripts
# --------------------------------------------------------------------------- #
def list_derivations(directory: str | Path = DIRECTORY) -> list[tuple[str, str]]:
    """(name, first docstring line) of every ``*.py`` script in ``directory`` not starting with ``_``, by name."""
    found = []
    for path in sorted(Path(directory).glob("*.py")):
        if not path.name.startswith("_"):
            docstring = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
            found.append((path.stem, docstring.strip().splitlines()[0] if docstring.strip() else ""))
    return found


def load(name: str, directory: str | Path = DIRECTORY) -> ModuleType:
    """Import ``derivations/<name>.py`` as a module (its ``__main__`` block does not run); cached."""
    key = f"lindstedt_derivation_{name}"
    path = Path(directory).resolve() / f"{name}.py"
    module = sys.modules.get(key)
    if module is None or Path(module.__file__).resolve() != path:
        spec = importlib.util.spec_from_file_location(key, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[key] = module
        try:
            spec.loader.exec_module(module)
        except BaseException:
            del sys.modules[key]
            raise
    return module


def _order(name: str, module: ModuleType, order: Any) -> int:
    if order is None:
        return module.DEFAULT_ORDER
    highest = getattr(module, "MAX_ORDER", None)
    if isinstance(order, bool) or not isinstance(order, int) or order < 1 or (highest is not None and order > highest):
        allowed = ("only order 1" if highest == 1 else
                   f"an integer order between 1 and {highest}" if highest else "an integer order >= 1")
        raise lindstedt.OrderError(f"derivation {name!r} takes {allowed}, got {order!r}")
    return order


def run(module: ModuleType, order: int | None = None, output: str | Path | None = None,
        formats: Sequence[str] = FORMATS) -> Derivation:
    """Derive the script's case at ``order`` (default its ``DEFAULT_ORDER``); write the files into ``output`` if given."""
    name = Path(module.__file__).stem
    order = _order(name, module, order)
    if isinstance(formats, str):
        formats = (formats,)
    unknown = [item for item in formats if item not in FORMATS]
    if unknown:
        raise lindstedt.ProblemError(f"unknown output format(s) {unknown}; choose among {list(FORMATS)}")
    started = time.perf_counter()
    sheet = module.derive(order)
    result = finish(sheet, name, description(module), order, time.perf_counter() - started)
    return result if output is None else write(result, output, formats)


def run_script(name: str, order: int | None = None, output: str | Path | None = None,
               formats: Sequence[str] = FORMATS, directory: str | Path = DIRECTORY) -> Derivation:
    """:func:`run` the script ``<directory>/<name>.py`` (what ``lindstedt derive NAME`` does)."""
    names = [item for item, _ in list_derivations(directory)]
    if name not in names:
        raise lindstedt.ProblemError(
            f"unknown derivation {name!r}; choose one of {', '.join(names)} (see `lindstedt derive --list`)"
        )
    return run(load(name, directory), order, output, formats)


def main(module: ModuleType, argv: Sequence[str] | None = None) -> int:
    """Command line of a script: ``python derivations/<name>.py [--order N] [--output DIR] [--format F]``.

    Prints the coefficients and checks (or the LaTeX / JSON) and where the files went.
    Exit status 0; 1 when a check disagrees with its reference; 2 on bad input
    (``error: ...`` on stderr, nothing written).
    """
    name = Path(module.__file__).stem
    parser = argparse.ArgumentParser(prog=f"derivations/{name}.py", description=description(module))
    parser.add_argument("--order", type=int, default=None, help=f"expansion order (default {module.DEFAULT_ORDER})")
    parser.add_argument("--output", default=str(DEFAULT_OUTPUT), help=f"output directory (default {DEFAULT_OUTPUT})")
    parser.add_argument("--format", choices=PRINT_FORMATS, default="text", help="what to print (default text)")
    arguments = parser.parse_args(argv)
    try:
        result = run(module, order=arguments.order, output=arguments.output)
    except lindstedt.LindstedtError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    except OSError as error:
        print(f"error: cannot write to {arguments.output!r}: {error.strerror or error}", file=sys.stderr)
        return 2
    print(render(result, arguments.format))
    if not result.agrees:
        print("error: a check disagrees with its reference (see above)", file=sys.stderr)
        return 1
    return 0
