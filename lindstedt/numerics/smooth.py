"""Reference flow of a smooth oscillator u'' + ω0² u + ε f(u) = 0 by DOP853 (scipy), for f without kinks.

The fallback ground truth where :class:`~lindstedt.numerics.ExactFlow` (piecewise-linear f,
closed-form arcs) does not apply: ``scipy.integrate.solve_ivp`` with method DOP853 at tight
tolerances, returning the same :class:`~lindstedt.numerics.FlowResult`.
"""

from __future__ import annotations

import math
from typing import Any, Callable, Sequence

import numpy as np
import sympy

from .._errors import ProblemError
from .._precision import locked
from .flow import FlowResult, SwitchEvent, _as_time

__all__ = ["smooth_flow"]


# --------------------------------------------------------------------------- #
# smooth fallback
# --------------------------------------------------------------------------- #
@locked  # parsing and lambdify: sympy
def _as_scalar_function(f: Any) -> Callable[[float], float]:
    if isinstance(f, str):
        from ..problems.parsing import parse_expression

        u = sympy.Symbol("u", real=True)
        f = parse_expression(f, symbols={"u": u}, what="f")
    if isinstance(f, sympy.Basic):
        symbols = sorted(f.free_symbols, key=str)
        if len(symbols) > 1:
            raise ProblemError(
                f"f = {f} has the symbols {[str(s) for s in symbols]}; substitute every parameter so only u is left"
            )
        function = sympy.lambdify(symbols[0] if symbols else sympy.Symbol("u"), f, modules="math")
        return lambda u: float(function(u))
    if callable(f):
        return f
    raise ProblemError(f"f must be a callable f(u), a sympy expression or a string, got {type(f).__name__}")


def smooth_flow(
    f: Any,
    omega0: float,
    epsilon: float,
    u0: float,
    v0: float,
    t_end: float,
    rtol: float = 1e-12,
    atol: float = 1e-14,
    *,
    events: Sequence[Callable[[float, float], float]] | None = None,
) -> FlowResult:
    """Integrate ``u'' + ω0² u + ε f(u) = 0`` with DOP853 (dense output and events).

    The fallback for nonlinearities without a closed-form flow.  It is accurate
    to about ``rtol`` for smooth ``f``; a kink in ``f`` (such as ``(u)_+``)
    costs step rejections and accuracy — use :class:`ExactFlow` for those.

    Parameters
    ----------
    f : callable, sympy expression or str
        The nonlinearity ``f(u)``.
    omega0, epsilon : float
        Linear frequency and small parameter.
    u0, v0 : float
        Initial displacement and velocity.
    t_end : float
        Final time (≥ 0).
    rtol, atol : float
        Tolerances of ``solve_ivp``.
    events : sequence of callables g(u, v), optional
        Functions whose zero crossings are recorded (``SwitchEvent.spring`` is
        the index, ``direction`` the sign of dg/dt).  Default: ``u`` (index 0)
        and ``v`` (index 1, the turning points).  The initial point is not
        recorded as a crossing.

    Returns
    -------
    FlowResult
        With ``method = "DOP853"``, ``n_evaluations`` the number of
        right-hand-side evaluations and ``state(t)`` the dense output.

    Examples
    --------
    >>> result = smooth_flow(lambda u: u**3, 1.0, 0.0, 1.0, 0.0, 2 * np.pi)
    >>> result.success, [e.spring for e in result.events][:3]
    (True, [0, 1, 0])
    >>> abs(float(result.state(np.pi)[0][0]) + 1.0) < 1e-10
    True
    """
    function = _as_scalar_function(f)
    try:
        omega0 = float(omega0)
        epsilon = float(epsilon)
        u0 = float(u0)
        v0 = float(v0)
    except (TypeError, ValueError):
        raise ProblemError("omega0, epsilon, u0 and v0 must be real numbers") from None
    if not all(math.isfinite(value) for value in (omega0, epsilon, u0, v0)):
        raise ProblemError("omega0, epsilon, u0 and v0 must be finite")
    if omega0 <= 0.0:
        raise ProblemError(f"omega0 must be positive, got {omega0}")
    t_end = _as_time(t_end, "t_end")
    if not (rtol > 0 and atol > 0):
        raise ProblemError(f"rtol and atol must be positive, got rtol={rtol}, atol={atol}")
    try:
        initial_force = float(function(u0))
    except Exception as error:  # noqa: BLE001 - report any failure of user code
        raise ProblemError(f"f(u0) failed: {error!r}; f must accept a float") from None
    if not math.isfinite(initial_force):
        raise ProblemError(f"f(u0) = {initial_force} is not finite")
    omega2 = omega0 * omega0

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        return [y[1], -omega2 * y[0] - epsilon * function(y[0])]

    event_functions = list(events) if events is not None else [lambda u, v: u, lambda u, v: v]
    wrapped = [(lambda t, y, g=g: g(y[0], y[1])) for g in event_functions]
    if t_end == 0.0:
        final = np.array([u0, v0])

        def evaluator(times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            return np.full((times.size, 1), u0), np.full((times.size, 1), v0)

        return FlowResult(True, "t_end = 0", "DOP853", 0.0, final[:1], final[1:], (), 0, 0, 1, 0, 0, (), evaluator)
    from scipy.integrate import solve_ivp  # here, not at module level: import lindstedt stays light
    solution = solve_ivp(
        rhs, (0.0, t_end), [u0, v0], method="DOP853", rtol=rtol, atol=atol, dense_output=True, events=wrapped or None
    )
    recorded: list[SwitchEvent] = []
    if wrapped:
        for index, (times, states) in enumerate(zip(solution.t_events, solution.y_events)):
            g = event_functions[index]
            for time, y in zip(times, states):
                if time <= 0.0:  # the initial point is not a crossing
                    continue
                derivative = np.asarray(rhs(time, y))
                step = 1e-7 * (1.0 + float(np.max(np.abs(y)))) / (1.0 + float(np.max(np.abs(derivative))))
                slope = g(*(y + step * derivative)) - g(*(y - step * derivative))
                recorded.append(SwitchEvent(float(time), index, int(np.sign(slope))))
    recorded.sort(key=lambda event: (event.time, event.spring))
    dense_solution = solution.sol
    reached = float(solution.t[-1])

    def evaluator(times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        values = dense_solution(times)
        return values[0][:, None], values[1][:, None]

    return FlowResult(
        success=bool(solution.success),
        message=str(solution.message),
        method="DOP853",
        t_final=reached,
        position=np.array([solution.y[0, -1]]),
        velocity=np.array([solution.y[1, -1]]),
        events=tuple(recorded),
        n_switches=0,
        n_root_solves=len(recorded),
        n_arcs=1,
        n_evaluations=int(solution.nfev),
        n_decompositions=0,
        contact_states=(),
        _evaluator=evaluator,
    )
