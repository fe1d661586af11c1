"""The displacement of a 1-dof expansion as float data compiled once: u(t) = a0 Σ_n η̂^n W_n(s), s = Ω t.

Each W_n is, piece by piece between the moving contact angles β_i + Σ_n η̂^n σ_{i,n}, a sum
Σ c s^m trig(ν s); the coefficients of every order are one flat vector (from the compiled closed forms of
:func:`lindstedt.compiled.family.compile_family`, with a rounding bound), evaluated for arrays of t, ε and
parameters at once.  Used by :class:`lindstedt.results.expansion.Expansion`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy

from ..engine.float_branches import FloatBranches
from ..compiled.family import compile_family

_WAVEFORM_TOLERANCE = 1e-13  # bound on |δu| / |a0| accepted from compiled waveform data


def _fold(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """s reduced to [0, π] by evenness and 2π-periodicity, and the sign of d/ds."""
    shifted = np.mod(s + np.pi, 2 * np.pi) - np.pi
    return np.abs(shifted), np.where(shifted < 0, -1.0, 1.0)


def _terms(parity: int, frequency: np.ndarray, power: np.ndarray, coefficients: np.ndarray, s: np.ndarray, derivative: bool) -> np.ndarray:
    """Σ_j c_j s^{m_j} trig(ν_j s) (trig = cos for parity 0, sin for 1) or its s-derivative; ``coefficients`` of
    shape (K,) (one set) or (len(s), K) (one set per point)."""
    argument = np.multiply.outer(s, frequency)
    trig = np.cos(argument) if parity == 0 else np.sin(argument)
    constant_power = not power.any()
    powers = 1.0 if constant_power else np.power.outer(s, power)
    if derivative:  # d/ds s^m trig(νs) = m s^{m−1} trig(νs) + ν s^m trig'(νs)
        slope = (-np.sin(argument) if parity == 0 else np.cos(argument)) * frequency * powers
        if not constant_power:
            slope = slope + trig * np.where(power > 0, power * np.power.outer(s, np.maximum(power - 1, 0)), 0.0)
        matrix = slope
    else:
        matrix = trig * powers
    if coefficients.ndim == 1:
        return matrix @ coefficients
    return np.einsum("nk,nk->n", matrix, coefficients)


@dataclass(frozen=True)
class _WaveformData:
    layout: "_WaveformLayout"
    amplitude: Any  # a0, shape P
    scale: Any  # ε̂/ε, shape P
    shifts: np.ndarray  # (P..., orders, boundaries): β_i and σ_{i,n}
    matrices: tuple[np.ndarray, ...]  # per block (P..., orders, keys)


@dataclass(frozen=True)
class _WaveformLayout:
    """The displacement's float data as one flat vector: a0, ε̂/ε, the shifts σ_{i,n} (orders × boundaries), and
    per (piece, parity) block the matrix of Σ_n ε̂^n Σ c s^m trig(ν s) (orders × (ν, m) keys); component 0 of
    the engine's float branches (1 dof), summed term by term as FloatBranches does."""

    orders: int
    boundaries: int
    pieces: int
    blocks: tuple[tuple[int, int, np.ndarray, np.ndarray, int, int], ...]  # piece, parity, ν, m, offset, keys
    expressions: tuple[Any, ...]
    weights: np.ndarray  # (orders, entries): |∂W_n/∂value| bound per entry (s in [0, π]); 0 for a0 and ε̂/ε
    family: Any  # BoundedFamily of the expressions (free symbols), or None
    constants: np.ndarray | None  # the floats (no free symbols)

    @staticmethod
    def build(branches: FloatBranches, amplitude: Any, scale: Any, symbols: tuple[sympy.Symbol, ...]) -> "_WaveformLayout":
        """From the engine's float branches (their values floats, or sympy expressions in ``symbols``)."""
        terms, shifts = branches.terms, branches.shifts
        orders, boundaries, pieces = len(terms), len(shifts[0]), len(terms[0])
        numeric = not symbols
        entries: list[Any] = [amplitude, scale]
        weights = [np.zeros(orders), np.zeros(orders)]

        def weight(n: int, value: float) -> np.ndarray:
            row = np.zeros(orders)
            row[n] = value
            return row

        for n in range(orders):
            entries.extend(shifts[n])
            weights.extend([weight(n, 1.0)] * boundaries)  # |u'| <= |a0| (1 + O(η̂)) where a boundary is misplaced
        blocks = []
        for piece in range(pieces):
            for parity in (0, 1):
                keys = sorted({(t[0], t[2]) for order in terms for t in order[piece][0] if t[1] == parity})
                if not keys:
                    continue
                index = {key: position for position, key in enumerate(keys)}
                matrix: list[list[Any]] = [[0.0 if numeric else sympy.Integer(0)] * len(keys) for _ in range(orders)]
                for n, order in enumerate(terms):
                    for frequency, term_parity, power, value in order[piece][0]:
                        if term_parity == parity:
                            matrix[n][index[frequency, power]] += value
                frequencies, powers = (np.array(column, dtype=float) for column in zip(*keys))
                blocks.append((piece, parity, frequencies, powers, len(entries), len(keys)))
                for n, row in enumerate(matrix):
                    entries.extend(row)
                    # |s^m trig(ν s)| and its s-derivative on [0, π]
                    weights.extend(weight(n, float(np.pi**m * (1 + nu + m))) for nu, m in keys)
        table = np.array(weights).T  # (orders, entries)
        if numeric:
            return _WaveformLayout(orders, boundaries, pieces, tuple(blocks), tuple(entries), table, None, np.array(entries, dtype=float))
        family = compile_family(entries, symbols)
        return _WaveformLayout(orders, boundaries, pieces, tuple(blocks), tuple(entries), table, family, None)

    def errors(self, values: np.ndarray, bounds: np.ndarray) -> np.ndarray:
        """Per order n and parameter element: the bound on |δW_n| (u/a0 and its s-derivative) from rounding
        in the compiled values; +inf where a0 or ε̂/ε is not within 1e-13 relative."""
        with np.errstate(all="ignore"):  # an infinite bound (a value the closed form cannot give) stays infinite
            errors = np.tensordot(self.weights, np.where(np.isfinite(bounds), bounds, np.inf), axes=1)  # (orders, P...)
            errors = np.where(np.isnan(errors), np.inf, errors)
            scaling = (bounds[:2] <= _WAVEFORM_TOLERANCE * np.abs(values[:2])).all(axis=0)
        return np.where(scaling, errors, np.inf)

    def unpack(self, values: np.ndarray) -> _WaveformData:
        moved = np.moveaxis(values, 0, -1)  # P + (V,)
        shape = moved.shape[:-1]
        start = 2 + self.orders * self.boundaries
        shifts = moved[..., 2:start].reshape(*shape, self.orders, self.boundaries)
        matrices = tuple(moved[..., offset : offset + self.orders * keys].reshape(*shape, self.orders, keys) for *_, offset, keys in self.blocks)
        return _WaveformData(self, moved[..., 0], moved[..., 1], shifts, matrices)

    def evaluate(self, data: _WaveformData, strained: Any, scaled: Any, derivative: bool) -> np.ndarray:
        """Σ_n η̂^n W_n(s) (or d/ds of it) at the strained times, between the moving contact angles."""
        folded, sign = _fold(np.asarray(strained, dtype=float))
        scaled = np.asarray(scaled, dtype=float)
        weights = scaled[..., None] ** np.arange(self.orders)  # Q + (orders,)
        result = np.zeros(folded.shape)
        if not weights.shape[:-1] and not data.shifts.shape[:-2]:  # one ε, one parameter set: shared coefficients
            index = np.searchsorted(weights @ data.shifts, folded) if self.pieces > 1 else None
            for (piece, parity, frequencies, powers, _, _), matrix in zip(self.blocks, data.matrices):
                mask = ... if index is None else index == piece
                points = folded[mask]
                if points.size:
                    values = _terms(parity, frequencies, powers, weights @ matrix, points, derivative)
                    result[mask] += values * sign[mask] if derivative else values
            return result
        full = folded.shape
        index = None
        if self.pieces > 1:
            limits = np.einsum("...l,...lb->...b", weights, data.shifts)
            index = (np.broadcast_to(limits, (*full, self.boundaries)) < folded[..., None]).sum(axis=-1)
        for (piece, parity, frequencies, powers, _, keys), matrix in zip(self.blocks, data.matrices):
            mask = np.ones(full, dtype=bool) if index is None else index == piece
            if not mask.any():
                continue
            coefficients = np.broadcast_to(np.einsum("...l,...lk->...k", weights, matrix), (*full, keys))[mask]
            values = _terms(parity, frequencies, powers, coefficients, folded[mask], derivative)
            result[mask] += values * sign[mask] if derivative else values
        return result
