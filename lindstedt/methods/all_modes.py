"""All modes excited, first order (seed Theorem 4.3):  M X'' + K X + ε W (A X − b)_+ = 0.

In modal coordinates ``U'' + Λ² U + ε G (B U − b)_+ = 0`` (``G = Φᵀ W``,
``B = A Φ``), released from rest at ``u_k(0) = a_k`` for every k, each mode is
strained separately, ``u_k ≈ a_k cos(λ_k^ε t)``, ``λ_k^ε = λ_k + ε λ_k¹``.
Balancing the ``cos(λ_k t)`` component of the almost-periodic forcing
``F_k(t) = Σ_i G_ki (S_i(t) − b_i)_+``, ``S_i(t) = Σ_l B_il a_l cos(λ_l t)``:

    λ_k¹ = c_k / (2 λ_k a_k),    c_k = lim_{T→∞} (2/T) ∫_0^T F_k(t) cos(λ_k t) dt.

For a spring with zero gap, ``x_+ = x/2 + |x|/2`` and — when the λ's are
ℤ-independent — |S_i| has no component at λ_k (seed Lemma 6.3), so its
contribution is exactly ``G_ki B_ik / (4 λ_k)`` (seed: a_kk/(4λ_k)).  Springs
with a gap are averaged numerically with a Hann window over [0, T] and
[0, 2T]; the difference is the error estimate.  The expansion holds on
t = o(1/ε) (weaker than the NNM's O(1/ε)).

*Polarisation*: if only mode j is excited the corrections of the others vanish
and u_k = O(ε), k ≠ j, on [0, 1/ε]: that case is the NNM of mode j
(:func:`lindstedt.nnm`), reported in the result.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from .._errors import ProblemError
from .._precision import locked, locked_methods
from ..render.json import JsonExport
from ..problems.system import UnilateralSystem

__all__ = ["AllModesFirstOrder", "all_modes_first_order"]


@locked_methods()
@dataclass(frozen=True)
class AllModesFirstOrder(JsonExport):
    """First-order frequency corrections λ_k¹ when all modes are excited.

    Attributes
    ----------
    lambdas : tuple of float
        λ_1 ≤ … ≤ λ_N.
    amplitudes : tuple of float
        Modal release amplitudes a_k.
    corrections : tuple of (float, float)
        (λ_k¹, error estimate); NaN-free: unexcited modes (a_k = 0) get the
        correction of an infinitesimal amplitude only for zero-gap springs,
        else they are reported as 0 with method "not excited".
    methods : tuple of str
        How each λ_k¹ was obtained: "closed form (zero gaps)", "almost-periodic average", "not excited".
    polarised_mode : int or None
        1-based j when only mode j is excited (then use :func:`lindstedt.nnm`).
    success : bool
    message : str
    averaging_time : float
    samples : int
        Cost counter: forcing samples used by the averages.
    system : UnilateralSystem
        The system (exported exactly, as :meth:`UnilateralSystem.to_json_dict`).

    JSON schema ``lindstedt.all-modes-first-order/1`` (:meth:`to_json`).
    """

    SCHEMA = "lindstedt.all-modes-first-order/1"

    lambdas: tuple[float, ...]
    amplitudes: tuple[float, ...]
    corrections: tuple[tuple[float, float], ...]
    methods: tuple[str, ...]
    polarised_mode: int | None
    success: bool
    message: str
    averaging_time: float
    samples: int
    system: UnilateralSystem | None = field(default=None, repr=False, compare=False)

    def frequency(self, epsilon: float) -> np.ndarray:
        """λ_k^ε = λ_k + ε λ_k¹ for every mode."""
        return np.array(self.lambdas) + epsilon * np.array([value for value, _ in self.corrections])

    def _display_rows(self) -> list[tuple[str, str, str, str, str]]:
        from ..render.display import format_number

        return [(str(k + 1), format_number(lam), format_number(amplitude), f"{format_number(value)} ± {format_number(error, 2)}", method)
                for k, (lam, amplitude, (value, error), method) in enumerate(zip(self.lambdas, self.amplitudes, self.corrections, self.methods))]

    def __repr__(self) -> str:
        """One labelled line per mode: λ_k, a_k, the correction λ_k¹ ± its error estimate and how it was obtained.

        Examples
        --------
        >>> import lindstedt
        >>> result = lindstedt.all_modes_first_order(lindstedt.UnilateralSystem.one_dof(1), [1.0])
        >>> print(repr(result).splitlines()[1])
          mode 1: lambda=1, a=1, correction=0.25 ± 0, closed form (zero gaps)
        """
        from ..render.display import shorten

        head = f"AllModesFirstOrder(success={self.success}, polarised_mode={self.polarised_mode}, message={shorten(self.message, 120)!r},"
        lines = [f"  mode {k}: lambda={lam}, a={a}, correction={c}, {m}" for k, lam, a, c, m in self._display_rows()]
        return "\n".join([head, *lines, f"  averaging_time={self.averaging_time:g}, samples={self.samples})"])

    def _repr_html_(self) -> str:
        """Jupyter's rendering: one row per mode."""
        from ..render.display import html_grid

        return html_grid("AllModesFirstOrder", ["mode", "λ_k", "a_k", "λ_k¹ ± error", "method"], self._display_rows(), note=self.message)


