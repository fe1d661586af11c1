"""The float coefficients of an expansion at parameter values: ω_k, φ_k and the waveform data of u(t) = Σ_k ε^k v_k.

With free symbols the closed forms are compiled once into a float64 family with a first-order rounding-error bound
(:func:`lindstedt.compiled.family.compile_family`); a value is used where its bound is below 1e-13 (relative for
ω_k and φ_k, of |a0| for u), else repaired: by the exact series of a gap coefficient in acos κ
(:func:`lindstedt.compiled.stable_source.stable_function`) or by the exact expression at the double's exact value.
With one free symbol the closed form of each ω_k is probed once on the nodes of
:func:`lindstedt.results._values.parameter_grid` when ω_k is first asked for: if it fails the bound at a node, its
stable series is generated then (0.1-0.3 s per coefficient, once), so that later parameter values new to the
expansion cost microseconds, not the 5-20 ms of an exact evaluation or a generation on demand (measured before:
worst 0.30 s for ``frequency_coefficients`` at a new κ, order 4).  Other coefficients get their series after
_STABLE_AFTER exact repairs, as before.  Without free symbols the floats are computed once.  Exact numbers a
double cannot hold are evaluated through the exactly substituted coefficients (:func:`frequency_coefficients`,
:func:`float_branches`, :func:`phase_value`).

Functions of an :class:`~lindstedt.Expansion`, typed ``Any``: :mod:`lindstedt.results.expansion` imports this
module, never the other way round.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from typing import Any, Callable, Mapping

import numpy as np

from ..compiled.stable_source import stable_function
from ..engine.float_branches import FloatBranches
from ._values import Point, core_family, finite, floats, omega_expr, probe_points, substitution, to_float
from ._waveform_data import _WAVEFORM_TOLERANCE, _WaveformData, _WaveformLayout

__all__ = ["COEFFICIENT_TOLERANCE", "WARNING_TOLERANCE", "float_branches", "frequency_coefficients", "omega_values",
           "phase_value", "phase_values", "scalar_omegas", "waveform_data", "waveform_layout"]

COEFFICIENT_TOLERANCE = 1e-13  # relative rounding bound accepted for a compiled ω_k, φ_k
WARNING_TOLERANCE = 1e-3  # ... for ω_{N+1}, ω_{N+2} when only a warning reads them
_STABLE_AFTER = 4  # exact evaluations of one ω_k before its stable series is generated (≈ 0.1-0.4 s)
_SCALAR_MEMORY = 64  # one-parameter points whose plain-float ω_k an expansion keeps (:func:`scalar_omegas`)


def omega_values(expansion: Any, highest: int, point: Point, tolerance: float = COEFFICIENT_TOLERANCE) -> np.ndarray:
    """Float ω_0 … ω_highest at the point, shape (highest + 1,) + point shape (see
    :meth:`lindstedt.Expansion.frequency_coefficients`)."""
    key = ("omega", highest, tolerance)
    cache = point.cache
    if key in cache:
        return cache[key]
    state = expansion._floats
    if not state.symbols:
        constants = state.cache.setdefault("omega floats", {})
        for k in range(highest + 1):
            if k not in constants:
                constants[k] = to_float(omega_expr(expansion, k))
        rows = np.array([constants[k] for k in range(highest + 1)])
    else:
        if len(state.symbols) == 1 and state.cache.get(("probed", tolerance), -1) < highest:
            _probe(expansion, highest, tolerance)
        core = cache.get("core")
        done = -1
        parts = []
        if core is not None:
            values, bounds, done = core
            done = min(done, highest)
            parts.append(_accepted(expansion, values[: done + 1], bounds[: done + 1], range(done + 1), point, tolerance))
        for k in range(done + 1, highest + 1):
            family = state.family(("omega", k), lambda k=k: [omega_expr(expansion, k)])
            values, bounds = family(*point.arrays) if family is not None else (None, None)
            parts.append(_accepted(expansion, values, bounds, [k], point, tolerance))
        rows = np.concatenate(parts)
    if not np.all(np.isfinite(rows)):
        columns = rows.reshape(rows.shape[0], -1)
        index = int(np.flatnonzero(~np.all(np.isfinite(columns), axis=0))[0])
        finite(rows, expansion.problem.numeric_substitution(state.values_at(point, index)) if point.arrays else {})
    cache[key] = rows
    return rows


def scalar_omegas(expansion: Any, value: float, last: int, following: bool) -> list[float] | None:
    """ω_0 … ω_last (and ω_{last+1} if ``following``, as the warnings read it) of a one-parameter expansion at one
    float value p, in plain floats: the single-point path of :func:`omega_values` and of the assumption check of
    :func:`~lindstedt.results._values.read`, in one pass; None wherever that path would do more than accept
    compiled values or stable series that exist already (then the caller takes the general path, which decides
    the same way and raises, repairs exactly or generates what is missing).

    One evaluation of the core family (:func:`~lindstedt.results._values.core_family`: the assumptions' conditions
    and ω_0 … ω_M, the straight-line scalar form of :meth:`lindstedt.compiled.family.BoundedFamily.scalar`) per new
    p, kept for the last _SCALAR_MEMORY values.  A condition's sign is taken where |value| exceeds its rounding bound
    (as :meth:`~lindstedt.results.assumptions.Assumptions.float_verdict`); an undecided or violated one, an
    assumption without a float form, a coefficient not finite, or one whose bound exceeds the tolerance without a
    stable series gives None.  Only after the general path probed the grid for these orders (its first call).
    """
    state = expansion._floats
    cache = state.cache
    if cache.get(("probed", COEFFICIENT_TOLERANCE), -1) < last or (following and cache.get(("probed", WARNING_TOLERANCE), -1) <= last):
        return None
    memory = cache.get("scalar omegas")
    if memory is None:
        memory = cache["scalar omegas"] = OrderedDict()
    entry = memory.get(value, memory)  # the dict itself marks a miss (None is an entry: general path)
    if entry is memory:
        entry = memory[value] = _scalar_entry(expansion, value)
        if len(memory) > _SCALAR_MEMORY:
            memory.popitem(last=False)
    if entry is None or entry[3] < last + following:
        return None
    accepted, raw, bounds, _ = entry
    coefficients = accepted[: last + 1]
    if None in coefficients:
        return None
    if not following:
        return coefficients
    next_value = raw[last + 1]
    if not bounds[last + 1] <= WARNING_TOLERANCE * abs(next_value):
        next_value = _stable_value(expansion, last + 1, value)
    return None if next_value is None else [*coefficients, next_value]


def _scalar_entry(expansion: Any, value: float) -> tuple[list[float | None], list[float], list[float], int] | None:
    """(ω_k accepted at COEFFICIENT_TOLERANCE or from an existing stable series, else None; the compiled ω_k; their
    bounds; M) at p = value, or None if the assumptions are not decided true there in floats."""
    cache = expansion._floats.cache
    setup = cache.get("one point")
    if setup is None or setup[2] <= expansion._steps * expansion.order:  # final once ω_{N+1} is in the core
        assumptions = expansion._assumptions
        family, conditions, highest = core_family(expansion)
        if assumptions._integers or assumptions._inexpressible:
            family = None
        setup = cache["one point"] = (family, conditions, highest, assumptions._condition_rows[1].tolist())
    family, conditions, highest, signs = setup
    point = None if family is None else family.scalar(value)
    if point is None:
        return None
    values, bounds = point
    for number, bound, allowed in zip(values[:conditions], bounds[:conditions], signs):
        if not (abs(number) > bound or (number == 0 and bound == 0)) or not allowed[(number > 0) - (number < 0) + 1]:
            return None
    raw, errors = values[conditions:], bounds[conditions:]
    accepted: list[float | None] = []
    for k, (number, bound) in enumerate(zip(raw, errors)):
        if not bound <= COEFFICIENT_TOLERANCE * abs(number):
            number = _stable_value(expansion, k, value)
        accepted.append(number if number is not None and math.isfinite(number) else None)
    return accepted, raw, errors, highest


def _stable_value(expansion: Any, k: int, value: float) -> float | None:
    """ω_k at p from its stable series if it exists and is finite there, else None."""
    stable = expansion._floats.cache.get("stable", {}).get(k)
    if stable is None:
        return None
    number = float(stable.scalar(value))
    return number if math.isfinite(number) else None


def _accepted(expansion: Any, values: np.ndarray | None, bounds: np.ndarray | None, indices: Any, point: Point,
              tolerance: float) -> np.ndarray:
    """Compiled ω_k where the rounding bound is at most ``tolerance`` of the value; elsewhere the stable
    series (one gap symbol, generated once a few points needed it) or the exact expression."""
    indices = list(indices)
    if values is None:
        values = np.full((len(indices), *point.shape), np.nan)
        bad = np.ones(values.shape, dtype=bool)
    else:
        bad = ~(bounds <= tolerance * np.abs(values))
        if not bad.any():
            return values
        values = values.copy()
    if bad.any():
        flat_values, flat_bad = values.reshape(len(indices), -1), bad.reshape(len(indices), -1)
        for row, k in enumerate(indices):
            _repair(expansion, flat_values[row], flat_bad[row], k, point)
    return values


def _repair(expansion: Any, values: np.ndarray, bad: np.ndarray, k: int, point: Point) -> None:
    if not bad.any():
        return
    state = expansion._floats
    stables = state.cache.setdefault("stable", {})
    if k in stables:
        stable = stables[k]
    else:  # not flagged by the probe: the series after a few exact repairs
        counts = state.cache.setdefault("repairs", {})
        counts[k] = counts.get(k, 0) + int(bad.sum())
        stable = _stable_omega(expansion, k) if counts[k] >= _STABLE_AFTER else None
    if stable is not None:
        if not point.shape:
            fixed = np.array([stable.scalar(float(point.arrays[0]))])
        else:
            fixed = np.broadcast_to(np.asarray(stable(*point.arrays), dtype=float), point.shape).reshape(-1)
        usable = bad & np.isfinite(fixed)
        values[usable] = fixed[usable]
        bad = bad & ~usable
    for index in np.flatnonzero(bad):
        values[index] = state.exact_at(omega_expr(expansion, k), point, int(index))


def _probe(expansion: Any, highest: int, tolerance: float) -> None:
    """Generate the stable series of each ω_k (k ≤ highest, one free symbol) whose compiled closed form fails the
    rounding bound ``tolerance`` at a point of :func:`~lindstedt.results._values.probe_points` or changes sign
    between two of them (near a root no closed form is accurate relative to ω_k): see the module docstring."""
    state = expansion._floats
    key = ("probed", tolerance)
    points = np.sort(probe_points(expansion))
    if points.size:
        for k in range(state.cache.get(key, -1) + 1, highest + 1):
            family = state.family(("omega", k), lambda k=k: [omega_expr(expansion, k)])
            if family is None:
                continue
            values, bounds = family(points)
            signs = np.sign(values[0])
            if not np.all(bounds <= tolerance * np.abs(values)) or np.any(signs[1:] * signs[:-1] < 0):
                _stable_omega(expansion, k)
    state.cache[key] = highest


def _stable_omega(expansion: Any, k: int) -> Callable[[Any], np.ndarray] | None:
    state = expansion._floats
    cache = state.cache.setdefault("stable", {})
    if k not in cache:
        cache[k] = stable_function(omega_expr(expansion, k), state.symbols[0]) if len(state.symbols) == 1 else None
    return cache[k]


def phase_values(expansion: Any, point: Point) -> np.ndarray:
    """Float φ_0 … φ_N at the point (from (u0, v0); accepted like ω_k, exact where the bound is too large)."""
    if "phase" in point.cache:
        return point.cache["phase"]
    state = expansion._floats
    phase = list(expansion.phase)
    if not state.symbols:
        values = state.cache.get("phase floats")
        if values is None:
            values = state.cache["phase floats"] = finite(np.array([to_float(value) for value in phase]), {})
    else:
        family = state.family("phase", lambda: phase)
        values, bounds = family(*point.arrays) if family is not None else (np.full((len(phase), *point.shape), np.nan), None)
        bad = np.ones(values.shape, dtype=bool) if bounds is None else ~(bounds <= COEFFICIENT_TOLERANCE * np.abs(values))
        flat_values, flat_bad = values.reshape(len(phase), -1), bad.reshape(len(phase), -1)
        for row, expression in enumerate(phase):
            for index in np.flatnonzero(flat_bad[row]):
                flat_values[row, index] = state.exact_at(expression, point, int(index))
    point.cache["phase"] = values
    return values


def waveform_layout(expansion: Any) -> _WaveformLayout:
    """Where each float of the displacement lives (a0, ε̂/ε, contact-angle shifts, the coefficient matrices of
    the branches), and their closed forms compiled once (or their floats, without free symbols)."""
    state = expansion._floats
    if state.layout is None:
        if not state.symbols:
            scale, amplitude, branches = float_branches(expansion, None)
            state.layout = _WaveformLayout.build(branches, amplitude, scale, ())
        else:
            form = expansion._form
            branches = expansion._hierarchy.float_branches(expansion._steps * expansion.order, form.to_expr)
            state.layout = _WaveformLayout.build(branches, expansion.problem.a0, form.epsilon_scale, state.symbols)
    return state.layout


def waveform_data(expansion: Any, layout: _WaveformLayout, point: Point, largest: float) -> _WaveformData:
    """The displacement's float data at the point (``layout`` from :func:`waveform_layout`), good for |η| up to
    ``largest``: compiled values where their rounding bound keeps u within _WAVEFORM_TOLERANCE |a0| at
    η̂ = (ε̂/ε)^(1/s) η, exact elsewhere."""
    state = expansion._floats
    compiled = point.cache.get("waveform")
    if compiled is None:
        if layout.constants is not None:
            values, errors = layout.constants, np.zeros(layout.orders)
        elif layout.family is None:
            values = np.full((len(layout.expressions), *point.shape), np.nan)
            errors = np.full((layout.orders, *point.shape), np.inf)
        else:
            values, bounds = layout.family(*point.arrays)
            errors = layout.errors(values, bounds)
        compiled = point.cache["waveform"] = (values, errors, {})
    values, errors, repaired = compiled
    if layout.constants is None:
        size = np.abs(values[1]) ** (1 / expansion._steps) * largest
        powers = size[None] ** np.arange(layout.orders).reshape(-1, *[1] * np.ndim(size))
        bad = np.broadcast_to(~(np.sum(powers * errors, axis=0) <= _WAVEFORM_TOLERANCE), point.shape)
        missing = [int(index) for index in np.flatnonzero(bad) if int(index) not in repaired]
        if missing:
            values = values.copy()  # never in place: a lock-free evaluation may be reading the last data
            flat = values.reshape(len(layout.expressions), -1)
            for index in missing:
                flat[:, index] = [state.exact_at(expression, point, index) for expression in layout.expressions]
                repaired[index] = True
            if not np.all(np.isfinite(flat[:, missing])):
                finite(flat[:, missing], expansion.problem.numeric_substitution(state.values_at(point, missing[0])))
            point.cache["waveform"] = (values, errors, repaired)
            point.cache.pop("unpacked", None)
    unpacked = point.cache.get("unpacked")
    if unpacked is None:
        if not np.all(np.isfinite(values)):
            columns = values.reshape(values.shape[0], -1)
            index = int(np.flatnonzero(~np.all(np.isfinite(columns), axis=0))[0])
            finite(values, expansion.problem.numeric_substitution(state.values_at(point, index)) if point.arrays else {})
        unpacked = point.cache["unpacked"] = layout.unpack(values)
    return unpacked


# -- exactly substituted values (numbers a double cannot hold; stretched contact arcs) ------------------
def frequency_coefficients(expansion: Any, highest: int, values: Mapping[Any, Any] | None) -> np.ndarray:
    """Float ω_0..ω_highest for these values (cached: repeated evaluations cost microseconds)."""
    return expansion._floats.cached(
        ("omega", highest), values, lambda: floats(expansion, [expansion.omega_correction(k) for k in range(highest + 1)], values)
    )


def float_branches(expansion: Any, values: Mapping[Any, Any] | None) -> tuple[float, float, FloatBranches]:
    """ε̂/ε, a0 and the float branches of v_0..v_N for these values (cached per values)."""

    def compute() -> tuple[float, float, FloatBranches]:
        exact = substitution(expansion, values)
        form = expansion._form

        def to_number(element: Any) -> float:
            return to_float(form.to_expr(element).xreplace(exact))

        branches = expansion._hierarchy.float_branches(expansion._steps * expansion.order, to_number)
        numbers = [term[3] for order in branches.terms for piece in order for component in piece for term in component]
        finite(np.array(numbers + [value for order in branches.shifts for value in order], dtype=float), exact)
        scale = float(form.epsilon_scale.xreplace(exact))
        return scale, float(expansion.problem.a0.xreplace(exact)), branches

    return expansion._floats.cached("branches", values, compute)


def phase_value(expansion: Any, gauge: float, values: Mapping[Any, Any] | None) -> float:
    """φ(ε) = Σ_{k≤N} φ_k gauge^k as a float (0 for a release at rest)."""
    if not expansion.problem.has_initial_velocity:
        return 0.0
    coefficients = expansion._floats.cached("phase", values, lambda: floats(expansion, list(expansion.phase), values))
    return float(np.polynomial.polynomial.polyval(gauge, coefficients))
