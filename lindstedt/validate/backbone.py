"""The backbone ω(a0) of ``u'' + ω0² u + ε f(u) = 0`` on an amplitude grid: the series against the exact frequency.

At each release amplitude a0 (``u(0) = a0``, ``u'(0) = 0``) the Lindstedt–Poincaré series is derived exactly
and truncated at every order n = 1 … N,

    ω_n(a0; ε) = Σ_{k ≤ n} ω_k(a0) ε^k,

and the exact frequency ``2π/T`` comes from the energy-integral quadrature of the period
(:func:`lindstedt.references.conservative_frequency`, with its own error estimate).  The amplitudes are
independent tasks: :func:`backbone` runs them serially or on any ``concurrent.futures``-style executor
(a process pool, a Dask cluster), with an optional progress bar.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field
from functools import partial
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from .._errors import ProblemError
from .._sweep import sweep_map
from ..render.json import JsonExport
from ..problems.oscillator import Oscillator

__all__ = ["Backbone", "backbone"]


@dataclass(frozen=True, repr=False)
class Backbone(JsonExport):
    """ω(a0) at one ε: truncated series of every order and the exact frequency.

    Attributes
    ----------
    success : bool
        Every expansion and every reference succeeded.
    message : str
        What happened (the amplitudes that failed, and why).
    epsilon : float
    amplitudes : numpy.ndarray, shape (A,)
        Release amplitudes a0.
    orders : tuple of int
        1 … N.
    series_frequencies : numpy.ndarray, shape (N, A)
        Row n − 1: ω truncated after ε^n (NaN where the expansion failed).
    exact_frequencies, exact_error_estimates : numpy.ndarray, shape (A,)
        The quadrature reference and its own error estimate (NaN without a reference).
    n_expansions, n_references : int
        Cost counters.
    seconds : float
        Wall time of the sweep.
    problem : Oscillator
        The problem at the first amplitude (its f, ω0 and parameters are shared by all).

    JSON schema ``lindstedt.backbone/1``.
    """

    SCHEMA = "lindstedt.backbone/1"

    success: bool
    message: str
    epsilon: float
    amplitudes: np.ndarray
    orders: tuple[int, ...]
    series_frequencies: np.ndarray
    exact_frequencies: np.ndarray
    exact_error_estimates: np.ndarray
    n_expansions: int
    n_references: int
    seconds: float
    problem: Oscillator | None = field(default=None, repr=False, compare=False)

    @property
    def errors(self) -> np.ndarray:
        """``|ω_n(a0) − ω_exact(a0)|``, shape (N, A)."""
        return np.abs(self.series_frequencies - self.exact_frequencies[None, :])

    def to_dataframe(self) -> Any:
        """One row per amplitude: ``a0``, ``omega_order_1`` … ``omega_order_N``, ``omega_exact``, ``error_estimate``.

        Examples
        --------
        >>> table = backbone("u**3", [0.5, 1.0], 0.1, order=2).to_dataframe()
        >>> list(table.columns)
        ['a0', 'omega_order_1', 'omega_order_2', 'omega_exact', 'error_estimate']
        """
        from ..export.tables import dataframe

        rows = []
        for j, a0 in enumerate(self.amplitudes):
            row: dict[str, Any] = {"a0": float(a0)}
            row.update({f"omega_order_{n}": float(self.series_frequencies[i, j]) for i, n in enumerate(self.orders)})
            row["omega_exact"] = float(self.exact_frequencies[j])
            row["error_estimate"] = float(self.exact_error_estimates[j])
            rows.append(row)
        return dataframe(rows)


def _amplitude_task(a0: float, *, f: Any, order: int, omega0: Any, params: Any, epsilon: float, reference: bool,
                    precision: int) -> tuple[list[float] | None, float, float, str, str]:
    """(ω_1 … ω_N truncated at ε, exact ω, its estimate, failure text, validity warning) at one amplitude (picklable).

    Safe on threads: the engine and the quadrature hold :data:`lindstedt._precision.LOCK` where they use mpmath.
    """
    from .._errors import LindstedtError
    from ..methods.lindstedt_poincare import expand
    from ..results.accuracy import ExpansionValidityWarning
    from ..references.quadrature import conservative_frequency

    failure = note = ""
    series: list[float] | None = None
    try:
        expansion = expand(f, order=order, a0=a0, omega0=omega0, params=params)
        with warnings.catch_warnings(record=True) as caught:  # in any gauge (√ε at grazing), with its warnings
            warnings.simplefilter("always", ExpansionValidityWarning)
            series = [float(expansion.frequency(epsilon, order=n)) for n in range(1, order + 1)]
        if caught:
            note = f"a0 = {a0:g}: {caught[-1].message}"
    except LindstedtError as error:
        failure = f"a0 = {a0:g}: expansion: {error}"
    exact = estimate = math.nan
    if reference:
        try:
            expression = Oscillator(f, a0=a0, omega0=omega0, params=params)
            value, error_estimate = conservative_frequency(expression.nonlinearity, epsilon, a0=a0,
                                                           omega0=expression.omega0, precision=precision)
            exact, estimate = float(value), float(error_estimate)
        except LindstedtError as error:
            failure = (failure + "; " if failure else "") + f"a0 = {a0:g}: reference: {error}"
    return series, exact, estimate, failure, note


def backbone(
    f: Any,
    amplitudes: Sequence[float],
    epsilon: float,
    *,
    order: int = 3,
    omega0: Any = 1,
    params: Mapping[str, Any] | None = None,
    reference: bool = True,
    precision: int = 20,
    executor: Any = None,
    progress: bool | Callable[[int, Any, Any], Any] | None = None,
) -> Backbone:
    """ω(a0) at ε on an amplitude grid: the series truncated at orders 1…``order`` and the exact frequency.

    Parameters
    ----------
    f : str or sympy expression
        The nonlinearity, as for :func:`lindstedt.expand` (parameters given values in ``params``).
    amplitudes : sequence of float
        Release amplitudes a0 > 0.
    epsilon : float
        ε ≥ 0.
    order : int
        Highest order N.
    reference : bool
        Also compute the exact frequency (energy-integral quadrature to ``precision`` digits).
    executor : concurrent.futures.Executor, optional
        Runs the amplitudes in parallel on a process pool or ``distributed.Client(...).get_executor()`` of
        processes (on threads they run one at a time: mpmath's precision is process-wide).
    progress : bool or callable, optional
        ``True``: a tqdm bar; a callable ``progress(index, a0, outcome)``.

    Returns
    -------
    Backbone

    Examples
    --------
    >>> curve = backbone("Max(0, u)", [1.0, 2.0], 0.2, order=2)
    >>> curve.success, [round(float(x), 10) for x in curve.exact_frequencies]   # bilinear: 2√(1+ε)/(1+√(1+ε)), any a0
    (True, [1.0455488499, 1.0455488499])
    """
    values = [float(a0) for a0 in amplitudes]
    if not values or any(not math.isfinite(a0) or a0 <= 0 for a0 in values):
        raise ProblemError(f"amplitudes must be positive finite release amplitudes, got {list(amplitudes)!r}")
    if not math.isfinite(float(epsilon)) or float(epsilon) < 0:
        raise ProblemError(f"epsilon must be a finite number ≥ 0, got {epsilon!r}")
    if isinstance(order, bool) or not isinstance(order, int) or order < 1:
        raise ProblemError(f"order must be a positive integer, got {order!r}")
    problem = Oscillator(f, a0=values[0], omega0=omega0, params=params)  # bad f or params fail here, once
    started = time.perf_counter()
    task = partial(_amplitude_task, f=f, order=order, omega0=omega0, params=params, epsilon=float(epsilon),
                   reference=reference, precision=precision)
    outcomes = sweep_map(task, values, executor=executor, progress=progress, description="backbone")
    series = np.full((order, len(values)), math.nan)
    for j, (column, *_) in enumerate(outcomes):
        if column is not None:
            series[:, j] = column
    failures = [outcome[3] for outcome in outcomes if outcome[3]]
    notes = [outcome[4] for outcome in outcomes if outcome[4]]
    return Backbone(
        success=not failures,
        message="; ".join(failures) if failures else f"{len(values)} amplitudes, orders 1…{order}"
        + (f", exact frequency to {precision} digits" if reference else ", no reference")
        + ("; validity warnings: " + "; ".join(notes) if notes else ""),
        epsilon=float(epsilon),
        amplitudes=np.array(values),
        orders=tuple(range(1, order + 1)),
        series_frequencies=series,
        exact_frequencies=np.array([outcome[1] for outcome in outcomes]),
        exact_error_estimates=np.array([outcome[2] for outcome in outcomes]),
        n_expansions=len(values),
        n_references=len(values) if reference else 0,
        seconds=time.perf_counter() - started,
        problem=problem,
    )
