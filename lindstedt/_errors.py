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
