"""The coefficients of an expansion as every text and LaTeX output prints them.

Closed forms of a piecewise nonlinearity with a symbolic gap are written in its contact angles
(κ = b/a0, β = acos κ, σ = sqrt(1 − κ²): :func:`lindstedt.algebra.in_contact_angles`, an identity), with
the definitions to print once before them: ``lindstedt expand``'s pretty output, :meth:`Expansion.summary`
and :meth:`Expansion.to_latex` share them.
"""

from __future__ import annotations

from typing import Any

from ..algebra import in_contact_angles

__all__ = ["readable_coefficients"]


def readable_coefficients(expansion: Any) -> tuple[tuple, tuple, tuple, tuple]:
    """(definitions, ω_k, A_k, φ_k) as printed: closed forms in the contact angles (κ = b/a0, β = acos κ,
    σ = sqrt(1 − κ²); :func:`lindstedt.algebra.in_contact_angles`, an identity) when they have any, with the
    definitions to print once before them; A_k, φ_k only for a release off the turning point."""
    omega = tuple(expansion.omega)
    amplitude, phase = (tuple(expansion.amplitude), tuple(expansion.phase)) if expansion.problem.has_initial_velocity else ((), ())
    forms = in_contact_angles(omega + amplitude + phase)
    split = (len(omega), len(omega) + len(amplitude))
    return forms.definitions, forms.forms[:split[0]], forms.forms[split[0]:split[1]], forms.forms[split[1]:]
