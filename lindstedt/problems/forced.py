"""Forced, damped oscillators: the problems of the frequency response.

One degree of freedom (:class:`ForcedOscillator`)::

    u'' + 2 ζ ω0 u' + ω0² u + ε f(u) = ε F cos(Ω t)

N degrees of freedom with unilateral springs (:class:`ForcedSystem`)::

    M X'' + C X' + K X + ε W (A X − b)_+ = ε P cos(Ω t)

with Rayleigh damping ``C = α M + β K``, modal damping ``C = M Φ diag(2 ζ_k ω_k) Φᵀ M``
(``Φ`` the mass-normalised modes of ``(K, M)``), or a given symmetric positive semi-definite
``C``.  Like :class:`~lindstedt.UnilateralSystem`, ε and the forcing frequency Ω are not part
of the problem: they are given to the methods (Ω is what a frequency response sweeps).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np
import sympy

from .._errors import ParameterError, ProblemError
from .._precision import locked, locked_methods
from .oscillator import Oscillator, terms_text
from .parsing import parse_real
from .matrices import _exact_matrix, _exact_scalar, _float_array
from .system import UnilateralSystem

__all__ = ["ForcedOscillator", "ForcedSystem", "check_forcing_frequency"]

DAMPING_KINDS = ("rayleigh", "modal", "matrix")
#: the largest float: ω0, ζ and F beyond it are refused (every forced method computes in floats)
_FLOAT_MAX = sympy.Float(sys.float_info.max)


@locked
def check_forcing_frequency(value: Any, name: str = "Omega") -> float:
    """The forcing frequency Ω as a positive finite float, or a :class:`ParameterError` naming the fix.

    Examples
    --------
    >>> check_forcing_frequency("1/2")
    0.5
    """
    if isinstance(value, bool):
        raise ParameterError(f"{name} must be a positive number, got {value!r}")
    try:
        number = float(parse_real(value, what=name)) if isinstance(value, str) else float(value)
    except (TypeError, ValueError) as error:
        raise ParameterError(f"{name} must be a positive number such as 1.05, got {value!r}") from error
    if not math.isfinite(number) or number <= 0:
        raise ParameterError(f"{name} must be a positive finite forcing frequency, got {value!r}; e.g. {name}=1.05")
    return number


def _nonnegative(value: Any, what: str) -> sympy.Expr:
    """An exact number ≥ 0, or a sympy symbol declared nonnegative/positive (kept symbolic)."""
    if isinstance(value, sympy.Symbol):
        if not (value.is_nonnegative or value.is_positive):
            raise ProblemError(f"{what} given as the symbol {value} must be declared nonnegative, e.g. sympy.Symbol({str(value)!r}, nonnegative=True)")
        return value
    exact = _exact_scalar(value, what)
    if exact < 0:
        raise ProblemError(f"{what} must be ≥ 0 (a negative damping feeds energy in), got {exact}; use {what}=0 for no damping")
    return exact


@locked_methods()
@dataclass(frozen=True)
class ForcedOscillator:
    """The forced, damped oscillator ``u'' + 2 ζ ω0 u' + ω0² u + ε f(u) = ε F cos(Ω t)``.

    Parameters
    ----------
    f : str or sympy expression
        The nonlinearity in ``u``, exactly as for :class:`~lindstedt.Oscillator` (read by the
        one safe parser): ``"u**3"``, ``"Max(0, u - b)"``, ``"Max(0, u)**(3/2)"``, ...
    omega0 : number, numeric string or sympy expression, optional
        Linear angular frequency ω0 > 0.  Default: the positive symbol ``omega0``.
    zeta : number, numeric string or nonnegative sympy Symbol, optional
        Damping ratio ζ ≥ 0 (default 0).  The weak-nonlinearity methods treat it as small,
        of the order of ε.
    forcing : number, numeric string or sympy Symbol, optional
        Forcing amplitude F ≠ 0 (default 1); the load is ε F cos(Ω t).
    params : mapping name -> value, optional
        Parameters of f, as for :class:`~lindstedt.Oscillator` (``None`` keeps one symbolic).

    Attributes
    ----------
    oscillator : Oscillator
        The free conservative problem ``u'' + ω0² u + ε f(u) = 0`` with symbolic amplitude
        ``a0``: its expansion is the backbone of the frequency response.

    Raises
    ------
    ProblemError, ParameterError
        With a message naming the fix (ζ < 0, F = 0, an undeclared parameter, ...).

    Examples
    --------
    >>> problem = ForcedOscillator("Max(0, u - b)", omega0=1, zeta="1/100", forcing="1/2", params={"b": "1/5"})
    >>> problem.nonlinearity, problem.zeta, problem.forcing
    (Max(0, u - 1/5), 1/100, 1/2)
    >>> problem.oscillator.a0
    a0
    """

    f: Any
    omega0: Any = None
    zeta: Any = 0
    forcing: Any = 1
    params: Any = None
    oscillator: Oscillator = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        free = Oscillator(self.f, omega0=self.omega0, params=self.params)
        zeta = _nonnegative(self.zeta, "zeta")
        if isinstance(self.forcing, sympy.Symbol):
            forcing: sympy.Expr = self.forcing
        else:
            forcing = _exact_scalar(self.forcing, "forcing")
            if forcing == 0:
                raise ProblemError(
                    "forcing F = 0 leaves a free damped oscillator; give F ≠ 0, or use lindstedt.expand / "
                    "lindstedt.nnm for free vibrations"
                )
        at_rest = free.nonlinearity.subs(free.variable, 0)
        if at_rest.has(sympy.zoo, sympy.oo, -sympy.oo, sympy.nan):
            raise ProblemError(
                f"f = {free.nonlinearity} is not finite at u = 0, where every forced response passes: give f finite "
                "near u = 0 (a pole or a logarithm there is not a restoring force); shift it, e.g. 1/(u - 2)"
            )
        for name, value in (("omega0", free.omega0), ("zeta", zeta), ("forcing", forcing)):
            if not value.free_symbols and abs(value) > _FLOAT_MAX:
                raise ParameterError(
                    f"{name} = {sympy.N(value, 3)} is beyond the range of floating point (|x| < 1.8e308) that the "
                    f"numerical flows and the steady amplitudes are computed in; rescale the problem (time or amplitude)"
                )
        set_field(self, "oscillator", free)
        set_field(self, "f", free.f)
        set_field(self, "omega0", free.omega0)
        set_field(self, "params", free.params)
        set_field(self, "zeta", zeta)
        set_field(self, "forcing", forcing)

    # views shared with Oscillator -------------------------------------------------------
    @property
    def nonlinearity(self) -> sympy.Expr:
        """f(u) with the numeric parameter values substituted (symbolic ones kept)."""
        return self.oscillator.nonlinearity

    @property
    def parameter_values(self) -> dict[sympy.Symbol, sympy.Expr]:
        """Declared parameters and their values (a symbol stands for itself)."""
        return self.oscillator.parameter_values

    @property
    def symbolic_parameters(self) -> tuple[sympy.Symbol, ...]:
        """Parameters without a numeric value."""
        return self.oscillator.symbolic_parameters

    @property
    def is_numeric(self) -> bool:
        """True when ω0, ζ, F and every parameter of f are numbers (what the exact numerics need)."""
        return not (self.nonlinearity.free_symbols - {self.oscillator.variable}) and all(
            not value.free_symbols for value in (self.omega0, self.zeta, self.forcing)
        )

    def numeric_coefficients(self) -> tuple[float, float, float]:
        """(ω0, ζ, F) as floats, or a :class:`ParameterError` naming the symbol that needs a value.

        Examples
        --------
        >>> ForcedOscillator("u**3", omega0=2, zeta="1/20", forcing=3).numeric_coefficients()
        (2.0, 0.05, 3.0)
        """
        names = sorted(str(symbol) for symbol in self.nonlinearity.free_symbols - {self.oscillator.variable})
        for name, value in (("omega0", self.omega0), ("zeta", self.zeta), ("forcing", self.forcing)):
            if value.free_symbols:
                names.append(name)
        if names:
            raise ParameterError(
                f"{', '.join(names)} must have numeric values for a numerical method; "
                f"give them when building the problem (e.g. params={{'b': '1/5'}}, omega0=1)"
            )
        return float(self.omega0), float(self.zeta), float(self.forcing)

    def describe(self) -> str:
        """One line: the equation.

        Examples
        --------
        >>> ForcedOscillator("u**3", omega0=1, zeta="1/100").describe()
        "u'' + u'/50 + u + eps*(u**3) = eps*cos(Omega*t)"
        """
        u, velocity, acceleration, eps, omega, t = sympy.symbols("u u' u'' eps Omega t")
        left = terms_text(acceleration, 2 * self.zeta * self.omega0 * velocity, self.omega0**2 * u)
        return f"{left} + eps*({self.nonlinearity}) = {terms_text(eps * self.forcing * sympy.cos(omega * t))}"


def _symmetric_positive_semidefinite(C: np.ndarray, C_exact: sympy.ImmutableMatrix) -> None:
    if C_exact != C_exact.T:
        raise ProblemError("the damping matrix C must be symmetric; give C = Cᵀ (or rayleigh=(alpha, beta))")
    eigenvalues = np.linalg.eigvalsh(C)
    scale = max(1.0, float(np.max(np.abs(eigenvalues))) if eigenvalues.size else 1.0)
    if eigenvalues.size and eigenvalues[0] < -1e-12 * scale:
        raise ProblemError(
            f"the damping matrix C has a negative eigenvalue ({eigenvalues[0]:.3g}): it feeds energy in; "
            "give a positive semi-definite C"
        )


@locked_methods()
class ForcedSystem:
    """``M X'' + C X' + K X + ε W (A X − b)_+ = ε P cos(Ω t)``: a unilateral system, damped and forced.

    Parameters
    ----------
    system : UnilateralSystem
        ``M``, ``K``, ``A``, ``b``, ``W``.
    load : array_like, shape (N,)
        The forcing shape ``P`` (exact entries, as for the system's matrices); not all zero.
    rayleigh : (alpha, beta), optional
        Rayleigh damping ``C = α M + β K`` with α, β ≥ 0.
    modal_damping : sequence of N ratios, optional
        Modal damping: mode k of ``(K, M)`` gets the damping ratio ζ_k ≥ 0,
        ``C = M Φ diag(2 ζ_k ω_k) Φᵀ M`` (float; exact only through the modes' rounding).
    C : array_like, shape (N, N), optional
        A damping matrix, symmetric positive semi-definite.

    Exactly one of ``rayleigh``, ``modal_damping``, ``C`` may be given; none means no damping.

    Attributes
    ----------
    C : numpy.ndarray
        The damping matrix (float, read-only).
    P : numpy.ndarray
        The load (float, read-only); ``P_exact`` is exact.
    damping : tuple
        ``("rayleigh", (α, β))``, ``("modal", (ζ_1, …))`` or ``("matrix", None)``.

    Examples
    --------
    >>> system = UnilateralSystem.chain(2, [(1, "1/10")])
    >>> forced = ForcedSystem(system, load=[1, 0], rayleigh=(0, "1/100"))
    >>> forced.C.tolist()
    [[0.02, -0.01], [-0.01, 0.02]]
    >>> ForcedSystem.one_dof(1, zeta="1/20", forcing=2).C.tolist(), ForcedSystem.one_dof(1, zeta="1/20", forcing=2).P.tolist()
    ([[0.1]], [2.0])
    """

    def __init__(
        self,
        system: UnilateralSystem,
        load: Any,
        *,
        rayleigh: Any = None,
        modal_damping: Any = None,
        C: Any = None,
    ) -> None:
        if not isinstance(system, UnilateralSystem):
            raise ProblemError(f"system must be a lindstedt.UnilateralSystem, got {type(system).__name__}")
        n = system.n_dof
        P_exact = _exact_matrix(load, "load", ndim=1)
        if P_exact.rows != n:
            raise ProblemError(f"load must have one entry per degree of freedom ({n}), got {P_exact.rows}")
        if all(entry == 0 for entry in P_exact):
            raise ProblemError("load P is zero: nothing forces the system; give a nonzero load, or use lindstedt.nnm for free vibrations")
        given = [name for name, value in (("rayleigh", rayleigh), ("modal_damping", modal_damping), ("C", C)) if value is not None]
        if len(given) > 1:
            raise ProblemError(f"give one damping model, not {' and '.join(given)}")
        for name, value in (("rayleigh", rayleigh), ("modal_damping", modal_damping)):
            if value is not None and (isinstance(value, (str, bytes, Mapping)) or not hasattr(value, "__len__")):
                example = "rayleigh=(alpha, beta)" if name == "rayleigh" else "modal_damping=[zeta_1, …, zeta_N]"
                raise ProblemError(f"{name} must be a sequence, e.g. {example}, got {value!r}")
        if rayleigh is not None:
            if len(rayleigh) != 2:
                raise ProblemError("rayleigh must be a pair (alpha, beta), C = alpha*M + beta*K")
            alpha, beta = (_nonnegative(value, name) for value, name in zip(rayleigh, ("alpha", "beta")))
            C_exact = sympy.ImmutableMatrix(alpha * system.M_exact + beta * system.K_exact)
            C_float = _float_array(C_exact)
            damping: tuple[str, Any] = ("rayleigh", (alpha, beta))
        elif modal_damping is not None:
            ratios = [_nonnegative(value, f"modal_damping[{k}]") for k, value in enumerate(modal_damping)]
            if len(ratios) != n:
                raise ProblemError(f"modal_damping needs one ratio per mode ({n}), got {len(ratios)}")
            frequencies, shapes = system.modes()
            weights = np.diag([2.0 * float(ratio) * float(omega) for ratio, omega in zip(ratios, frequencies)])
            MPhi = system.M @ shapes
            C_float = MPhi @ weights @ MPhi.T
            C_float = (C_float + C_float.T) / 2
            C_float.setflags(write=False)
            C_exact = None
            damping = ("modal", tuple(ratios))
        elif C is not None:
            C_exact = _exact_matrix(C, "C", ndim=2)
            if C_exact.shape != (n, n):
                raise ProblemError(f"C must have the shape of M, ({n}, {n}), got {C_exact.shape}")
            C_float = _float_array(C_exact)
            _symmetric_positive_semidefinite(C_float, C_exact)
            damping = ("matrix", None)
        else:
            C_exact = sympy.ImmutableMatrix.zeros(n, n)
            C_float = _float_array(C_exact)
            damping = ("rayleigh", (sympy.S.Zero, sympy.S.Zero))
        self.system = system
        self.P_exact = P_exact
        self.P = _float_array(P_exact, vector=True)
        self.C_exact = C_exact
        self.C = C_float
        self.damping = damping

    @classmethod
    def one_dof(cls, omega0: Any, *, zeta: Any = 0, forcing: Any = 1, a: Any = 1, b: Any = 0) -> "ForcedSystem":
        """``u'' + 2 ζ ω0 u' + ω0² u + ε (a u − b)_+ = ε F cos(Ω t)`` as a system (M = [[1]], C = [[2 ζ ω0]]).

        Examples
        --------
        >>> ForcedSystem.one_dof(2, zeta="1/10").C_exact
        Matrix([[2/5]])
        """
        system = UnilateralSystem.one_dof(omega0, a=a, b=b)
        zeta_exact = _nonnegative(zeta, "zeta")
        return cls(system, [forcing], C=[[2 * zeta_exact * _exact_scalar(omega0, "omega0")]])

    @property
    def n_dof(self) -> int:
        """Number of degrees of freedom N."""
        return self.system.n_dof

    def __repr__(self) -> str:
        kind, values = self.damping
        damping = f"{kind}={tuple(str(v) for v in values)}" if values is not None else "C=matrix"
        return f"ForcedSystem(N={self.n_dof}, springs={self.system.n_springs}, {damping}, P={[str(p) for p in self.P_exact]})"

    def to_json_dict(self) -> dict[str, Any]:
        """The system, the load and the damping, with exact entries as strings."""
        data: dict[str, Any] = {"system": self.system.to_json_dict(), "load": [str(p) for p in self.P_exact]}
        kind, values = self.damping
        if kind == "matrix":
            data["C"] = [[str(self.C_exact[i, j]) for j in range(self.n_dof)] for i in range(self.n_dof)]
        else:
            data[kind if kind == "rayleigh" else "modal_damping"] = [str(v) for v in values]
        return data

    @classmethod
    def from_json_dict(cls, data: Mapping[str, Any]) -> "ForcedSystem":
        """Inverse of :meth:`to_json_dict` (keys ``system``, ``load`` and one of ``rayleigh``, ``modal_damping``, ``C``)."""
        if not isinstance(data, Mapping) or "system" not in data or "load" not in data:
            raise ProblemError("a forced system needs the keys 'system' (M, K, A, b) and 'load' (P)")
        unknown = set(data) - {"system", "load", "rayleigh", "modal_damping", "C"}
        if unknown:
            raise ProblemError(f"unknown key(s) {sorted(unknown)}; allowed: system, load, rayleigh, modal_damping, C")
        return cls(
            UnilateralSystem.from_json_dict(data["system"]),
            data["load"],
            rayleigh=data.get("rayleigh"),
            modal_damping=data.get("modal_damping"),
            C=data.get("C"),
        )