def _hann_average(times: np.ndarray, values: np.ndarray) -> float:
    window = np.sin(np.pi * times / times[-1]) ** 2
    return float(np.trapezoid(values * window, times) / np.trapezoid(window, times))


@locked
def all_modes_first_order(
    system: UnilateralSystem,
    amplitudes: Sequence[float],
    *,
    averaging_periods: int = 400,
    points_per_period: int = 256,
) -> AllModesFirstOrder:
    """λ_k¹ for the release u_k(0) = a_k (all k), velocities zero.

    Examples
    --------
    >>> from lindstedt.problems.system import UnilateralSystem
    >>> system = UnilateralSystem.chain(2, unilateral=[(0, 0)])
    >>> result = all_modes_first_order(system, [1.0, 0.5])
    >>> [round(value, 12) for value, _ in result.corrections]
    [0.125, 0.072168783649]
    """
    system.require_unilateral("the first-order frequency shifts of every mode (all_modes_first_order)")
    modes = system.modes()
    lambdas = np.asarray(modes.frequencies, dtype=float)
    size = system.n_dof
    amplitude_array = np.asarray(amplitudes, dtype=float)
    if amplitude_array.shape != (size,):
        raise ProblemError(f"give one modal amplitude per mode: expected {size}, got shape {amplitude_array.shape}")
    if not np.all(np.isfinite(amplitude_array)) or not np.any(amplitude_array):
        raise ProblemError("the modal amplitudes must be finite and not all zero")
    coupling = np.asarray(system.A, dtype=float) @ modes.shapes  # B
    forcing = modes.shapes.T @ np.asarray(system.W, dtype=float)  # G
    gaps = np.asarray(system.b, dtype=float).reshape(-1)
    excited = np.flatnonzero(amplitude_array)
    polarised = int(excited[0]) + 1 if excited.size == 1 else None
    period = 2 * np.pi / lambdas.min()
    total_time = averaging_periods * period
    sample_count = int(averaging_periods * points_per_period * lambdas.max() / lambdas.min()) + 1
    long_times = np.linspace(0.0, total_time, 2 * sample_count - 1)
    short_times = long_times[:sample_count]
    signals = coupling @ (amplitude_array[:, None] * np.cos(np.outer(lambdas, long_times)))  # S_i(t)
    gapped = [i for i in range(len(gaps)) if gaps[i] != 0]
    corrections, methods = [], []
    for k in range(size):
        if amplitude_array[k] == 0:
            corrections.append((0.0, 0.0))
            methods.append("not excited")
            continue
        closed = sum(forcing[k, i] * coupling[i, k] / (4 * lambdas[k]) for i in range(len(gaps)) if gaps[i] == 0)
        value, error = closed, 0.0
        if gapped:
            force = sum(forcing[k, i] * np.maximum(signals[i] - gaps[i], 0.0) for i in gapped)
            weighted = force * np.cos(lambdas[k] * long_times)
            long_average = _hann_average(long_times, weighted)
            short_average = _hann_average(short_times, weighted[:sample_count])
            coarse_average = _hann_average(long_times[::2], weighted[::2])  # sampling error (kinks of x_+)
            value += 2 * long_average / (2 * lambdas[k] * amplitude_array[k])
            error = (abs(long_average - short_average) + abs(long_average - coarse_average)) / (lambdas[k] * abs(amplitude_array[k]))
            methods.append("almost-periodic average")
        else:
            methods.append("closed form (zero gaps)")
        corrections.append((float(value), float(error)))
    message = "converged"
    if polarised is not None:
        message = f"only mode {polarised} is excited: polarisation, u_k = O(eps) for k != {polarised}; see lindstedt.nnm"
    return AllModesFirstOrder(
        lambdas=tuple(float(v) for v in lambdas),
        amplitudes=tuple(float(v) for v in amplitude_array),
        corrections=tuple(corrections),
        methods=tuple(methods),
        polarised_mode=polarised,
        success=True,
        message=message,
        averaging_time=float(total_time),
        samples=int(long_times.size) if gapped else 0,
        system=system,
    )
