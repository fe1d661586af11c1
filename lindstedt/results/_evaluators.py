"""The float evaluators of an expansion of ``u'' + ω0² u + ε f(u) = 0``: ω(ε) = Σ_k ω_k ε^k and
u(t) ≈ Σ_{k≤N} ε^k v_k(ω t + φ(ε)), with their error estimates and the warnings that judge ε.

These are the bodies of :meth:`lindstedt.Expansion.frequency`, :meth:`~lindstedt.Expansion.displacement`,
:meth:`~lindstedt.Expansion.velocity`, :meth:`~lindstedt.Expansion.frequency_coefficients`, the error estimates
and :meth:`~lindstedt.Expansion.epsilon_range` (documented there).  They read the parameter values through
:mod:`lindstedt.results._values` and the float coefficients through :mod:`lindstedt.results._coefficients`.
ε is judged against the orbit's range (:mod:`lindstedt.results.orbit_range`: an error where no periodic orbit
exists, a warning outside the contact regime or beyond the radius of convergence) and against the series' own
terms: the warnings read ω_{N+1} (ω_{N+2} for the phase drift) only where they could speak, i.e. where a stand-in
as large as :func:`lindstedt.results.accuracy.next_term_bound` would make them speak.

Functions of an :class:`~lindstedt.Expansion`, typed ``Any``: :mod:`lindstedt.results.expansion` imports this
module, never the other way round.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from typing import Any, Callable, Mapping

import numpy as np

from .._errors import LindstedtError, ParameterError, ProblemError
from .._precision import LOCK, locked, warn_caller
from ..problems.parsing import parse_floats
from ._coefficients import (
    WARNING_TOLERANCE,
    float_branches,
    frequency_coefficients,
    omega_values,
    phase_value,
    phase_values,
    scalar_omegas,
    waveform_data,
    waveform_layout,
)
from ._values import UNSET, Point, grid_cell, omega_expr, omega_known, parameter_grid, read, substitution, values_key
from .accuracy import (
    ExpansionValidityWarning,
    branch_bound,
    displacement_error,
    gauge_values,
    next_term_bound,
    phase_warning,
    quiet_radius,
    series_warning,
    series_warning_mask,
)
from .orbit_range import OrbitRange, orbit_range, range_function

__all__ = ["coefficients", "displacement_error_estimate", "epsilon_range", "evaluate", "frequency", "truncation_error_estimate"]

_RANGE_MEMORY = 4096  # parameter points whose OrbitRange an expansion keeps (small objects)


def _horner(points: Any, coefficients: np.ndarray) -> Any:
    """Σ_k c_k x^k by Horner's rule, c_k of shape P broadcast against x (as numpy's polyval for one P)."""
    if coefficients.ndim == 1 and not np.ndim(points):  # plain floats: the same operations, without numpy's overhead
        x, total = float(points), 0.0
        for coefficient in coefficients[::-1].tolist():
            total = total * x + coefficient
        return np.float64(total)
    result = coefficients[-1] + 0 * points
    for coefficient in coefficients[-2::-1]:
        result = result * points + coefficient
    return result


def _gauge_values(expansion: Any, epsilon: Any) -> np.ndarray:
    """The gauge at ε (ε itself, or √ε: then ε must not be negative)."""
    return gauge_values(
        epsilon, expansion._steps, "the orbit stays on its side and the frequency is analytic: use "
        "lindstedt.reference_solution, or expand the problem with f replaced by -f at -epsilon"
    )


# -- the frequency ---------------------------------------------------------------------------------------
@locked
def frequency(expansion: Any, epsilon: Any, values: Mapping[Any, Any] | None, order: int | None) -> Any:
    """:meth:`lindstedt.Expansion.frequency` past its scalar fast path."""
    if type(values) is dict and len(values) == 1 and type(epsilon) is float:
        result = _one_point_frequency(expansion, epsilon, values, order)
        if result is not None:
            return result
    epsilon = parse_floats(epsilon, what="epsilon")
    last = expansion._steps * (expansion.order if order is None else order)
    if len(expansion._floats.symbols) == 1 and not omega_known(expansion, expansion._steps * expansion.order + 1):
        # one parameter: ω_{N+1}, which the warnings read, derived before the first point is compiled (measured
        # 24-120 ms at orders 2-4 of a symbolic gap), so that no later call derives it and recompiles the core
        omega_expr(expansion, expansion._steps * expansion.order + 1)
    point = read(expansion, values)
    if point is None:
        return _frequency_exact(expansion, epsilon, values, last)
    coefficients = omega_values(expansion, last, point)
    points = _gauge_values(expansion, epsilon)
    result = _horner(points, coefficients)
    message = _range_message(expansion, epsilon, point, values) or _series_message(expansion, coefficients, last, points, point)
    if message:
        warn_caller(ExpansionValidityWarning(message))
    if values is None and order is None and not point.arrays and expansion._steps == 1 and not message:
        _set_fast_frequency(expansion, coefficients, last)
    return float(result) if np.ndim(result) == 0 else result


def _one_point_frequency(expansion: Any, epsilon: float, values: dict[Any, Any], order: int | None) -> float | None:
    """ω(ε) at one float ε and one float value of the one free symbol (gauge ε), in one pass of plain floats, where
    no warning can speak: the coefficients from :func:`scalar_omegas` (which also checks the assumptions), ε inside
    the quiet table's bound for the cell of p (no OrbitRange), and the comparisons of :func:`series_warning` made
    here, silent; None otherwise (the general path then decides, warns or raises as before).  Measured on the
    symbolic-κ gap, order 3, each κ new: 84 µs median through the general path (read, _check_point, float_verdict,
    omega_values, _range_message, _series_message: NumPy on one element each), ~20 µs here."""
    state = expansion._floats
    (name, value), = values.items()
    if (type(value) is not float or len(state.names) != 1 or name != state.names[0] or expansion._steps != 1
            or not (math.isfinite(value) and math.isfinite(epsilon))):
        return None
    last = expansion.order if order is None else order
    if type(last) is not int or last < 0:
        return None
    coefficients = scalar_omegas(expansion, value, last, last >= 1)
    if coefficients is None:
        return None
    source = state.range_source
    if source is UNSET:
        return None
    if source is not None:
        table = _quiet_table(expansion)
        if table is None or not abs(epsilon) < table[grid_cell(value)]:
            return None
    if last >= 1:  # series_warning's comparisons at |η| = |ε|, in its order
        size = abs(epsilon)
        powers = [size**k for k in range(last + 2)]
        terms = [abs(coefficient) * power for coefficient, power in zip(coefficients, powers)]
        if last >= 3 and max(terms[last], terms[last + 1]) > max(terms[last - 2], terms[last - 1]):
            return None
        if terms[last + 1] > max(abs(sum([coefficients[k] * powers[k] for k in range(1, last + 1)])), 1e-300):
            return None
    total = 0.0
    for coefficient in coefficients[last::-1]:
        total = total * epsilon + coefficient
    return total


def _frequency_exact(expansion: Any, epsilon: Any, values: Mapping[Any, Any] | None, last: int) -> Any:
    """ω(ε) from the exactly substituted coefficients (values a double cannot hold)."""
    coefficients = frequency_coefficients(expansion, last + 1, values)
    points = _gauge_values(expansion, epsilon)
    result = np.polynomial.polynomial.polyval(points, coefficients[: last + 1])
    message = _range_message(expansion, epsilon, None, values) or series_warning(coefficients, last, points, expansion._floats.gauge)
    if message:
        warn_caller(ExpansionValidityWarning(message))
    return float(result) if np.ndim(result) == 0 else result


def _set_fast_frequency(expansion: Any, coefficients: np.ndarray, last: int) -> None:
    """Enable the scalar fast path of :meth:`~lindstedt.Expansion.frequency` (no free symbols, gauge ε): Horner in
    Python floats for |ε| up to the radius below which no warning can speak (with the next term, or its stand-in
    while ω_{N+1} is not derived: beyond that radius the general path derives it)."""
    known = omega_known(expansion, last + 1)
    current = expansion.__dict__.get("_fast_frequency_known")
    if current is not None and current >= known:
        return
    if known:
        following = float(omega_values(expansion, last + 1, expansion._floats.no_parameters, WARNING_TOLERANCE)[last + 1])
    else:
        following = float(next_term_bound(coefficients))
    radius = quiet_radius([*coefficients, following], last)
    bounds = _range_at(expansion, ())
    if bounds is not None:  # strictly inside the orbit's range and the disc of convergence
        radius = min(radius, bounds.radius, bounds.upper, -bounds.lower) * (1 - 1e-9)
    expansion.__dict__["_fast_frequency"] = (tuple(float(value) for value in coefficients[::-1]), radius)
    expansion.__dict__["_fast_frequency_known"] = known


def coefficients(expansion: Any, values: Mapping[Any, Any] | None, order: int | None) -> np.ndarray:
    """:meth:`lindstedt.Expansion.frequency_coefficients`."""
    last = expansion._steps * (expansion.order if order is None else order)
    if type(values) is dict and len(values) == 1 and type(last) is int and last >= 0 and len(expansion._floats.names) == 1:
        (name, value), = values.items()
        if type(value) is float and name == expansion._floats.names[0] and math.isfinite(value):
            fast = scalar_omegas(expansion, value, last, False)  # the single-point path (see _one_point_frequency)
            if fast is not None:
                return np.array(fast)
    point = read(expansion, values)
    if point is None:
        return frequency_coefficients(expansion, last, values)[: last + 1].copy()
    return omega_values(expansion, last, point).copy()


def truncation_error_estimate(expansion: Any, epsilon: Any, values: Mapping[Any, Any] | None, order: int | None) -> Any:
    """:meth:`lindstedt.Expansion.truncation_error_estimate`."""
    epsilon = parse_floats(epsilon, what="epsilon")
    last = expansion._steps * (expansion.order if order is None else order)
    point = read(expansion, values)
    if point is None:
        coefficient = frequency_coefficients(expansion, last + 1, values)[last + 1]
    else:  # vectorised over parameter arrays too
        coefficient = omega_values(expansion, last + 1, point)[last + 1]
    estimate = np.abs(coefficient * _gauge_values(expansion, epsilon) ** (last + 1))
    message = _range_message(expansion, epsilon, point, values)
    if message:
        warn_caller(ExpansionValidityWarning(message))
    return estimate


# -- the displacement and the velocity ---------------------------------------------------------------
def evaluate(expansion: Any, t: Any, epsilon: Any, values: Mapping[Any, Any] | None, derivative: bool) -> Any:
    """:meth:`lindstedt.Expansion.displacement` (``derivative=False``) and :meth:`~lindstedt.Expansion.velocity`."""
    t, epsilon = parse_floats(t, what="t"), parse_floats(epsilon, what="epsilon")
    steps = expansion._steps
    with LOCK:  # the values read, the float data (compiled on first use) and the warnings: sympy on a slow path
        point = read(expansion, values)
        if point is None or expansion._stretched_pieces:
            return _evaluate_exact(expansion, t, epsilon, values, derivative)
        last = steps * expansion.order
        coefficients = omega_values(expansion, last + 1, point)  # the frequency through ω_{N+1}
        eta = _gauge_values(expansion, epsilon)
        times = np.asarray(t, dtype=float)
        frequency = _horner(eta, coefficients)
        message = _range_message(expansion, epsilon, point, values) or _series_message(
            expansion, coefficients[: last + 1], last, eta, point, coefficients[last + 1])
        if message is None:
            message = _drift_message(expansion, coefficients, last, eta, times, point)
        if message:
            warn_caller(ExpansionValidityWarning(message))
        phase = _horner(eta, phase_values(expansion, point)) if expansion.problem.has_initial_velocity else None
        layout = expansion._floats.layout
        if layout is None:
            layout = waveform_layout(expansion)
        data = waveform_data(expansion, layout, point, float(np.max(np.abs(eta))) if eta.size else 0.0)  # accurate for the largest |η|
    # floats only from here: the waveform over the times runs lock-free (numpy releases the GIL on large arrays)
    strained = times * frequency if phase is None else times * frequency + phase
    scaled = data.scale ** (1 / steps) * eta
    result = data.amplitude * layout.evaluate(data, strained, scaled, derivative)
    if derivative:
        result = result * frequency
    return result if result.ndim else float(result)


def _evaluate_exact(expansion: Any, t: Any, epsilon: Any, values: Mapping[Any, Any] | None, derivative: bool) -> Any:
    """The evaluator on exactly substituted data (values a double cannot hold; stretched contact arcs)."""
    if np.ndim(epsilon):
        raise ProblemError(
            "epsilon must be one number here (exact parameter values or a stretched contact arc); "
            "loop over epsilon, or give the parameter values as floats"
        )
    scale, amplitude, branches = float_branches(expansion, values)
    gauge, frequency, message, drift = _at_epsilon(expansion, float(epsilon), values)
    times = np.asarray(t, dtype=float)
    message = _range_message(expansion, epsilon, None, values) or message
    if message is None:
        message = phase_warning(drift, times)
    if message:
        warn_caller(ExpansionValidityWarning(message))
    strained = times * frequency + phase_value(expansion, gauge, values)
    result = amplitude * branches.evaluate(strained, scale ** (1 / expansion._steps) * gauge, derivative)[..., 0]
    if derivative:
        result = result * frequency
    return result if result.ndim else float(result)


def _at_epsilon(expansion: Any, epsilon: float, values: Mapping[Any, Any] | None) -> tuple[float, float, str | None, float]:
    """Per ε (cached): the gauge η, the frequency ω through ω_{n+1}, the series' warning (or None) and the
    phase drift rate |ω_{n+2} η^{n+2}| (the frequency is used through ω_{n+1})."""

    def compute() -> tuple[float, float, str | None, float]:
        gauge = float(_gauge_values(expansion, epsilon))
        last = expansion._steps * expansion.order
        coefficients = frequency_coefficients(expansion, last + 2, values)
        frequency = float(np.polynomial.polynomial.polyval(gauge, coefficients[: last + 2]))
        message = series_warning(coefficients[: last + 2], last, np.array([gauge]), expansion._floats.gauge)
        return gauge, frequency, message, abs(float(coefficients[last + 2])) * abs(gauge) ** (last + 2)

    # one slot per values: repeated evaluations at one ε hit it, a sweep over ε does not grow the cache
    cache = expansion._floats.cache
    key = ("at", values_key(values))
    cached = cache.get(key)
    if cached is None or cached[0] != epsilon:
        cached = cache[key] = (epsilon, compute())
    return cached[1]


def displacement_error_estimate(expansion: Any, t: Any, epsilon: float, values: Mapping[Any, Any] | None) -> np.ndarray:
    """:meth:`lindstedt.Expansion.displacement_error_estimate`."""
    t, epsilon = parse_floats(t, what="t"), parse_floats(epsilon, what="epsilon", scalar=True)
    steps = expansion._steps
    scale, amplitude, branches = float_branches(expansion, values)
    last = steps * expansion.order
    eta = float(_gauge_values(expansion, float(epsilon)))
    message = _range_message(expansion, epsilon, None, values)
    if message:
        warn_caller(ExpansionValidityWarning(message))
    # The displacement pairs v_0 … v_n with ω through ω_{n+1}: its phase drifts with the next terms, one power of ε
    # of them (two in the gauge ε^{1/2}, whose analytic and non-analytic terms interleave).
    coefficients = frequency_coefficients(expansion, last + 1 + steps, values)
    frequency_error = sum(abs(coefficients[k]) * abs(eta) ** k for k in range(last + 2, last + 2 + steps))
    scaled = abs(scale) ** (1 / steps) * eta  # η̂, the normalised gauge of the waveforms
    neglected = abs(amplitude) * scaled ** (last + 1) * branch_bound(branches.terms[last], branches.shifts[0])
    return displacement_error(amplitude, frequency_error, np.asarray(t, dtype=float), neglected)


# -- what judges ε: the orbit's range and the series' terms ------------------------------------------
def epsilon_range(expansion: Any, values: Mapping[Any, Any] | None) -> OrbitRange | None:
    """:meth:`lindstedt.Expansion.epsilon_range`."""
    point = read(expansion, values)
    if point is not None and point.shape:
        raise ParameterError("epsilon_range takes one parameter point: give scalar values")
    return _range_at(expansion, _range_arguments(expansion, point, values))


def _range_source(expansion: Any) -> Callable[..., tuple[Any, ...]] | None:
    state = expansion._floats
    if state.range_source is UNSET:
        state.range_source = range_function(expansion.problem, state.symbols)
    return state.range_source


def _range_arguments(expansion: Any, point: Point | None, values: Mapping[Any, Any] | None) -> tuple[float, ...]:
    if point is not None:
        return tuple(float(value) for value in point.arrays)
    exact = substitution(expansion, values)
    return tuple(float(exact[symbol]) for symbol in expansion._floats.symbols)


def _range_at(expansion: Any, arguments: tuple[float, ...], source: Any = UNSET) -> OrbitRange | None:
    """The :class:`OrbitRange` at float parameter values (about 1.6 ms each; the last _RANGE_MEMORY points kept, so
    that a repeated sweep over an array of parameter values pays it once); ``source`` is :func:`_range_source`."""
    if source is UNSET:
        source = _range_source(expansion)
    if source is None:
        return None
    memory = expansion._floats.cache.setdefault("ranges", OrderedDict())
    if arguments not in memory:
        memory[arguments] = orbit_range(*source(*arguments), expansion._steps)
        if len(memory) > _RANGE_MEMORY:
            memory.popitem(last=False)
    return memory[arguments]


# The quiet table (one free parameter p).  The OrbitRange at a new p costs about 1 ms (measured: 1.0 ms of the
# 1.1 ms median of .frequency(0.05, values={"kappa": new}) on Max(0, u - kappa), order 3, before the table), a
# hundred times the arithmetic of the evaluation.  So the quiet radius q(p) = min(upper, −lower, radius) — below
# which judge() says nothing — is computed once per expansion on the valid nodes of parameter_grid (127 for a gap
# κ in (−1, 1): 0.13 s), and cell j (nodes j, j + 1), with its neighbourhood W_j = {q_{j−1}, q_j, q_{j+1}, q_{j+2}},
# accepts without an OrbitRange
#     |ε| < min W_j / max(2, ρ_j),   ρ_j = max W_j / min W_j ≤ _QUIET_SPREAD   (else nothing: the exact OrbitRange),
# and every |ε| where q is +inf at all four nodes.  Why this is conservative: a warning missed at p in cell j needs
# q(p) ≤ |ε| < min W_j / max(2, ρ_j), i.e. q falling inside one cell to below its smallest node value by a factor
# larger than 2 and than the whole variation ρ_j seen over the four nodes (three cells) around it.  q is the
# distance in ε to the nearest event of the orbit (a grazing, an escape, a singularity of ω(ε)); where those events
# move continuously with p, q is continuous (a min of continuous functions: kinks where two events cross, no dips),
# and such a factor needs a feature narrower than one cell (Δs = 1/128 in s = p/(1 + |p|)).  Where the set of
# events changes (the regime's end, κ → ±a0 of a gap: q → 0 or ∞; a law whose stiffness changes sign) q varies by
# more than _QUIET_SPREAD over a few cells or is missing (a node outside the regime, no orbit, +inf next to a
# finite q): those cells accept nothing.  So a miss needs an event that appears and disappears again inside one
# cell.  Checked against the exact OrbitRange (no miss; the smallest q / bound 2.02): Max(0, u - kappa) at 20 000
# random p (s uniform; 9 602 accepted by the table) and κ = ±(1 − 2^−k), k = 1 … 40 (q = (1 + κ)/(1 − κ) for κ ≤ 0, where the breakpoint becomes the lower turning
# point; 1/(1 − κ) measured for κ > 0: a kink at κ = 0), alpha*u**3, kappa*Max(0, u - 1/2) and u**3 + kappa*u**2 at
# 3 000 random p each; tests/test_evaluators_quiet.py checks on every run that a warning comes just beyond q at
# 300 random κ and 167 κ next to ±1 and at the cells' edges.  Every other ε or p takes the exact OrbitRange.
_QUIET_SPREAD = 16.0  # largest max/min of q over a cell's four nodes that the table accepts


def _quiet_table(expansion: Any) -> list[float] | None:
    """Per cell of :func:`parameter_grid`: the |ε| below which the expansion needs no warning (0: none known)."""
    cache = expansion._floats.cache
    if "quiet" not in cache:
        cache["quiet"] = _build_quiet(expansion)
    return cache["quiet"]


def _build_quiet(expansion: Any) -> list[float] | None:
    grid = parameter_grid(expansion)
    if grid is None or _range_source(expansion) is None:
        return None
    nodes, valid = grid
    radii = np.full(nodes.shape, np.nan)
    for index in np.flatnonzero(valid):
        try:
            bounds = _range_at(expansion, (float(nodes[index]),))
        except (LindstedtError, ArithmeticError, ValueError):
            continue
        quiet = min(bounds.upper, -bounds.lower, bounds.radius)
        radii[index] = quiet if quiet > 0 else np.nan
    # cell j lies between nodes j and j + 1; its neighbourhood is nodes j - 1 ... j + 2 (NaN beyond the ends)
    padded = np.concatenate([[np.nan], radii, [np.nan]])
    windows = np.lib.stride_tricks.sliding_window_view(padded, 4)[: len(nodes) - 1]
    with np.errstate(invalid="ignore"):
        low, high = windows.min(axis=1), windows.max(axis=1)  # NaN where a node is missing
        table = np.where(np.isfinite(high) & (high <= _QUIET_SPREAD * low), low / np.maximum(2.0, high / low), 0.0)
    table[np.isposinf(windows).all(axis=1)] = np.inf  # no event at any of the four nodes
    # OrbitRange.judge reaches np.unique at its first warning, and NumPy's first np.unique in a process imports
    # numpy.ma (measured 7 ms): paid here, in the first evaluation, not in the first warning after it
    np.unique(radii)
    return table.tolist()


def _quiet(expansion: Any, epsilon: Any, point: Point) -> bool:
    """Whether the quiet table says ε needs no OrbitRange at this point (see the comment above)."""
    table = _quiet_table(expansion)
    if table is None:
        return False
    value = point.arrays[0]
    if not point.shape:
        limit = table[grid_cell(float(value))]
        return bool(abs(epsilon) < limit) if isinstance(epsilon, float) else bool(np.all(np.abs(epsilon) < limit))
    return bool(np.all(np.abs(epsilon) < np.asarray(table)[grid_cell(value)]))


def _range_message(expansion: Any, epsilon: Any, point: Point | None, values: Mapping[Any, Any] | None) -> str | None:
    """Raise where no periodic orbit exists at some ε; else the warning for ε outside the derivation's regime
    or beyond the radius of convergence (see :meth:`~lindstedt.Expansion.epsilon_range`), or None."""
    state = expansion._floats
    source = state.range_source
    if source is UNSET:
        source = _range_source(expansion)
    if source is None:
        return None
    if point is not None and len(point.arrays) == 1 and _quiet(expansion, epsilon, point):
        return None
    gauge = state.gauge
    if point is None or not point.shape:
        bounds = _range_at(expansion, _range_arguments(expansion, point, values), source)
        return bounds.judge(epsilon, gauge)
    arrays = np.broadcast_arrays(np.asarray(epsilon, dtype=float), *[np.asarray(value, dtype=float) for value in point.arrays])
    columns = np.stack([array.reshape(-1) for array in arrays[1:]], axis=1)
    epsilons = arrays[0].reshape(-1)
    unique, inverse = np.unique(columns, axis=0, return_inverse=True)
    for index, row in enumerate(unique):
        message = _range_at(expansion, tuple(float(value) for value in row), source).judge(epsilons[inverse.reshape(-1) == index], gauge)
        if message:
            given = ", ".join(f"{name} = {value:.6g}" for name, value in zip(state.names, row))
            return f"at {given}: {message}"
    return None


def _series_message(expansion: Any, coefficients: np.ndarray, last: int, eta: np.ndarray, point: Point,
                    following: np.ndarray | None = None) -> str | None:
    """:func:`series_warning` for ω_0 … ω_last at these gauge values, deriving ω_{last+1} only where it could
    make the warning speak (if ``following`` is not given and it is not derived yet): below the radius where
    a next term as large as :func:`next_term_bound` would speak, it cannot."""
    if last < 1 or eta.size == 0:
        return None
    gauge = expansion._floats.gauge
    if following is None and omega_known(expansion, last + 1):
        following = omega_values(expansion, last + 1, point, WARNING_TOLERANCE)[last + 1]
    if not point.shape:  # one coefficient set: the largest |η| decides, as series_warning reads it
        if following is None:
            size = np.array([float(np.max(np.abs(eta)))])
            if series_warning([*coefficients.tolist(), float(next_term_bound(coefficients))], last, size, gauge) is None:
                return None
            following = omega_values(expansion, last + 1, point, WARNING_TOLERANCE)[last + 1]
        return series_warning([*coefficients.tolist(), float(following)], last, np.asarray(eta), gauge)
    size = np.abs(eta)  # one coefficient set per element: each element is judged at its own |η|
    if following is None:
        stand_in = next_term_bound(coefficients)
        if not series_warning_mask(np.concatenate([coefficients, stand_in[None]]), last, size).any():
            return None
        following = omega_values(expansion, last + 1, point, WARNING_TOLERANCE)[last + 1]
    table = np.concatenate([coefficients, np.asarray(following)[None]])
    speaking = series_warning_mask(table, last, size)
    if not speaking.any():
        return None
    index = int(np.argmax(speaking))
    rows = table.reshape(table.shape[0], *[1] * (speaking.ndim - table.ndim + 1), *table.shape[1:])
    column = np.broadcast_to(rows, (table.shape[0], *speaking.shape)).reshape(table.shape[0], -1)[:, index]
    return series_warning(list(column), last, np.array([np.broadcast_to(size, speaking.shape).flat[index]]), gauge)


def _drift_message(expansion: Any, coefficients: np.ndarray, last: int, eta: np.ndarray, times: np.ndarray,
                   point: Point) -> str | None:
    """:func:`phase_warning` with the drift rate |ω_{last+2} η^{last+2}|; ω_{last+2} is derived only if a next
    term as large as :func:`next_term_bound` could make the drift reach one radian at these times."""
    if times.size == 0:
        return None
    power = np.abs(eta) ** (last + 2)
    longest = float(np.max(np.abs(times)))
    if not omega_known(expansion, last + 2):
        stand_in = next_term_bound(coefficients[: last + 2])
        if not float(np.max(stand_in * power)) * longest >= 1.0:
            return None
    rate = np.abs(omega_values(expansion, last + 2, point, WARNING_TOLERANCE)[last + 2]) * power
    if not np.shape(rate):
        return phase_warning(float(rate), times)
    drift = np.abs(rate * times) if times.ndim else np.abs(rate) * longest
    index = int(np.argmax(drift))
    broadcast = np.broadcast_to(times, drift.shape) if times.ndim else np.full(drift.shape, longest)
    return phase_warning(float(np.broadcast_to(rate, drift.shape).flat[index]), np.array([broadcast.flat[index]]))
