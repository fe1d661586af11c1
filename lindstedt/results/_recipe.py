"""How a result is unpickled: derived again by the method that derived it (results never import the methods)."""

from __future__ import annotations

from typing import Any

__all__ = ["derived_again"]


def derived_again(method: Any, problem: Any, order: int) -> Any:
    """``method.expand(problem, order)``: the result a method (a ``LindstedtPoincare``, a ``StrainedCoordinatesNNM``)
    derived, derived again from its recipe (``__reduce__`` of :class:`~lindstedt.Expansion` and
    :class:`~lindstedt.NNMExpansion`).

    Examples
    --------
    >>> import lindstedt
    >>> derived_again(lindstedt.LindstedtPoincare(), lindstedt.Oscillator("u**3", a0=1, omega0=1), 1).omega
    (1, 3/8)
    """
    return method.expand(problem, order)
