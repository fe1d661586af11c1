"""The float image of a branch hierarchy: W(s; ε) = Σ_n ε̂^n W_n(s) evaluated for many s and ε at float cost.

Between the moving contact angles ``s_i*(ε) = Σ_n σ_{i,n} ε̂^n`` every correction W_n is a sum of terms
``c s^m cos(ν s)`` / ``c s^m sin(ν s)`` (:mod:`lindstedt.algebra.branch`); on a stretched contact arc it is
a Chebyshev series in ``v = (1 − τ)^{1/d}`` (:class:`~lindstedt.engine.stretched.FloatArc`).  The strained time
is folded to [0, π] by evenness and 2π-periodicity (:func:`fold`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._precision import cached_property

__all__ = ["FloatBranches", "fold"]


@dataclass(frozen=True)
class FloatBranches:
    """Float image of W_0 … W_N for fast evaluation between the moving contact angles.

    ``terms[n][p][k]`` lists ``(frequency, parity, power, value)`` of W_{n,k} on piece p;
    ``shifts[n][i]`` is σ_{i,n} (n = 0: the contact angle β_i).
    """

    terms: tuple
    shifts: tuple
    arcs: tuple[Any, Any] = (None, None)  # per component, the FloatArcs of the first / last piece (or None)

    @cached_property
    def _arrays(self) -> tuple[np.ndarray, list[list[list[tuple[int, np.ndarray, np.ndarray, np.ndarray]]]]]:
        """The shifts as an (orders × boundaries) array; per piece and component, per parity, the
        frequencies, powers and an (orders × terms) coefficient matrix: a new ε costs small matrix products."""
        shifts = np.array(self.shifts, dtype=float).reshape(len(self.shifts), -1)
        pieces = []
        for piece in range(len(self.terms[0])):
            components = []
            for component in range(len(self.terms[0][piece])):
                groups = []
                for parity in (0, 1):
                    keys = sorted({(t[0], t[2]) for order in self.terms for t in order[piece][component] if t[1] == parity})
                    if not keys:
                        continue
                    index = {key: position for position, key in enumerate(keys)}
                    coefficients = np.zeros((len(self.terms), len(keys)))
                    for n, order in enumerate(self.terms):
                        for frequency, term_parity, power, value in order[piece][component]:
                            if term_parity == parity:
                                coefficients[n, index[frequency, power]] += value
                    frequencies, powers = (np.array(column, dtype=float) for column in zip(*keys))
                    groups.append((parity, frequencies, powers, coefficients))
                components.append(groups)
            pieces.append(components)
        return shifts, pieces

    def evaluate(self, strained_time: Any, scaled_epsilon: float, derivative: bool = False) -> np.ndarray:
        """Σ_n ε̂^n W_n(s) (or d/ds of it) at the strained times s; shape ``s.shape + (N,)``."""
        folded, sign = fold(np.asarray(strained_time, dtype=float))
        shifts, pieces = self._arrays
        weights = float(scaled_epsilon) ** np.arange(len(self.terms))
        result = np.zeros(folded.shape + (len(pieces[0]),))
        piece_index = np.searchsorted(weights @ shifts, folded) if len(pieces) > 1 else None
        for piece, components in enumerate(pieces):
            if piece_index is None:  # one piece (smooth f, or no contact): no masks
                mask, points = ..., folded
            else:
                mask = piece_index == piece
                if not np.any(mask):
                    continue
                points = folded[mask]
            if piece == 0 and self.arcs[0] is not None:  # Y(s/s_1*), one FloatArc per component
                length = weights @ shifts[:, 0]
                for component, arc in enumerate(self.arcs[0]):
                    values = arc.evaluate(points / length, weights, derivative)
                    result[mask, component] = values * sign[mask] / length if derivative else values
                continue
            if piece == len(pieces) - 1 and self.arcs[1] is not None:  # −Y((π − s)/(π − s_L*)), per component
                length = np.pi - weights @ shifts[:, -1]
                for component, arc in enumerate(self.arcs[1]):
                    values = arc.evaluate((np.pi - points) / length, weights, derivative)
                    result[mask, component] = values * sign[mask] / length if derivative else -values
                continue
            for component, groups in enumerate(components):
                values = sum((_evaluate_terms(*group[:3], weights @ group[3], points, derivative) for group in groups), np.zeros(points.shape))
                result[mask, component] = values * sign[mask] if derivative else values
        return result


def _evaluate_terms(parity: int, frequency: np.ndarray, power: np.ndarray, value: np.ndarray, s: np.ndarray, derivative: bool) -> np.ndarray:
    """Σ value s^m trig(ν s) (trig = cos for parity 0, sin for 1), or its s-derivative, vectorised."""
    argument = np.multiply.outer(s, frequency)
    trig = np.cos(argument) if parity == 0 else np.sin(argument)
    constant_power = not power.any()
    powers = 1.0 if constant_power else np.power.outer(s, power)
    if not derivative:
        return (trig * powers) @ value
    # d/ds s^m trig(νs) = m s^{m−1} trig(νs) + ν s^m trig'(νs),  cos' = −sin, sin' = cos
    slope = (-np.sin(argument) if parity == 0 else np.cos(argument)) * frequency * powers
    if not constant_power:
        slope = slope + trig * np.where(power > 0, power * np.power.outer(s, np.maximum(power - 1, 0)), 0.0)
    return slope @ value


def fold(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reduce s to [0, π] using evenness and 2π-periodicity; also the sign of d/ds."""
    shifted = np.mod(s + np.pi, 2 * np.pi) - np.pi
    return np.abs(shifted), np.where(shifted < 0, -1.0, 1.0)
