"""Named derivations behind ``lindstedt derive``: one worked case per name, exported as LaTeX and JSON.

The one-degree-of-freedom cases expand (strained coordinates, ``s = ω t``)

    u'' + ω0² u + ε f(u) = 0,    u(0) = a0,  u'(0) = 0,

and the N-degree-of-freedom cases

    M X'' + K X + ε W (A X − b)_+ = 0      (chains: M = I, K = tridiag(−1, 2, −1), W = Aᵀ).

Registry (:data:`DERIVATIONS`, in this order):

``duffing``           f = u³, symbolic a0, ω0, both amplitude normalisations.
``u_plus``            f = a·u_+, symbolic a, a0, ω0.
``gap``               f = (u − b)_+, b > 0: κ = b/a0 = 1/3 exactly, and the
                      closed forms of ω1, ω2 for symbolic κ.
``prestress``         f = (u − b)_+, b = −1/2 < 0 (a preloaded spring).
``negative_release``  f = (u − 1/3)_+ released at a0 = −1.
``grazing``           |a0| = |b|: regime "grazing", linear approximation, validity ε^{-1/2}.
``nnm_2dof``          NNMs (Theorem 4.1) of a 2-mass chain with a zero-gap spring on mass 1.
``nnm_5dof``          NNMs of the 5-mass chain with a zero-gap spring on mass 1
                      and a preloaded spring (b = −1/5) on mass 4.
``all_modes``         Theorem 4.3: first-order corrections with all modes of a
                      3-mass chain excited.

Each derivation builds a LaTeX document fragment (``\\subsection*`` plus
``align*`` blocks; needs ``amsmath``; pure ASCII) with the equation, the ω_k,
the first terms of the waveform and the validity time scale, and a JSON
dictionary.  Every case with an independent reference also records its check
(exact Duffing and u_+ series, Cauchy-integral Taylor coefficients of the exact
piecewise-linear period, Theorem 4.3 against the NNM hierarchy).

JSON schema ``lindstedt.derivation/1``::

    {
      "schema": "lindstedt.derivation/1", "name": str, "description": str,
      "order": int, "lindstedt_version": str, "equation": str,
      "omega": {label: [str, ...]},         # ω_0..ω_N per variant (sympy-parsable; decimals for N-dof)
      "omega_float": {label: [float | null, ...]},
      "variants": [{"label": str, ...}],    # everything else, per variant
      "checks": [{"variant", "quantity", "reference", "kind", "max_abs_difference", "tolerance", "agrees"}],
      ...                                    # case-specific keys ("closed_forms", "exact_comparison", ...)
    }

Examples
--------
>>> result = derive("duffing", order=2)
>>> result.json["omega"]["initial"]
['omega0', '3*a0**2/(8*omega0)', '-21*a0**4/(256*omega0**3)']
>>> [name for name, _ in list_derivations()][:3]
['duffing', 'u_plus', 'gap']
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from types import MappingProxyType
from typing import Any, Callable, Mapping, Sequence

import mpmath
import numpy as np
import sympy

from ._errors import LindstedtError, OrderError, ProblemError

__all__ = [
    "DERIVATIONS",
    "DerivationResult",
    "DerivationSpec",
    "FORMATS",
    "derive",
    "format_derivation",
    "list_derivations",
    "script_main",
]

SCHEMA = "lindstedt.derivation/1"
FORMATS = ("latex", "json")
_SUFFIXES = {"latex": ".tex", "json": ".json"}
_PRINT_FORMATS = ("text", "latex", "json")

#: Waveform terms v_0 … v_WAVEFORM_TERMS written out ("the first terms").
WAVEFORM_TERMS = 2
#: Significant digits of the decimal values written next to exact numbers.
DECIMAL_DIGITS = 30
#: Digits shown in LaTeX for numeric (N-dof) results.
LATEX_DIGITS = 15
#: Absolute agreement required between exact ω_k and the Cauchy-integral reference (computed at 40 digits).
PIECEWISE_REFERENCE_TOLERANCE = 1e-20
#: Working digits of the piecewise-linear reference.
PIECEWISE_REFERENCE_DIGITS = 40
#: Agreement required between the NNM ω_1 and Theorem 4.3's λ¹ for a single excited mode:
#: exact closed form for zero gaps, Hann-windowed average (accuracy ~1e-7) otherwise.
NNM_CROSS_CHECK_TOLERANCE = {"closed form (zero gaps)": 1e-12, "almost-periodic average": 1e-6}
#: Grazing from outside (b = a0): the exact solution is a0 cos(omega0 t); allowed difference at 30 digits.
GRAZING_EXACT_TOLERANCE = 1e-25
#: Working digits of the N-dof strained-coordinates arithmetic.
NNM_PRECISION = 30

_A0 = sympy.Symbol("a0", positive=True)
_OMEGA0 = sympy.Symbol("omega0", positive=True)
_KAPPA = sympy.Symbol("kappa", real=True)
_BETA = sympy.Symbol("beta", positive=True)
_SIGMA = sympy.Symbol("sigma", positive=True)
_LATEX_NAMES = {"a0": "a_{0}", "omega0": r"\omega_{0}", "epsilon": r"\varepsilon"}


# --------------------------------------------------------------------------- #
# public types
# --------------------------------------------------------------------------- #
@dataclass(frozen=True)
class DerivationSpec:
    """One registered derivation.

    Attributes
    ----------
    name : str
        Registry key (also the script ``derivations/<name>.py``).
    description : str
        One line.
    default_order : int
        Order used when none is given.
    max_order : int
        Highest order accepted (the lowest is 1).
    """

    name: str
    description: str
    default_order: int
    max_order: int
    _builder: Callable[[int], "_Content"] = field(repr=False, compare=False)


@dataclass(frozen=True)
class DerivationResult:
    """What :func:`derive` produced.

    Attributes
    ----------
    name : str
    description : str
    order : int
    latex : str
        The LaTeX document fragment (also written to ``<name>.tex``).
    json : dict
        The JSON-ready dictionary, schema ``lindstedt.derivation/1`` (also written to ``<name>.json``).
    paths : tuple of pathlib.Path
        Files written (empty without an output directory).
    elapsed : float
        Wall time of the derivation in seconds.
    """

    name: str
    description: str
    order: int
    latex: str
    json: dict[str, Any]
    paths: tuple[Path, ...]
    elapsed: float


@dataclass
class _Content:
    """What a builder returns: the LaTeX body (after the title) and the case-specific JSON."""

    title: str
    equation: str
    body: list[str] = field(default_factory=list)
    omega: dict[str, list[str]] = field(default_factory=dict)
    omega_float: dict[str, list[float | None]] = field(default_factory=dict)
    variants: list[dict[str, Any]] = field(default_factory=list)
    checks: list[_Check] = field(default_factory=list)
    extra: dict[str, Any] = field(default_factory=dict)


# --------------------------------------------------------------------------- #
# small helpers
# --------------------------------------------------------------------------- #
def _latex(expression: Any) -> str:
    expression = sympy.sympify(expression, strict=True)
    names = {symbol: _LATEX_NAMES[symbol.name] for symbol in expression.free_symbols if symbol.name in _LATEX_NAMES}
    return sympy.latex(expression, symbol_names=names)


def _is_number(expression: sympy.Expr) -> bool:
    return not sympy.sympify(expression, strict=True).free_symbols


def _as_float(expression: sympy.Expr) -> float | None:
    return float(expression) if _is_number(expression) else None


def _decimal(expression: sympy.Expr, digits: int = DECIMAL_DIGITS) -> str | None:
    return str(sympy.N(expression, digits)) if _is_number(expression) else None


def _mp(value: Any, digits: int = LATEX_DIGITS) -> str:
    return mpmath.nstr(value, digits)


def _align(lines: Sequence[str]) -> str:
    return "\\begin{align*}\n" + " \\\\\n".join(lines) + "\n\\end{align*}"


def _validity_latex(exponent: sympy.Expr) -> str:
    return rf"0 \le t \le C\,\varepsilon^{{{sympy.sstr(exponent)}}}"


def _validity_json(exponent: sympy.Expr) -> dict[str, str]:
    return {"exponent": sympy.sstr(exponent), "time_scale": f"0 <= t <= C*epsilon**({sympy.sstr(exponent)})"}


def _sci(value: float, digits: int = 1) -> str:
    """``value`` in LaTeX scientific notation, e.g. ``-8.2\\times 10^{-6}``."""
    if value == 0:
        return "0"
    mantissa, exponent = f"{value:.{digits}e}".split("e")
    return rf"{mantissa}\times 10^{{{int(exponent)}}}"


def _omega_range(order: int) -> tuple[str, str]:
    """Plain and LaTeX names of ω_0..ω_order."""
    return f"omega_0..omega_{order}", rf"$\omega_{{0}}, \dots, \omega_{{{order}}}$"


@dataclass(frozen=True)
class _Check:
    """One comparison with an independent reference; plain text for JSON, LaTeX for the fragment."""

    variant: str
    quantity: str
    reference: str
    kind: str  # "exact" or "numeric"
    difference: float
    tolerance: float
    variant_latex: str
    quantity_latex: str
    reference_latex: str

    @property
    def agrees(self) -> bool:
        return bool(self.difference <= self.tolerance)

    def to_json(self) -> dict[str, Any]:
        return {
            "variant": self.variant,
            "quantity": self.quantity,
            "reference": self.reference,
            "kind": self.kind,
            "max_abs_difference": float(self.difference),
            "tolerance": float(self.tolerance),
            "agrees": self.agrees,
        }

    def to_latex(self) -> str:
        if self.kind == "exact":
            verdict = "exact agreement" if self.agrees else "DISAGREEMENT (exact comparison)"
        else:
            verdict = "agreement" if self.agrees else "DISAGREEMENT"
            verdict += rf" (largest difference ${_sci(self.difference)}$, tolerance ${_sci(self.tolerance, 0)}$)"
        return rf"  \item {self.variant_latex}: {self.quantity_latex} against {self.reference_latex}: {verdict}."


def _checks_latex(checks: Sequence[_Check]) -> str:
    if not checks:
        return ""
    return "\\paragraph{Checks.}\n\\begin{itemize}\n" + "\n".join(check.to_latex() for check in checks) + "\n\\end{itemize}"


def _problem_dict(problem: Any) -> dict[str, Any]:
    return {
        "description": problem.describe(),
        "f": sympy.sstr(problem.f),
        "a0": sympy.sstr(problem.a0),
        "omega0": sympy.sstr(problem.omega0),
        "parameters": {str(symbol): sympy.sstr(value) for symbol, value in problem.params},
        "normalization": problem.normalization,
    }


# --------------------------------------------------------------------------- #
# one-degree-of-freedom expansions
# --------------------------------------------------------------------------- #
def _waveform_latex(waveform: Any) -> str:
    """LaTeX of v_k(s): a cosine polynomial, or cases on [0, π] for piecewise-linear f."""
    if not hasattr(waveform, "branches"):
        return _latex(waveform.to_expr())
    if len(set(waveform.branches)) == 1:
        return _latex(waveform.branches[0])
    limits = [sympy.Integer(0), *waveform.breakpoints, sympy.pi]
    rows = [
        rf"{_latex(branch)}, & {_latex(lower)} \le s \le {_latex(upper)}"
        for branch, lower, upper in zip(waveform.branches, limits, limits[1:])
    ]
    return "\\begin{cases}\n" + " \\\\\n".join(rows) + "\n\\end{cases}"


def _waveform_json(waveform: Any) -> dict[str, Any]:
    if not hasattr(waveform, "branches"):
        return {"order": waveform.order, "cosine_coefficients": {str(n): sympy.sstr(c) for n, c in waveform.coefficients}}
    return {
        "order": waveform.order,
        "domain": "[0, pi], extended evenly and 2*pi-periodically",
        "breakpoints": [sympy.sstr(value) for value in waveform.breakpoints],
        "branches": [sympy.sstr(branch) for branch in waveform.branches],
    }


def _expansion_variant(content: _Content, label: str, heading: str, expansion: Any, *, note: str = "") -> dict[str, Any]:
    """Add one 1-dof expansion to ``content`` (LaTeX and JSON); returns its JSON variant."""
    omegas, alphas = expansion.omega, expansion.alpha
    terms = min(expansion.order, WAVEFORM_TERMS)
    waveforms = expansion.waveforms[: terms + 1]
    regime, exponent, angles = expansion.regime, expansion.validity_exponent, expansion.contact_angles

    parts = [rf"\paragraph{{{heading}}}" if heading else "", expansion.to_latex(waveforms=False).strip()]
    if all(_is_number(value) for value in omegas) and not all(value.is_Rational for value in omegas):
        numbers = [rf"\omega_{{{k}}} &\approx {_decimal(value, LATEX_DIGITS)}" for k, value in enumerate(omegas) if k]
        parts.append("Numerically:\n" + _align(numbers))
    waveform_lines = [rf"v_{{{w.order}}}(s) &= {_waveform_latex(w)}" for w in waveforms]
    shown = ", ".join(f"$v_{{{w.order}}}$" for w in waveforms)
    extension = " (each given on $[0,\\pi]$, extended evenly and $2\\pi$-periodically)" if expansion.is_piecewise else ""
    parts.append(
        rf"Waveform: $u(t) = \sum_{{k=0}}^{{{expansion.order}}} \varepsilon^{{k}} v_{{k}}(s) + O(\varepsilon^{{{expansion.order + 1}}})$"
        rf" with $s = \omega(\varepsilon)\, t$; first terms {shown}{extension}:" + "\n" + _align(waveform_lines)
    )
    regime_text = {"smooth": "smooth nonlinearity", "contact": "crossing contact (simple roots of $v_0 - b$)",
                   "no contact": "no contact at order zero", "grazing": r"grazing ($v_0 - b$ has a double root)"}[regime]
    angle_text = ""
    if angles:
        angle_text = "; contact angle" + ("s " if len(angles) > 1 else " ") + ", ".join(rf"$\beta = {_latex(a)}$" for a in angles)
    parts.append(
        rf"Regime: {regime_text}{angle_text}. The expansion is uniformly valid for ${_validity_latex(exponent)}$"
        rf" (time scale $T_\varepsilon \sim \varepsilon^{{{sympy.sstr(exponent)}}}$)." + (f" {note}" if note else "")
    )
    content.body.append("\n\n".join(part for part in parts if part))

    omega_text = [sympy.sstr(value) for value in omegas]
    content.omega[label] = omega_text
    content.omega_float[label] = [_as_float(value) for value in omegas]
    variant = {
        "label": label,
        "problem": _problem_dict(expansion.problem),
        "order": expansion.order,
        "regime": regime,
        "contact_angles": [sympy.sstr(angle) for angle in angles],
        "validity": _validity_json(exponent),
        "omega": omega_text,
        "omega_float": [_as_float(value) for value in omegas],
        "omega_digits": [_decimal(value) for value in omegas],
        "alpha": [sympy.sstr(value) for value in alphas],
        "alpha_float": [_as_float(value) for value in alphas],
        "waveforms": [_waveform_json(w) for w in waveforms],
    }
    content.variants.append(variant)
    return variant


def _expand(f: str, order: int, **arguments: Any) -> Any:
    from ._api import expand

    return expand(f, order=order, **arguments)


def _piecewise_numeric_check(content: _Content, label: str, label_latex: str, expansion: Any, *, b: Any, a0: Any) -> None:
    """ω_1..ω_N against the Cauchy-integral Taylor coefficients of the exact period (ω0 = 1, a = 1)."""
    from ._reference_piecewise import piecewise_linear_frequency_taylor

    with mpmath.workdps(PIECEWISE_REFERENCE_DIGITS):
        reference = piecewise_linear_frequency_taylor(
            expansion.order, a=1, b=b, a0=a0, omega0=1, dps=PIECEWISE_REFERENCE_DIGITS
        )
        worst = max(
            abs(mpmath.mpf(str(sympy.N(value, PIECEWISE_REFERENCE_DIGITS))) - reference[k][0])
            for k, value in enumerate(expansion.omega)
        )
    quantity, quantity_latex = _omega_range(expansion.order)
    reference = "the Taylor coefficients of the exact period (Cauchy integral, {} digits)".format(PIECEWISE_REFERENCE_DIGITS)
    content.checks.append(
        _Check(label, quantity, reference, "numeric", float(worst), PIECEWISE_REFERENCE_TOLERANCE, label_latex, quantity_latex, reference)
    )


# --------------------------------------------------------------------------- #
# builders: one degree of freedom
# --------------------------------------------------------------------------- #
def _build_duffing(order: int) -> _Content:
    from ._reference_duffing import duffing_frequency_taylor

    content = _Content(
        title=r"Duffing oscillator: $f(u) = u^{3}$",
        equation="u'' + omega0**2*u + epsilon*u**3 = 0, u'(0) = 0",
    )
    content.body.append(
        r"Symbolic amplitude $a_{0}$ and linear frequency $\omega_{0}$. Two normalisations of the amplitude: "
        r"\emph{initial} ($u(0) = a_{0}$, every $v_k(0) = 0$) and \emph{harmonic} ($a_{0}$ is the amplitude "
        r"of the first harmonic, no $\cos s$ in $v_k$, $k \ge 1$). They agree at first order and differ from $\omega_2$ on."
    )
    for normalization, heading in (("initial", r"Initial normalisation, $u(0) = a_{0}$."),
                                   ("harmonic", r"Harmonic normalisation, $a_{0}$ = first-harmonic amplitude.")):
        expansion = _expand("u**3", order, normalization=normalization)
        _expansion_variant(content, normalization, heading, expansion)
        reference = duffing_frequency_taylor(order, normalization=normalization)
        scale = _A0**2 / _OMEGA0**2
        exact = all(sympy.simplify(value - _OMEGA0 * reference[k] * scale**k) == 0 for k, value in enumerate(expansion.omega))
        reference = "the Taylor series of the exact frequency (complete elliptic integral K, exact rationals)"
        quantity, quantity_latex = _omega_range(order)
        content.checks.append(
            _Check(normalization, quantity, reference, "exact", 0.0 if exact else float("inf"), 0.0,
                   f"{normalization.capitalize()} normalisation", quantity_latex, reference)
        )
    return content


def _build_u_plus(order: int) -> _Content:
    from ._reference_piecewise import piecewise_linear_frequency_taylor_symbolic

    content = _Content(
        title=r"Unilateral spring without gap: $f(u) = a\,u_{+}$",
        equation="u'' + omega0**2*u + epsilon*a*max(u, 0) = 0, u(0) = a0, u'(0) = 0",
    )
    content.body.append(
        r"Symbolic stiffness $a$, amplitude $a_{0} > 0$ and $\omega_{0}$. The frequency does not depend on $a_{0}$: "
        r"the exact period is $\pi/\omega_{0} + \pi/\sqrt{\omega_{0}^{2} + \varepsilon a}$ (two harmonic half-arcs)."
    )
    expansion = _expand("a*Max(0, u)", order, params={"a": None})
    _expansion_variant(content, "a u_+", "", expansion)
    epsilon = sympy.Symbol("epsilon")
    a_symbol = next(symbol for symbol in expansion.problem.free_symbols if symbol.name == "a")
    series = piecewise_linear_frequency_taylor_symbolic(order, epsilon=epsilon, a=a_symbol, omega0=_OMEGA0)
    exact = all(sympy.simplify(value - series.coeff(epsilon, k)) == 0 for k, value in enumerate(expansion.omega))
    quantity, quantity_latex = _omega_range(order)
    content.checks.append(
        _Check("a u_+", quantity, "the Taylor series of the exact period pi/omega0 + pi/sqrt(omega0**2 + epsilon*a)", "exact",
               0.0 if exact else float("inf"), 0.0, r"$a\,u_{+}$", quantity_latex,
               r"the Taylor series of the exact period $\pi/\omega_{0} + \pi/\sqrt{\omega_{0}^{2} + \varepsilon a}$")
    )
    return content


def _kappa_closed_form(expression: sympy.Expr, b_symbol: sympy.Symbol) -> sympy.Expr:
    """Rewrite ω_k(b) (a0 = 1) in κ, β = arccos κ and σ = sqrt(1 − κ²), reduced modulo σ² = 1 − κ²."""
    one_minus = 1 - _KAPPA**2
    value = expression.subs(b_symbol, _KAPPA)
    value = value.replace(lambda x: isinstance(x, sympy.acos) and x.args[0] == _KAPPA, lambda x: _BETA)
    value = value.replace(
        lambda x: x.is_Pow and sympy.expand(x.base - one_minus) == 0 and (2 * x.exp).is_integer,
        lambda x: _SIGMA ** int(2 * x.exp),
    )
    numerator, denominator = sympy.fraction(sympy.together(value))
    power = sympy.degree(denominator, _SIGMA)
    numerator, denominator = sympy.expand(numerator * _SIGMA**power), sympy.expand(denominator * _SIGMA**power)
    relation = _SIGMA**2 - one_minus
    numerator = sympy.rem(numerator, relation, _SIGMA)
    denominator = sympy.rem(denominator, relation, _SIGMA)
    numerator, denominator = sympy.fraction(sympy.cancel(numerator / denominator))
    numerator = sympy.collect(sympy.expand(numerator), [_BETA, _SIGMA], sympy.factor)
    numerator = numerator.subs((_KAPPA - 1) * (_KAPPA + 1), -(_SIGMA**2))
    return numerator / sympy.factor(denominator)


@lru_cache(maxsize=None)
def _gap_closed_forms() -> tuple[sympy.Expr, ...]:
    """(ω_1, ω_2) of u'' + ω0² u + ε (u − b)_+ = 0, u(0) = a0 > 0, as functions of κ = b/a0 (|κ| < 1)."""
    expansion = _expand("Max(0, u - b)", 2, a0=1, params={"b": None})
    b_symbol = next(symbol for symbol in expansion.problem.free_symbols if symbol.name == "b")
    return tuple(_kappa_closed_form(expansion.omega[k], b_symbol) for k in (1, 2))


def _kappa_value(expression: sympy.Expr, kappa: sympy.Expr) -> sympy.Expr:
    return expression.subs({_KAPPA: kappa, _BETA: sympy.acos(kappa), _SIGMA: sympy.sqrt(1 - kappa**2)})


def _closed_form_check(content: _Content, label: str, label_latex: str, expansion: Any, kappa: sympy.Expr) -> None:
    """The symbolic-κ ω_1, ω_2 at this κ against the exact derivation (ω0 = 1), to 40 digits."""
    forms = _gap_closed_forms()
    worst = max(
        abs(sympy.N(_kappa_value(form, kappa).subs(_OMEGA0, 1) - expansion.omega[k + 1], PIECEWISE_REFERENCE_DIGITS))
        for k, form in enumerate(forms[: expansion.order])
    )
    content.checks.append(
        _Check(label, "omega_1, omega_2", f"the symbolic-kappa closed forms at kappa = {kappa}", "numeric", float(worst),
               PIECEWISE_REFERENCE_TOLERANCE, label_latex, r"$\omega_{1}, \omega_{2}$",
               rf"the symbolic-$\kappa$ closed forms at $\kappa = {_latex(kappa)}$")
    )


def _closed_forms_section(content: _Content) -> None:
    forms = _gap_closed_forms()
    lines = [rf"\omega_{{{k + 1}}} &= {_latex(form)}" for k, form in enumerate(forms)]
    content.body.append(
        r"\paragraph{Symbolic $\kappa$.} For $a_{0} > 0$ and $|\kappa| < 1$, with $\kappa = b/a_{0}$, "
        r"$\beta = \arccos\kappa$ (the contact angle) and $\sigma = \sqrt{1-\kappa^{2}} = \sin\beta$, "
        r"the closed forms (independent of $a_{0}$ at fixed $\kappa$; $b < 0$ is the prestressed spring) are" + "\n" + _align(lines)
    )
    content.extra["closed_forms"] = {
        "equation": "u'' + omega0**2*u + epsilon*max(u - b, 0) = 0, u(0) = a0 > 0, u'(0) = 0",
        "valid_for": "|kappa| < 1",
        "definitions": {"kappa": "b/a0", "beta": "acos(kappa)", "sigma": "sqrt(1 - kappa**2)"},
        "omega": {f"omega_{k + 1}": sympy.sstr(form) for k, form in enumerate(forms)},
    }


def _build_gap(order: int) -> _Content:
    content = _Content(
        title=r"Unilateral spring with a gap: $f(u) = (u - b)_{+}$, $b > 0$",
        equation="u'' + omega0**2*u + epsilon*max(u - b, 0) = 0, u(0) = a0, u'(0) = 0",
    )
    content.body.append(
        r"The spring engages only while $u > b$. With $\kappa = b/a_{0} = 1/3$ ($a_{0} = \omega_{0} = 1$) "
        r"every coefficient is an exact closed form in $\pi$, $\arccos\frac{1}{3}$ and $\sqrt{2}$."
    )
    kappa = sympy.Rational(1, 3)
    expansion = _expand("Max(0, u - 1/3)", order, a0=1, omega0=1)
    _expansion_variant(content, "kappa = 1/3", r"$\kappa = 1/3$.", expansion)
    _piecewise_numeric_check(content, "kappa = 1/3", r"$\kappa = 1/3$", expansion, b=kappa, a0=1)
    _closed_forms_section(content)
    _closed_form_check(content, "kappa = 1/3", r"$\kappa = 1/3$", expansion, kappa)
    return content


def _build_prestress(order: int) -> _Content:
    content = _Content(
        title=r"Prestressed unilateral spring: $f(u) = (u - b)_{+}$, $b = -\frac{1}{2} < 0$",
        equation="u'' + omega0**2*u + epsilon*max(u + 1/2, 0) = 0, u(0) = 1, u'(0) = 0",
    )
    content.body.append(
        r"With $b < 0$ the spring is already compressed at $u = 0$: it is in contact for $u > b$, "
        r"most of the period. Here $a_{0} = \omega_{0} = 1$, $\kappa = -1/2$, contact angle $2\pi/3$."
    )
    kappa = sympy.Rational(-1, 2)
    expansion = _expand("Max(0, u + 1/2)", order, a0=1, omega0=1)
    _expansion_variant(content, "kappa = -1/2", "", expansion)
    _piecewise_numeric_check(content, "kappa = -1/2", r"$\kappa = -1/2$", expansion, b=kappa, a0=1)
    _closed_form_check(content, "kappa = -1/2", r"$\kappa = -1/2$", expansion, kappa)
    return content


def _build_negative_release(order: int) -> _Content:
    content = _Content(
        title=r"Release on the far side: $f(u) = (u - \frac{1}{3})_{+}$, $a_{0} = -1$",
        equation="u'' + omega0**2*u + epsilon*max(u - 1/3, 0) = 0, u(0) = -1, u'(0) = 0",
    )
    content.body.append(
        r"Released at $a_{0} = -1 < 0$ ($\omega_{0} = 1$) the mass meets the spring half a period later, "
        r"around $s = \pi$. At first order only the orbit of $v_0$ matters, so $\omega_1$ equals that of the release "
        r"at $a_{0} = +1$; from $\omega_2$ on they differ (the two releases lie on different orbits)."
    )
    expansion = _expand("Max(0, u - 1/3)", order, a0=-1, omega0=1)
    _expansion_variant(content, "a0 = -1", "", expansion)
    _piecewise_numeric_check(content, "a0 = -1", r"$a_{0} = -1$", expansion, b=sympy.Rational(1, 3), a0=-1)
    mirror = _expand("Max(0, u - 1/3)", min(order, 2), a0=1, omega0=1)
    differences = [sympy.Integer(0) if k == 0 else sympy.N(expansion.omega[k] - mirror.omega[k], DECIMAL_DIGITS)
                   for k in range(mirror.order + 1)]
    lines = [rf"\omega_{{{k}}}(a_0 = -1) - \omega_{{{k}}}(a_0 = +1) &\approx {sympy.N(value, LATEX_DIGITS)}"
             for k, value in enumerate(differences) if k]
    content.body.append("Comparison with the release at $a_{0} = +1$ (the \\texttt{gap} case):\n" + _align(lines))
    content.extra["comparison_with_positive_release"] = {
        "omega_difference": [str(value) for value in differences],
        "note": "omega_k(a0 = -1) - omega_k(a0 = +1), same f",
    }
    return content


def _build_grazing(order: int) -> _Content:
    from ._expansion import EPSILON
    from ._reference_piecewise import piecewise_linear_exact_frequency

    content = _Content(
        title=r"Grazing: $|a_{0}| = |b|$",
        equation="u'' + omega0**2*u + epsilon*max(u - b, 0) = 0, u(0) = a0 = 1, b = 1 or b = -1",
    )
    content.body.append(
        r"When $|a_{0}| = |b|$ the order-zero gap $v_0 - b$ has a double root (a turning point touches the "
        r"switching point): the expansion reduces to the \emph{linear approximation} of the side the orbit "
        r"lives on, and it holds only on the shorter time scale $T_\varepsilon \sim \varepsilon^{-1/2}$, "
        r"because the true frequency is not analytic in $\varepsilon$ there."
    )
    cases = (
        ("b = a0", 1, r"$b = a_{0} = 1$: the turning point touches the spring, no contact; $\omega = \omega_{0}$ exactly."),
        ("b = -a0", -1, r"$b = -a_{0} = -1$: always in contact except at the far turning point; linear frequency $\sqrt{\omega_{0}^{2} + \varepsilon}$."),
    )
    table: dict[str, list[dict[str, str]]] = {}
    for label, b_value, heading in cases:
        expansion = _expand(f"Max(0, u - ({b_value}))", order, a0=1)
        _expansion_variant(content, label, heading, expansion)
        approximation = expansion.frequency_expr().subs(_OMEGA0, 1)
        rows = []
        worst = 0.0
        for epsilon in ("1e-2", "1e-3", "1e-4"):
            exact = piecewise_linear_exact_frequency(epsilon, a=1, b=b_value, a0=1, omega0=1, dps=DECIMAL_DIGITS)
            value = approximation.subs(EPSILON, sympy.Rational(epsilon))
            approximate = mpmath.mpf(str(sympy.N(value, DECIMAL_DIGITS)))
            difference = exact - approximate
            rows.append({"epsilon": epsilon, "exact": _mp(exact, 20), "expansion": _mp(approximate, 20), "difference": _mp(difference, 6)})
            worst = max(worst, abs(float(difference)))
        table[label] = rows
        lines = [rf"\varepsilon = 10^{{{int(row['epsilon'][2:])}}}:\ \omega_{{\mathrm{{exact}}}} - \omega_{{\le {order}}} &= {_sci(float(row['difference']), 3)}" for row in rows]
        content.body.append(r"Against the exact frequency ($\omega_0 = 1$, exact period of the piecewise-linear oscillator):" + "\n" + _align(lines))
        if b_value == 1:  # the exact solution is a0 cos(omega0 t): the expansion must be exact
            reference = "the exact frequency (closed-form period) at epsilon = 1e-2, 1e-3, 1e-4"
            content.checks.append(
                _Check(label, "omega(epsilon)", reference, "numeric", worst, GRAZING_EXACT_TOLERANCE, r"$b = a_{0}$",
                       r"$\omega(\varepsilon)$", r"the exact frequency (closed-form period) at $\varepsilon = 10^{-2}, 10^{-3}, 10^{-4}$")
            )
    content.extra["exact_comparison"] = {
        "omega0": "1",
        "note": "exact frequency (closed-form period) minus the truncated expansion; b = -a0 shows the non-analytic remainder",
        "rows": table,
    }
    return content


# --------------------------------------------------------------------------- #
# builders: N degrees of freedom
# --------------------------------------------------------------------------- #
def _system_latex(system: Any, springs_text: str) -> str:
    size = system.n_dof
    return (
        r"$M \ddot X + K X + \varepsilon A^{T} (A X - b)_{+} = 0$ with $M = I_{" + str(size) + r"}$ and" + "\n"
        + _align([
            rf"K &= {sympy.latex(sympy.Matrix(system.K_exact))}",
            rf"A &= {sympy.latex(sympy.Matrix(system.A_exact))},\quad b = {sympy.latex(sympy.Matrix(system.b_exact).T)}^{{T}}",
        ])
        + "\n" + springs_text
    )


def _mode_shape_latex(column: Sequence[float]) -> str:
    return r"\left(" + ",\\ ".join(f"{value:.6g}" if abs(value) > 1e-14 else "0" for value in column) + r"\right)^{T}"


def _nnm_modes(content: _Content, system: Any, order: int, a0: int, label_prefix: str = "") -> None:
    from ._all_modes import all_modes_first_order
    from ._nnm_expansion import nnm

    shapes = system.modes().shapes
    lambdas = system.modes().frequencies
    content.body.append(
        "Linear frequencies: " + ", ".join(rf"$\lambda_{{{k + 1}}} = {value:.12g}$" for k, value in enumerate(lambdas))
        + r". Each NNM is sought with one strained time $s = \omega t$, $\omega = \sum_n \omega_n \varepsilon^n$, "
        r"$\omega_0 = \lambda_j$, released from rest at $u_j(0) = a_{0}$, $u_k(0) = \varepsilon a_k$ ($k \ne j$, modal "
        r"coordinates $X = \Phi U$, $\Phi^{T} M \Phi = I$); the $a_k$ are outputs that make every correction periodic."
    )
    for mode in range(1, system.n_dof + 1):
        result = nnm(system, mode, sympy.Integer(a0), order, precision=NNM_PRECISION)
        label = f"{label_prefix}mode {mode}"
        data = result.to_dict()
        lines = [rf"\omega_{{0}} &= \lambda_{{{mode}}} = {_mp(result.omega[0])}"]
        lines += [rf"\omega_{{{n}}} &= {_mp(value)}" for n, value in enumerate(result.omega) if n]
        lines += [rf"a_{{{k + 1}}} &= {_mp(value)}" for k, value in enumerate(result.release_modal) if k != mode - 1]
        roots = ", ".join(result.spring_roots)
        content.body.append(
            rf"\paragraph{{Mode {mode}.}}" + "\n" + _align(lines) + "\n"
            + rf"First terms: $X(t) = a_{{0}} \varphi_{{{mode}}} \cos(\omega t) + O(\varepsilon)$ with $a_0 = {a0}$, "
            + rf"$\varphi_{{{mode}}} = {_mode_shape_latex(shapes[:, mode - 1])}$. "
            + rf"Spring roots of $v_0$: {roots}; valid for ${_validity_latex(result.validity_exponent)}$."
        )
        content.omega[label] = list(data["omega_digits"])
        content.omega_float[label] = list(data["omega"])
        content.variants.append({"label": label, "mode_shape": [float(v) for v in shapes[:, mode - 1]],
                                 "validity": _validity_json(result.validity_exponent), "nnm": data})
        if order >= 1:
            amplitudes = np.zeros(system.n_dof)
            amplitudes[mode - 1] = 1.0
            first_order = all_modes_first_order(system, amplitudes)
            value, _ = first_order.corrections[mode - 1]
            method = first_order.methods[mode - 1]
            reference = f"Theorem 4.3 with only mode {mode} excited, {method}"
            content.checks.append(
                _Check(label, "omega_1", reference, "numeric", abs(float(result.omega[1]) - value),
                       NNM_CROSS_CHECK_TOLERANCE[method], f"Mode {mode}", r"$\omega_{1}$", reference)
            )


def _nnm_extra(content: _Content, system: Any, a0: int, springs: Sequence[Mapping[str, Any]]) -> None:
    content.extra["system"] = {"definition": system.to_json_dict(), "springs": list(springs), "a0": a0,
                               "lambda": [float(v) for v in system.modes().frequencies]}


def _build_nnm_2dof(order: int) -> _Content:
    from ._system import UnilateralSystem

    system = UnilateralSystem.chain(2, unilateral=[(0, 0)])
    content = _Content(
        title=r"Nonlinear normal modes of a 2-mass chain with a unilateral spring",
        equation="M X'' + K X + epsilon A^T (A X - b)_+ = 0, chain of 2 unit masses, zero-gap spring on mass 1",
    )
    content.body.append(_system_latex(
        system, r"Two unit masses between fixed walls, unit springs; one unilateral spring of stiffness $\varepsilon$ "
                r"on mass 1 with zero gap (it pushes back while $X_1 > 0$). Modal amplitude $a_{0} = 1$ (with a zero gap "
                r"the $\omega_n$ do not depend on it)."))
    _nnm_modes(content, system, order, 1)
    _nnm_extra(content, system, 1, [{"mass": 1, "gap": "0", "engages_while": "X_1 > 0"}])
    return content


def _build_nnm_5dof(order: int) -> _Content:
    from ._system import UnilateralSystem

    system = UnilateralSystem.chain(5, unilateral=[(0, 0), (3, "-1/5")])
    content = _Content(
        title=r"Nonlinear normal modes of a 5-mass chain with two unilateral springs",
        equation="M X'' + K X + epsilon A^T (A X - b)_+ = 0, chain of 5 unit masses, zero-gap spring on mass 1, preloaded spring (b = -1/5) on mass 4",
    )
    content.body.append(_system_latex(
        system, r"The seed's $N$-degree-of-freedom setting, with our choice of springs (the seed does not fix them): "
                r"five unit masses between fixed walls joined by unit springs; unilateral springs of stiffness "
                r"$\varepsilon$ on mass 1 with zero gap (engaged while $X_1 > 0$) and on mass 4 with the gap "
                r"$b = -1/5$ (preloaded: engaged while $X_4 > -1/5$). Modal amplitude $a_{0} = 1$."))
    _nnm_modes(content, system, order, 1)
    _nnm_extra(content, system, 1, [{"mass": 1, "gap": "0", "engages_while": "X_1 > 0"},
                                    {"mass": 4, "gap": "-1/5", "engages_while": "X_4 > -1/5"}])
    return content


def _build_all_modes(order: int) -> _Content:
    from ._all_modes import all_modes_first_order
    from ._nnm_expansion import nnm
    from ._system import UnilateralSystem

    amplitudes = [1.0, 0.5, 0.25]
    content = _Content(
        title=r"All modes excited: first-order corrections (Theorem 4.3), 3-mass chain",
        equation="M X'' + K X + epsilon A^T (A X - b)_+ = 0, chain of 3 unit masses, u_k(0) = a_k for every mode",
    )
    content.body.append(
        r"Every mode is released at once, $u_k(0) = a_k$ with $(a_1, a_2, a_3) = (1, \tfrac12, \tfrac14)$, velocities zero, "
        r"and each mode is strained separately: $u_k(t) \approx a_k \cos(\lambda_k^{\varepsilon} t)$, "
        r"$\lambda_k^{\varepsilon} = \lambda_k + \varepsilon \lambda_k^{1}$, with "
        r"$\lambda_k^{1} = c_k/(2\lambda_k a_k)$ and $c_k$ the $\cos(\lambda_k t)$ component of the almost-periodic forcing. "
        r"First terms: $X(t) \approx \Phi\, (a_k \cos(\lambda_k^{\varepsilon} t))_k$. "
        r"Validity: $t = o(\varepsilon^{-1})$ (weaker than for a single NNM)."
    )
    settings = (
        ("zero gaps", [(0, 0)], r"One zero-gap spring on mass 1: closed form $\lambda_k^{1} = G_{k1} B_{1k}/(4\lambda_k)$ "
                                r"($B = A\Phi$, $G = \Phi^{T} A^{T}$), independent of the amplitudes."),
        ("with a gap", [(0, 0), (2, "1/10")], r"Add a spring with gap $1/10$ on mass 3: Hann-windowed almost-periodic "
                                              r"averages, with error estimates."),
    )
    for name, springs, text in settings:
        system = UnilateralSystem.chain(3, unilateral=springs)
        result = all_modes_first_order(system, amplitudes)
        lines = []
        for k, (lam, (value, error), method) in enumerate(zip(result.lambdas, result.corrections, result.methods)):
            estimate = rf"\ (\pm {_sci(error)})" if error else ""
            lines.append(rf"\lambda_{{{k + 1}}} = {lam:.12g},\quad \lambda_{{{k + 1}}}^{{1}} &= {value:.12g}{estimate}")
            label = f"{name}, mode {k + 1}"
            content.omega[label] = [repr(lam), repr(value)]
            content.omega_float[label] = [lam, value]
        content.body.append(rf"\paragraph{{{name.capitalize()}.}} " + text + "\n" + _system_latex(system, "") + "\n" + _align(lines))
        content.variants.append({
            "label": name,
            "system": system.to_json_dict(),
            "amplitudes": amplitudes,
            "lambda": list(result.lambdas),
            "corrections": [{"mode": k + 1, "lambda_1": value, "error_estimate": error, "method": method}
                            for k, ((value, error), method) in enumerate(zip(result.corrections, result.methods))],
            "validity": {"exponent": "-1", "time_scale": "t = o(1/epsilon)"},
            "averaging_time": result.averaging_time,
            "message": result.message,
        })
        if name == "zero gaps":
            for k, (value, _) in enumerate(result.corrections):
                single = nnm(system, k + 1, sympy.Integer(1), 1, precision=NNM_PRECISION)
                content.checks.append(
                    _Check(f"{name}, mode {k + 1}", "lambda_1", f"the NNM omega_1 of mode {k + 1} (zero gaps: the same closed form)",
                           "numeric", abs(float(single.omega[1]) - value), NNM_CROSS_CHECK_TOLERANCE["closed form (zero gaps)"],
                           f"{name.capitalize()}, mode {k + 1}", rf"$\lambda_{{{k + 1}}}^{{1}}$",
                           rf"the NNM $\omega_{{1}}$ of mode {k + 1} (zero gaps: the same closed form)")
                )
    return content


# --------------------------------------------------------------------------- #
# registry
# --------------------------------------------------------------------------- #
def _registry() -> Mapping[str, DerivationSpec]:
    from ._hierarchy import MAX_ORDER

    specs = (
        DerivationSpec("duffing", "Duffing u'' + omega0^2 u + eps u^3 = 0: symbolic a0, omega0, both normalisations, exact check",
                       6, MAX_ORDER, _build_duffing),
        DerivationSpec("u_plus", "Unilateral spring a*u_+: symbolic a, a0, omega0, exact check against the period",
                       4, MAX_ORDER, _build_u_plus),
        DerivationSpec("gap", "Gap (u - b)_+ with b > 0: kappa = b/a0 = 1/3 exactly, plus symbolic-kappa closed forms of omega_1, omega_2",
                       3, MAX_ORDER, _build_gap),
        DerivationSpec("prestress", "Preloaded spring (u - b)_+ with b = -1/2 < 0, a0 = omega0 = 1, exact",
                       3, MAX_ORDER, _build_prestress),
        DerivationSpec("negative_release", "Gap (u - 1/3)_+ released on the far side, a0 = -1, exact",
                       3, MAX_ORDER, _build_negative_release),
        DerivationSpec("grazing", "|a0| = |b|: grazing regime, linear approximation, validity eps^(-1/2)",
                       3, MAX_ORDER, _build_grazing),
        DerivationSpec("nnm_2dof", "NNMs of a 2-mass chain with a zero-gap unilateral spring: every mode, omega_0..omega_N, a_k",
                       2, 12, _build_nnm_2dof),
        DerivationSpec("nnm_5dof", "NNMs of a 5-mass chain, springs on mass 1 (gap 0) and mass 4 (preload b = -1/5): every mode",
                       2, 12, _build_nnm_5dof),
        DerivationSpec("all_modes", "Theorem 4.3: first-order corrections with all modes of a 3-mass chain excited",
                       1, 1, _build_all_modes),
    )
    return MappingProxyType({spec.name: spec for spec in specs})


#: Ordered, read-only registry name -> :class:`DerivationSpec`.
DERIVATIONS: Mapping[str, DerivationSpec] = _registry()


def list_derivations() -> list[tuple[str, str]]:
    """(name, one-line description) of every registered derivation, in registry order.

    Examples
    --------
    >>> dict(list_derivations())["grazing"]
    '|a0| = |b|: grazing regime, linear approximation, validity eps^(-1/2)'
    """
    return [(spec.name, spec.description) for spec in DERIVATIONS.values()]


def _spec(name: str) -> DerivationSpec:
    if name not in DERIVATIONS:
        raise ProblemError(f"unknown derivation {name!r}; choose one of {', '.join(DERIVATIONS)} (see `lindstedt derive --list`)")
    return DERIVATIONS[name]


def _validated_order(spec: DerivationSpec, order: Any) -> int:
    if order is None:
        return spec.default_order
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or not 1 <= order <= spec.max_order:
        allowed = "only order 1" if spec.max_order == 1 else f"an integer order between 1 and {spec.max_order}"
        raise OrderError(f"derivation {spec.name!r} takes {allowed}, got {order!r}")
    return int(order)


def _version() -> str:
    from . import __version__

    return __version__


def derive(
    name: str,
    order: int | None = None,
    output_directory: str | Path | None = None,
    formats: Sequence[str] = FORMATS,
) -> DerivationResult:
    """Run the named derivation; write ``<name>.tex`` and/or ``<name>.json`` into ``output_directory``.

    Parameters
    ----------
    name : str
        A key of :data:`DERIVATIONS` (see :func:`list_derivations`).
    order : int, optional
        Expansion order (default: the spec's ``default_order``; 1 ≤ order ≤ ``max_order``).
    output_directory : str or Path, optional
        Created if needed.  ``None`` writes nothing (the result still holds the text).
    formats : sequence of {"latex", "json"}
        Which files to write.

    Returns
    -------
    DerivationResult

    Raises
    ------
    ProblemError
        Unknown name or format.
    OrderError
        Order out of range.

    Examples
    --------
    >>> result = derive("u_plus", order=2)
    >>> result.json["omega"]["a u_+"]
    ['omega0', 'a/(4*omega0)', '-a**2/(8*omega0**3)']
    >>> result.paths, result.json["checks"][0]["agrees"]
    ((), True)
    """
    spec = _spec(name)
    order = _validated_order(spec, order)
    if isinstance(formats, str):
        formats = (formats,)
    unknown = [item for item in formats if item not in FORMATS]
    if unknown:
        raise ProblemError(f"unknown output format(s) {unknown}; choose among {list(FORMATS)}")
    started = time.perf_counter()
    content = spec._builder(order)
    version = _version()
    header = (
        f"% lindstedt derive {name} --order {order}  (lindstedt {version}; regenerate with `python derivations/{name}.py`)\n"
        "% LaTeX fragment: \\input it into a document that loads amsmath.\n"
    )
    pieces = [rf"\subsection*{{{content.title}}}", *content.body]
    checks = _checks_latex(content.checks)
    if checks:
        pieces.append(checks)
    latex = header + "\n\n".join(pieces) + "\n"
    data: dict[str, Any] = {
        "schema": SCHEMA,
        "name": name,
        "description": spec.description,
        "order": order,
        "lindstedt_version": version,
        "equation": content.equation,
        "omega": content.omega,
        "omega_float": content.omega_float,
        "variants": content.variants,
        "checks": [check.to_json() for check in content.checks],
        **content.extra,
    }
    elapsed = time.perf_counter() - started
    paths: list[Path] = []
    if output_directory is not None:
        directory = Path(output_directory)
        directory.mkdir(parents=True, exist_ok=True)
        texts = {"latex": latex, "json": json.dumps(data, indent=2, allow_nan=False) + "\n"}
        for item in dict.fromkeys(formats):
            path = directory / f"{name}{_SUFFIXES[item]}"
            path.write_text(texts[item], encoding="utf-8")
            paths.append(path)
    return DerivationResult(
        name=name, description=spec.description, order=order, latex=latex, json=data, paths=tuple(paths), elapsed=elapsed
    )


def format_derivation(result: DerivationResult, format: str = "text") -> str:
    """Printable form of a result: ``"latex"`` (the fragment), ``"json"`` (indented) or ``"text"`` (summary and paths).

    Examples
    --------
    >>> print(format_derivation(derive("grazing", order=1)))  # doctest: +ELLIPSIS
    grazing (order 1): |a0| = |b|: grazing regime, linear approximation, validity eps^(-1/2)
      b = a0: omega = omega0, 0
      b = -a0: omega = omega0, 1/(2*omega0)
    ...
    """
    if format == "latex":
        return result.latex.rstrip("\n")
    if format == "json":
        return json.dumps(result.json, indent=2, allow_nan=False)
    if format != "text":
        raise ProblemError(f"unknown format {format!r}; choose among {list(_PRINT_FORMATS)}")
    lines = [f"{result.name} (order {result.order}): {result.description}"]
    for label, values in result.json["omega"].items():
        lines.append(f"  {label}: omega = {', '.join(values)}")
    for check in result.json["checks"]:
        verdict = "agrees" if check["agrees"] else "DISAGREES"
        lines.append(f"  check [{check['variant']}] {check['quantity']}: {verdict} (max |difference| {check['max_abs_difference']:.1e})")
    for path in result.paths:
        lines.append(f"  wrote {path}")
    lines.append(f"  derived in {result.elapsed:.2f} s")
    return "\n".join(lines)


def script_main(name: str, argv: Sequence[str] | None = None, *, default_output: str | Path) -> int:
    """Entry point of ``derivations/<name>.py [--order N] [--output DIR]``: derive, write, print the paths.

    Returns the exit status (2 on an input error, with ``error: ...`` on stderr).
    """
    spec = _spec(name)
    parser = argparse.ArgumentParser(prog=f"derivations/{name}.py", description=spec.description)
    parser.add_argument("--order", type=int, default=None, help=f"expansion order (default {spec.default_order}, at most {spec.max_order})")
    parser.add_argument("--output", default=str(default_output), help=f"output directory (default {default_output})")
    arguments = parser.parse_args(argv)
    try:
        result = derive(name, order=arguments.order, output_directory=arguments.output)
    except LindstedtError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    for path in result.paths:
        print(path)
    print(f"{name}: order {result.order}, derived in {result.elapsed:.2f} s", file=sys.stderr)
    return 0
