"""Typed exceptions of lindstedt.

Every error raised on bad input is one of these; each message names what was
wrong and how to fix it.  The hierarchy is deliberately small:

``LindstedtError``
    ``ProblemError`` (also a ``ValueError``): the problem definition is invalid.
        ``ParameterError``: a parameter is undeclared, unused or lacks a value.
        ``UnsupportedNonlinearityError``: f(u) is of a kind no method handles.
    ``OrderError`` (also a ``ValueError``): an expansion order out of range.
    ``ResonanceError``: an internal resonance makes the expansion undefined.
    ``ConvergenceError``: a numerical method did not reach its tolerance.
    ``CodeGenerationError``: code could not be generated, compiled or loaded.
    ``BudgetError``: a request costs more than the budget in force (:mod:`lindstedt.limits`).
    ``Cancelled``: a request was cancelled at one of its checkpoints (:mod:`lindstedt.limits`).
"""

from __future__ import annotations

__all__ = [
    "LindstedtError",
    "ProblemError",
    "ParameterError",
    "UnsupportedNonlinearityError",
    "OrderError",
    "ResonanceError",
    "ConvergenceError",
    "CodeGenerationError",
    "BudgetError",
    "Cancelled",
]


class LindstedtError(Exception):
    """Base class of every error raised by lindstedt."""


class ProblemError(LindstedtError, ValueError):
    """The problem definition is invalid (bad a0, omega0, f, matrices...)."""


class ParameterError(ProblemError):
    """A parameter is undeclared, declared but unused, or has no value where one is needed."""


class UnsupportedNonlinearityError(ProblemError):
    """The nonlinearity f(u) is of a kind that no available method handles."""


class OrderError(LindstedtError, ValueError):
    """An expansion order is negative, not an integer, or absurdly large."""


class ResonanceError(LindstedtError):
    """An internal resonance (a small divisor that is exactly zero) was met."""


class ConvergenceError(LindstedtError):
    """A numerical method (quadrature, series, Newton) failed to converge."""


class CodeGenerationError(LindstedtError):
    """The generated code could not be generated, compiled or loaded (e.g. an unknown target language)."""


class BudgetError(LindstedtError):
    """A request costs more than the budget in force (:mod:`lindstedt.limits`): refused before it starts (its
    :attr:`estimate` above the budget), or stopped at a checkpoint once the budget was spent."""

    def __init__(self, message: str, estimate: object = None, up_front: bool = False):
        super().__init__(message)
        self.estimate = estimate
        self.up_front = up_front

    def __reduce__(self) -> tuple:
        return type(self), (self.args[0], self.estimate, self.up_front)


class Cancelled(LindstedtError):
    """A request stopped at a checkpoint because the cancel event of its ``lindstedt.limits.budget`` block was set."""
