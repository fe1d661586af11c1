"""Plots of expansions against the truth, on matplotlib (optional: ``pip install 'lindstedt[plot]'``).

Each function draws one standard figure of the field on a matplotlib ``Axes`` (a new figure when ``ax`` is
None) and returns the Axes; the data drawn are those of the package's results and independent references:

* :func:`backbone` — the frequency ω(a0) of ``u'' + ω0² u + ε f(u) = 0`` at orders 1…N of the Lindstedt–Poincaré
  series against the exact frequency from the energy integral
  (:func:`lindstedt.references.conservative_frequency`);
* :func:`waveform` — the truncated expansion u_N(t) against the exact flow
  (:func:`lindstedt.validate.reference_solution`: closed-form arcs for piecewise-linear f, DOP853 otherwise);
* :func:`spectrum` — line spectra (:class:`lindstedt.Spectrum`), e.g. of the expansion and of the exact
  solution side by side (seed fig. 2);
* :func:`convergence` — max error against ε on log-log axes with the fitted slope
  (:class:`lindstedt.validate.ConvergenceFit`);
* :func:`error_over_time` — ``|u_N(t) − u(t)|`` against t for expansions of several orders (the exact flow as u);
* :func:`frequency_response` — forced responses (:class:`lindstedt.FrequencyResponse`): amplitude against Ω,
  stable solid, unstable dashed, folds / period doublings / Neimark–Sacker points marked, with the
  multiple-scales curve (:class:`lindstedt.FrequencyResponseCurve`) and its backbone overlaid;
* :func:`branch` — an NNM branch (:class:`lindstedt.NNMBranch`): frequency against the continuation parameter,
  stable points solid, unstable dashed, jumps across internal-resonance tongues marked;
* :func:`nnm_orbit` — one NNM (:class:`lindstedt.NNMResult`) over a period of the exact flow: the orbit in
  configuration space (X_i, X_j) and the line spectrum of X_i (seed figs. 3–8).

Examples
--------
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> import lindstedt, lindstedt.plot
>>> e = lindstedt.expand("Max(0, u)", order=2, a0=1, omega0=1)
>>> ax = lindstedt.plot.waveform(e, 0.1, [0.0, 5.0, 10.0])
>>> [line.get_label() for line in ax.get_lines()]
['expansion, order 2', 'exact flow']
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ._errors import LindstedtError

__all__ = ["backbone", "branch", "convergence", "error_over_time", "frequency_response", "nnm_orbit", "spectrum",
           "waveform"]


def _pyplot() -> Any:
    try:
        import matplotlib.pyplot as plt
    except ImportError as error:
        raise LindstedtError("plotting needs matplotlib: pip install 'lindstedt[plot]'") from error
    return plt


def _axes(ax: Any) -> Any:
    if ax is None:
        _, ax = _pyplot().subplots()
    return ax


def backbone(
    f: Any,
    amplitudes: Sequence[float],
    epsilon: float,
    *,
    order: int = 3,
    omega0: float = 1,
    params: dict[str, Any] | None = None,
    reference: bool = True,
    executor: Any = None,
    progress: Any = None,
    ax: Any = None,
) -> Any:
    """ω(a0) at ε from the series truncated at orders 1…``order``, and the exact frequency
    (the data of :func:`lindstedt.validate.backbone`).

    Parameters
    ----------
    f : str or sympy expression
        The nonlinearity, as for :func:`lindstedt.expand` (with ``params`` given values).
    amplitudes : sequence of float
        Release amplitudes a0 (u(0) = a0, u'(0) = 0).
    epsilon : float
        The small parameter.
    order : int
        Highest order drawn (one curve per order 1…order).
    reference : bool
        Also draw the exact frequency (energy-integral quadrature, 20 digits).
    executor, progress
        Run the amplitudes on an executor, with progress (see :func:`lindstedt.validate.backbone`).

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import lindstedt.plot
    >>> ax = lindstedt.plot.backbone("u**3", [0.5, 1.0], 0.1, order=2)
    >>> [line.get_label() for line in ax.get_lines()]
    ['order 1', 'order 2', 'exact']
    """
    from lindstedt.validate import backbone as backbone_sweep

    ax = _axes(ax)
    curve = backbone_sweep(f, amplitudes, epsilon, order=order, omega0=omega0, params=params, reference=reference,
                           executor=executor, progress=progress)
    if not curve.success:
        raise LindstedtError(f"the backbone failed: {curve.message}")
    for n, values in zip(curve.orders, curve.series_frequencies):
        ax.plot(curve.amplitudes, values, label=f"order {n}")
    if reference:
        ax.plot(curve.amplitudes, curve.exact_frequencies, "k--", label="exact")
    ax.set_xlabel("amplitude $a_0$")
    ax.set_ylabel(r"frequency $\omega$")
    ax.set_title(rf"backbone at $\varepsilon = {epsilon:g}$")
    ax.legend()
    return ax


def waveform(expansion: Any, epsilon: float, t: Sequence[float], *, values: dict[str, Any] | None = None,
             reference: bool = True, ax: Any = None) -> Any:
    """The expansion's displacement u_N(t) at ε and, with ``reference``, the exact flow's.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import lindstedt, lindstedt.plot
    >>> ax = lindstedt.plot.waveform(lindstedt.expand("u**3", order=1, a0=1, omega0=1), 0.1, [0, 1, 2], reference=False)
    >>> ax.get_lines()[0].get_label()
    'expansion, order 1'
    """
    from lindstedt.validate import reference_solution

    ax = _axes(ax)
    times = np.asarray(t, dtype=float)
    ax.plot(times, expansion.displacement(times, epsilon, values=values), label=f"expansion, order {expansion.order}")
    if reference:
        exact = reference_solution(expansion, epsilon, times, values=values)
        if not exact.success:
            raise LindstedtError(f"the exact flow failed: {exact.message}")
        ax.plot(times, exact.displacement, "k--", label="exact flow")
    ax.set_xlabel("time $t$")
    ax.set_ylabel("displacement $u$")
    ax.set_title(rf"$\varepsilon = {epsilon:g}$")
    ax.legend()
    return ax


def spectrum(spectra: Any, *, labels: Sequence[str] | None = None, ax: Any = None) -> Any:
    """Line spectra (one :class:`lindstedt.Spectrum` or several), amplitude on a log scale against ω.

    Several spectra are drawn side by side (slightly offset in ω) so that their lines can be compared.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import lindstedt, lindstedt.plot
    >>> from lindstedt.validate import expansion_spectrum
    >>> e = lindstedt.expand("Max(0, u)", order=2, a0=1, omega0=1)
    >>> ax = lindstedt.plot.spectrum(expansion_spectrum(e, 0.1), labels=["expansion"])
    >>> ax.get_yscale()
    'log'
    """
    ax = _axes(ax)
    spectra = [spectra] if not isinstance(spectra, (list, tuple)) else list(spectra)
    labels = list(labels) if labels is not None else [f"spectrum {i + 1}" for i in range(len(spectra))]
    for index, (item, label) in enumerate(zip(spectra, labels)):
        if not item.success:
            raise LindstedtError(f"spectrum {label!r} failed: {item.message}")
        frequencies = np.asarray(item.angular_frequencies, dtype=float)
        amplitudes = np.asarray(item.amplitudes, dtype=float)
        shown = amplitudes > 0
        offset = 0.08 * item.fundamental * (index - (len(spectra) - 1) / 2)
        ax.vlines(frequencies[shown] + offset, np.min(amplitudes[shown]) / 10, amplitudes[shown], colors=f"C{index}", label=label)
    ax.set_yscale("log")
    ax.set_xlabel(r"angular frequency $\omega$")
    ax.set_ylabel("amplitude")
    ax.legend()
    return ax


def convergence(fits: Any, *, labels: Sequence[str] | None = None, ax: Any = None) -> Any:
    """Max error against ε (log-log) for one or several :class:`~lindstedt.validate.ConvergenceFit`, with the fitted line.

    Each legend entry states the fitted slope and the expected one (N + 1 for a simple contact).

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import lindstedt, lindstedt.plot
    >>> from lindstedt.validate import fitted_convergence_order
    >>> fit = fitted_convergence_order(lindstedt.expand("u**3", order=1, a0=1, omega0=1), [0.01, 0.02, 0.04])
    >>> ax = lindstedt.plot.convergence(fit)
    >>> ax.get_xscale(), ax.get_yscale()
    ('log', 'log')
    """
    ax = _axes(ax)
    fits = [fits] if not isinstance(fits, (list, tuple)) else list(fits)
    labels = list(labels) if labels is not None else [None] * len(fits)
    for index, (fit, label) in enumerate(zip(fits, labels)):
        epsilons, errors = np.asarray(fit.epsilons, dtype=float), np.asarray(fit.max_errors, dtype=float)
        text = f"slope {fit.slope:.2f}" + (f" (expected {fit.expected_slope:g})" if fit.expected_slope is not None else "")
        ax.loglog(epsilons, errors, "o", color=f"C{index}", label=f"{label}: {text}" if label else text)
        ax.loglog(epsilons, np.exp(fit.intercept) * epsilons**fit.slope, "-", color=f"C{index}")
    ax.set_xlabel(r"$\varepsilon$")
    ax.set_ylabel(r"max error on $[0, T_\varepsilon]$")
    ax.legend()
    return ax


def error_over_time(expansions: Any, epsilon: float, t: Sequence[float], *, values: dict[str, Any] | None = None,
                    ax: Any = None) -> Any:
    """``|u_N(t) − u(t)|`` against t (log scale) for one or several expansions of one problem, u the exact flow.

    The reference is :func:`lindstedt.validate.reference_solution` (closed-form arcs for piecewise-linear f,
    DOP853 otherwise), computed once; each expansion is labelled by its order.  Errors below 1e-16 are drawn at
    1e-16 (the log scale has no zero).

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import lindstedt, lindstedt.plot
    >>> orders = [lindstedt.expand("Max(0, u)", order=n, a0=1, omega0=1) for n in (0, 1)]
    >>> ax = lindstedt.plot.error_over_time(orders, 0.1, [0.0, 5.0, 10.0])
    >>> [line.get_label() for line in ax.get_lines()], ax.get_yscale()
    (['order 0', 'order 1'], 'log')
    """
    from lindstedt.validate import reference_solution

    ax = _axes(ax)
    expansions = [expansions] if not isinstance(expansions, (list, tuple)) else list(expansions)
    if not expansions:
        raise LindstedtError("error_over_time needs at least one expansion")
    times = np.asarray(t, dtype=float)
    exact = reference_solution(expansions[-1], epsilon, times, values=values)
    if not exact.success:
        raise LindstedtError(f"the exact flow failed: {exact.message}")
    for expansion in expansions:
        error = np.abs(expansion.displacement(times, epsilon, values=values) - exact.displacement)
        ax.semilogy(times, np.maximum(error, 1e-16), label=f"order {expansion.order}")
    ax.set_xlabel("time $t$")
    ax.set_ylabel(r"$|u_N(t) - u(t)|$")
    ax.set_title(rf"error against the exact flow, $\varepsilon = {epsilon:g}$")
    ax.legend()
    return ax


_BIFURCATION_MARKERS = {"fold": ("o", "fold"), "period-doubling": ("s", "period doubling"),
                        "neimark-sacker": ("D", "Neimark–Sacker")}


def frequency_response(responses: Any, *, curve: Any = None, epsilon: float | None = None, dof: int = 0,
                       ax: Any = None) -> Any:
    """Forced responses: the peak amplitude ``max_t |X_dof|`` against Ω; stable solid, unstable dashed, bifurcations marked.

    Parameters
    ----------
    responses : FrequencyResponse or a sequence of them
        Branches from :func:`lindstedt.frequency_response` (and :func:`lindstedt.switch_period_doubling`).
    curve : FrequencyResponseCurve, optional
        The multiple-scales prediction (:func:`lindstedt.frequency_response_curve`) drawn over the same Ω
        range with its backbone, at ``epsilon`` (default: the first response's ε).
    dof : int
        The degree of freedom drawn (0-based).

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import lindstedt, lindstedt.plot
    >>> problem = lindstedt.ForcedOscillator("u**3", omega0=1, zeta="1/20", forcing=1)
    >>> response = lindstedt.frequency_response(problem, 0.9, 1.3, epsilon=0.2)
    >>> ax = lindstedt.plot.frequency_response(response, curve=lindstedt.frequency_response_curve(problem))
    >>> sorted({line.get_label() for line in ax.get_lines() if not line.get_label().startswith("_")})
    ['backbone (multiple scales)', 'fold', 'multiple scales, order 1', 'stable', 'unstable']
    """
    ax = _axes(ax)
    responses = [responses] if not isinstance(responses, (list, tuple)) else list(responses)
    if not responses:
        raise LindstedtError("frequency_response needs at least one FrequencyResponse")
    drawn: set[str] = set()

    def label(text: str) -> str | None:
        if text in drawn:
            return None
        drawn.add(text)
        return text

    parameters = {response.parameter for response in responses}
    if len(parameters) != 1:
        raise LindstedtError("the responses drawn together must follow the same parameter (all 'frequency' or all 'forcing')")
    parameter = parameters.pop()
    for response in responses:
        if len(response) and not 0 <= dof < len(response.points[0].amplitude):
            raise LindstedtError(f"dof must be 0 … {len(response.points[0].amplitude) - 1}, got {dof!r}")
    if curve is not None and (parameter != "frequency" or any(p.forcing_scale != 1.0 for r in responses for p in r.points[:1])):
        raise LindstedtError("the multiple-scales curve is drawn against Ω at the problem's own load: draw responses "
                             "with parameter='frequency' and forcing_scale=1, or leave curve out")
    for index, response in enumerate(responses):
        if not len(response):
            continue
        omega = np.asarray(response.parameter_values, dtype=float)
        peak = np.asarray(response.amplitudes, dtype=float).reshape(len(omega), -1)[:, dof]
        stable = np.asarray(response.stable, dtype=bool)
        colour = f"C{index}"
        for k in range(len(omega) - 1):
            both = stable[k] and stable[k + 1]
            ax.plot(omega[k:k + 2], peak[k:k + 2], "-" if both else "--", color=colour,
                    label=label("stable" if both else "unstable"))
        for event in response.bifurcations:
            marker, text = _BIFURCATION_MARKERS.get(event.kind, ("x", event.kind))
            ax.plot([event.frequency if parameter == "frequency" else event.forcing_scale], [np.asarray(event.amplitude, dtype=float).reshape(-1)[dof]], marker,
                    color="k", markerfacecolor="none", label=label(text))
    if curve is not None:
        if epsilon is None and responses[0].epsilon is None:
            raise LindstedtError("give epsilon= for the multiple-scales curve (the responses do not say theirs)")
        eps = float(epsilon if epsilon is not None else responses[0].epsilon)
        low = min(float(np.min(r.parameter_values)) for r in responses if len(r))
        high = max(float(np.max(r.parameter_values)) for r in responses if len(r))
        grid = np.linspace(low, high, 400)
        points = []
        for w in grid:
            try:
                points += [(w, a) for a in curve.displacement_maxima(w, eps)]
            except LindstedtError:  # Ω outside the primary resonance the method covers: not drawn there
                continue
        if points:
            w_values, a_values = zip(*points)
            ax.plot(w_values, a_values, ".", markersize=2, color="0.45", label=label(f"multiple scales, order {curve.order}"))
            top = max(a_values)
            amplitudes = np.linspace(top / 200, top, 200)
            ax.plot([curve.backbone(a, eps) for a in amplitudes], amplitudes, ":", color="0.3",
                    label=label("backbone (multiple scales)"))
    ax.set_xlabel(r"forcing frequency $\Omega$" if parameter == "frequency" else "load scale $s$ (the load is $s\\,\\varepsilon F$)")
    ax.set_ylabel(rf"$\max_t |X_{{{dof + 1}}}|$" if dof else r"$\max_t |u|$")
    first = responses[0]
    ax.set_title(rf"frequency response, $\varepsilon = {first.epsilon:g}$" if first.epsilon is not None else "frequency response")
    ax.legend()
    return ax


def branch(nnm_branch: Any, *, ax: Any = None) -> Any:
    """An NNM branch: frequency against the continuation parameter; stable solid, unstable dashed, jumps dotted.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import lindstedt, lindstedt.plot
    >>> system = lindstedt.UnilateralSystem.one_dof(1)
    >>> b = lindstedt.continue_nnm(system, 1, start=0.0, stop=0.5, modal_amplitude=1.0)
    >>> ax = lindstedt.plot.branch(b)
    >>> ax.get_xlabel()
    'epsilon'
    """
    ax = _axes(ax)
    values = np.asarray(nnm_branch.parameter_values, dtype=float)
    frequencies = np.array([point.frequency for point in nnm_branch.points], dtype=float)
    stable = np.array([bool(point.stable) for point in nnm_branch.points])
    jumps = set(getattr(nnm_branch, "jumps", ()))
    drawn: set[str] = set()
    for k in range(len(values) - 1):
        if k in jumps:
            style, label = ":", "jump (resonance tongue)"
        elif stable[k] and stable[k + 1]:
            style, label = "-", "stable"
        else:
            style, label = "--", "unstable"
        ax.plot(values[k : k + 2], frequencies[k : k + 2], style, color="C0", label=None if label in drawn else label)
        drawn.add(label)
    if len(values) == 1:
        ax.plot(values, frequencies, "o", color="C0", label="stable" if stable[0] else "unstable")
    ax.set_xlabel(nnm_branch.parameter)
    ax.set_ylabel(r"frequency $\omega$")
    ax.set_title(f"{'complete' if nnm_branch.success else 'stopped'}: {len(values)} points")
    ax.legend()
    return ax


def nnm_orbit(point: Any, *, dofs: tuple[int, int] = (0, 1), samples: int = 512, axes: Any = None) -> tuple[Any, Any]:
    """One NNM over one period of the exact flow: (X_i, X_j) in configuration space, and the spectrum of X_i.

    Parameters
    ----------
    point : NNMResult
        A converged NNM (:func:`lindstedt.nnm_point`, a branch's point).
    dofs : (int, int)
        0-based degrees of freedom on the two axes of the configuration plot.
    samples : int
        Samples of the period (the flow is evaluated in closed form at each).
    axes : (Axes, Axes), optional
        Where to draw; a new figure with two panels by default.

    Returns
    -------
    (Axes, Axes)
        The configuration-space panel and the spectrum panel.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import lindstedt, lindstedt.plot
    >>> point = lindstedt.nnm_point(lindstedt.UnilateralSystem.chain(2, [(0, 0.1)]), 0.2, 1, modal_amplitude=1.0)
    >>> orbit, lines = lindstedt.plot.nnm_orbit(point)
    >>> orbit.get_xlabel(), lines.get_yscale()
    ('$X_{1}$', 'log')
    """
    import lindstedt

    if not point.success:
        raise LindstedtError(f"the NNM did not converge ({point.message}); plot a converged point")
    if axes is None:
        _, axes = _pyplot().subplots(1, 2, figsize=(10, 4))
    orbit, lines = axes
    times = np.linspace(0.0, point.period, samples, endpoint=False)
    exact = point.system.ramp_equivalent  # unilateral springs or piecewise-linear laws: the exact flow
    if exact is not None:
        flow = lindstedt.ExactFlow(exact[0], point.epsilon).solve(point.release_position, point.release_velocity,
                                                                   point.period)
        if not flow.success:
            raise LindstedtError(f"the exact flow failed: {flow.message}")
        positions, _ = flow.state(times)
    else:  # any other law: DOP853, sampled in the same run
        _, states, _ = lindstedt.numerics.SmoothForcedFlow(point.system, point.epsilon).run(
            np.r_[point.release_position, point.release_velocity], point.period, times)
        positions = states[:, :point.system.n_dof]
    first, second = dofs
    orbit.plot(positions[:, first], positions[:, second], label=f"mode {point.mode}, ε = {point.epsilon:g}")
    orbit.set_xlabel(f"$X_{{{first + 1}}}$")
    orbit.set_ylabel(f"$X_{{{second + 1}}}$")
    orbit.set_title(f"NNM in configuration space, ω = {point.frequency:.6g}")
    orbit.legend()
    line_spectrum = lindstedt.spectrum(positions[:, first], point.period, periods=1)
    spectrum([line_spectrum], labels=[f"$X_{{{first + 1}}}$"], ax=lines)
    lines.set_title("line spectrum over one period")
    return orbit, lines
