"""The exact event-driven forced flow (lindstedt.numerics.forced_flow) against independent references.

References: the textbook solution of the linear damped forced oscillator (transient + steady state),
scipy's DOP853 restarted at located events, central finite differences of the flow itself for the
analytic sensitivities, the textbook Floquet multipliers exp(λT) of a linear oscillator, and an
independent product of scipy.linalg.expm transition matrices and saltation matrices.
"""

import json
import math

import numpy as np
import pytest
import scipy.linalg
from scipy.integrate import solve_ivp

from lindstedt import ParameterError, ProblemError, ResonanceError, UnsupportedNonlinearityError
from lindstedt import ForcedOscillator, ForcedSystem, UnilateralSystem
from lindstedt.numerics import ForcedFlow, PeriodMap


def textbook(w0, zeta, load, Om, u0, v0, t):
    """u'' + 2ζω0 u' + ω0² u = load cos Ωt, u(0) = u0, u'(0) = v0 (under-, critically or over-damped)."""
    H = load / (w0**2 - Om**2 + 2j * zeta * w0 * Om)
    up, vp = (H * np.exp(1j * Om * t)).real, (1j * Om * H * np.exp(1j * Om * t)).real
    C1, D = u0 - H.real, v0 - (1j * Om * H).real
    if zeta == 1:
        C2 = D + w0 * C1
        return up + (C1 + C2 * t) * np.exp(-w0 * t), vp + (C2 - w0 * (C1 + C2 * t)) * np.exp(-w0 * t)
    lam1, lam2 = np.roots([1, 2 * zeta * w0, w0**2]).astype(complex)  # distinct roots
    a2 = (D - lam1 * C1) / (lam2 - lam1)
    a1 = C1 - a2
    u = (a1 * np.exp(lam1 * t) + a2 * np.exp(lam2 * t)).real
    v = (a1 * lam1 * np.exp(lam1 * t) + a2 * lam2 * np.exp(lam2 * t)).real
    return up + u, vp + v


# ----------------------------------------------------------------------------- linear reference
@pytest.mark.parametrize("zeta", [0.02, 0.3, 1.0, 2.5])  # 1.0: critical damping, the expm fallback
def test_linear_damped_oscillator_against_textbook(zeta):
    eps, F, w0, Om = 0.5, 2.0, 1.5, 1.1
    flow = ForcedFlow(ForcedOscillator("Max(0, u - 100)", omega0=w0, zeta=zeta, forcing=F), eps)
    result = flow.solve([0.3, -0.2], 40.0, Om)
    assert result.success and result.n_switches == 0
    t = np.linspace(0.0, 40.0, 401)
    X, V = result.state(t)
    u, v = textbook(w0, zeta, eps * F, Om, 0.3, -0.2, t)
    assert np.max(np.abs(X[:, 0] - u)) < 1e-13
    assert np.max(np.abs(V[:, 0] - v)) < 1e-13


def test_linear_system_one_dof_period_map_and_floquet():
    w0, zeta, F, eps, Om = 2.0, 0.05, 3.0, 0.4, 1.7
    flow = ForcedFlow(ForcedSystem.one_dof(w0, zeta=zeta, forcing=F, b=50), eps)
    assert isinstance(flow, PeriodMap)
    T = 2 * math.pi / Om
    out = flow.period_map([0.1, 0.2], Om, periods=2)
    u, v = textbook(w0, zeta, eps * F, Om, 0.1, 0.2, 2 * T)
    assert abs(out.state[0] - u) < 1e-13 and abs(out.state[1] - v) < 1e-13
    # Floquet multipliers of a linear oscillator: exp(λ kT), λ = −ζω0 ± iω0√(1 − ζ²)
    lam = -zeta * w0 + 1j * w0 * math.sqrt(1 - zeta**2)
    expected = np.sort_complex(np.exp(np.array([lam, lam.conjugate()]) * 2 * T))
    assert np.max(np.abs(np.sort_complex(np.linalg.eigvals(out.d_state)) - expected)) < 1e-14


# ----------------------------------------------------------------------------- DOP853 reference
def dop853_piecewise(slopes, intercepts, breakpoints, w0, zeta, load, Om, z0, t_end):
    """u'' + 2ζω0u' + ω0²u + ε f(u) = load cos Ωt with ε f = slope_j u + intercept_j on interval j, by DOP853
    restarted at each located crossing of a breakpoint (the field of each interval is smooth)."""
    def interval(u, v):
        return int(sum(u > b or (u == b and v > 0) for b in breakpoints))
    t, z = 0.0, np.array(z0, dtype=float)
    j = interval(*z)
    crossings = 0
    while t < t_end:
        def rhs(s, y, j=j):
            return [y[1], -2 * zeta * w0 * y[1] - w0**2 * y[0] - slopes[j] * y[0] - intercepts[j] + load * math.cos(Om * s)]
        events = []
        for i, b in enumerate(breakpoints):
            def event(s, y, b=b):
                return y[0] - b
            event.terminal = True
            event.direction = -1 if i < j else 1  # only leaving the interval (not the breakpoint just crossed)
            events.append(event)
        sol = solve_ivp(rhs, (t, t_end), z, method="DOP853", rtol=1e-13, atol=1e-15, events=events)
        t, z = sol.t[-1], sol.y[:, -1]
        if sol.status == 1:
            crossings += 1
            j = j + 1 if z[1] > 0 else j - 1
    return z, crossings


def dop853_system(forced, eps, Om, z0, t_end):
    """M X'' + C X' + K X + ε W (A X − b)_+ = ε P cos Ωt by DOP853, restarted at each located spring switch."""
    system = forced.system
    n, m = forced.n_dof, system.n_springs
    Minv = np.linalg.inv(system.M)
    t, z = 0.0, np.array(z0, dtype=float)
    flags = [bool(system.A[i] @ z[:n] > system.b[i]) for i in range(m)]
    switches = 0
    while t < t_end:
        mask = np.array(flags, dtype=bool)
        K_S = system.K + eps * system.W[:, mask] @ system.A[mask]
        r_S = eps * system.W[:, mask] @ system.b[mask]

        def rhs(s, y, K_S=K_S, r_S=r_S):
            return np.concatenate([y[n:], Minv @ (r_S - K_S @ y[:n] - forced.C @ y[n:] + eps * forced.P * math.cos(Om * s))])
        events = []
        for i in range(m):
            def event(s, y, i=i):
                return system.A[i] @ y[:n] - system.b[i]
            event.terminal = True
            event.direction = -1 if flags[i] else 1
            events.append(event)
        sol = solve_ivp(rhs, (t, t_end), z, method="DOP853", rtol=1e-13, atol=1e-15, events=events)
        t, z = sol.t[-1], sol.y[:, -1]
        if sol.status == 1:
            for i in range(m):
                if sol.t_events[i].size:
                    flags[i] = not flags[i]
                    switches += 1
    return z, switches


def test_two_dof_chain_against_dop853():
    system = UnilateralSystem.chain(2, [(0, "1/10"), (1, "1/20", -1)])
    forced = ForcedSystem(system, load=[1, "1/2"], rayleigh=("1/50", "1/100"))
    eps, Om = 1.5, 1.1
    t_end = 10 * 2 * math.pi / Om
    z_ref, switches = dop853_system(forced, eps, Om, [0.2, -0.1, 0.0, 0.3], t_end)
    result = ForcedFlow(forced, eps).solve([0.2, -0.1, 0.0, 0.3], t_end, Om)
    assert result.success and result.n_switches == switches >= 10
    tolerance = 100 * max(_reference_tolerance(), 1e-13) * max(1.0, switches / 20)  # as for one dof
    assert np.max(np.abs(np.concatenate([result.position, result.velocity]) - z_ref)) < tolerance


def _reference_tolerance():
    """DOP853's own global error over the horizon, measured on the linear problem against the textbook."""
    w0, zeta, load, Om = 1.0, 0.05, 0.5, 1.3
    z, _ = dop853_piecewise([0.0], [0.0], [], w0, zeta, load, Om, [0.0, 0.0], 20 * 2 * math.pi / Om)
    u, v = textbook(w0, zeta, load, Om, 0.0, 0.0, 20 * 2 * math.pi / Om)
    return max(abs(z[0] - u), abs(z[1] - v))


@pytest.mark.parametrize("kind", ["system", "oscillator", "jump", "two-sided"])
def test_piecewise_linear_against_dop853(kind):
    w0, zeta, F, eps, Om, gap = 1.0, 0.05, 1.0, 0.5, 1.3, 0.2
    breakpoints = [gap]
    if kind == "two-sided":  # three breakpoints, a jump at the last one, no damping
        zeta, eps, Om, c = 0.0, 0.7, 1.25, 0.1
        law = "Max(0, u - 1/5) + Min(0, u + 1/5) + 1/10*sign(u - 1/2)"
        flow = ForcedFlow(ForcedOscillator(law, omega0=w0, zeta=zeta, forcing=F), eps)
        breakpoints = [-0.2, 0.2, 0.5]
        slopes, intercepts = [eps, 0.0, eps, eps], [eps * (0.2 - c), -eps * c, -eps * (0.2 + c), -eps * (0.2 - c)]
    elif kind == "system":
        flow = ForcedFlow(ForcedSystem.one_dof(w0, zeta=zeta, forcing=F, b=gap), eps)
        slopes, intercepts, c = [0.0, eps], [0.0, -eps * gap], 0.0
    elif kind == "oscillator":
        flow = ForcedFlow(ForcedOscillator("Max(0, u - b)", omega0=w0, zeta=zeta, forcing=F, params={"b": gap}), eps)
        slopes, intercepts, c = [0.0, eps], [0.0, -eps * gap], 0.0
    else:  # a force that jumps by c at the breakpoint
        c = 0.1
        flow = ForcedFlow(
            ForcedOscillator("Max(0, u - b) + c*Heaviside(u - b)", omega0=w0, zeta=zeta, forcing=F, params={"b": gap, "c": c}), eps
        )
        slopes, intercepts = [0.0, eps], [0.0, eps * (c - gap)]
    t_end = 20 * 2 * math.pi / Om
    z_ref, crossings = dop853_piecewise(slopes, intercepts, breakpoints, w0, zeta, eps * F, Om, [0.0, 0.0], t_end)
    result = flow.solve([0.0, 0.0], t_end, Om)
    assert result.success
    assert result.n_switches == crossings >= 10
    # DOP853's global error (rtol 1e-13) measured on the linear problem over the same horizon (1e-14, floored at
    # 1e-13), x100 for its restarts at ~40 events located to ~1e-15 and the error growth across the switches:
    # 1e-11 per 20 switches (measured agreement: 1.3e-13 for the spring, 5e-14 with the jump over 40 switches;
    # 5.7e-12 over 184 switches for the two-sided law)
    tolerance = 100 * max(_reference_tolerance(), 1e-13) * max(1.0, crossings / 20)
    assert tolerance < 1e-9
    error = np.max(np.abs(np.concatenate([result.position, result.velocity]) - z_ref))
    assert error < tolerance


# ----------------------------------------------------------------------------- sensitivities
def central_differences(func, x, h):
    columns = []
    for k in range(len(x)):
        step = np.zeros(len(x))
        step[k] = h
        columns.append((func(x + step) - func(x - step)) / (2 * h))
    return np.array(columns).T


# The flow's value carries rounding eta ~ 3e-15 (measured: the differences grow as eta/h below h = 1e-6), and
# central differences err by eta/h + h^2 |d3 Pi|/6 with |d3 Pi| = O(1-10) (measured: ~5e-10 at h = 1e-4); the
# balance h = (3 eta/|d3 Pi|)^(1/3) ~ 1e-5 gives errors ~3e-10 relative (measured 2e-11 to 1.3e-9 over these
# cases), so a relative tolerance of 1e-8 keeps a margin of about 10.
STEP, RTOL = 1e-5, 1e-8


def check_sensitivities(flow, z0, Om, periods=1):
    out = flow.period_map(z0, Om, periods=periods)
    assert out.counters["switches"] >= 2

    def state(z):
        return flow.period_map(z, Om, periods=periods, sensitivity=False).state

    J = central_differences(state, np.asarray(z0, float), STEP)
    dW = central_differences(lambda w: flow.period_map(z0, w[0], periods=periods, sensitivity=False).state, np.array([Om]), STEP)[:, 0]
    dS = central_differences(
        lambda s: flow.period_map(z0, Om, periods=periods, forcing_scale=s[0], sensitivity=False).state, np.array([1.0]), STEP
    )[:, 0]
    scale = 1 + np.max(np.abs(out.d_state))
    assert np.max(np.abs(out.d_state - J)) < RTOL * scale
    assert np.max(np.abs(out.d_frequency - dW)) < RTOL * (1 + np.max(np.abs(dW)))
    assert np.max(np.abs(out.d_forcing - dS)) < RTOL * (1 + np.max(np.abs(dS)))
    return out, J


def test_sensitivities_one_dof():
    flow = ForcedFlow(ForcedSystem.one_dof(1, zeta="1/20", forcing=1, b="1/5"), 0.8)
    check_sensitivities(flow, [0.3, 0.1], 1.3, periods=2)


def test_sensitivities_two_dof_chain_rayleigh():
    system = UnilateralSystem.chain(2, [(0, "1/10"), (1, "1/20", -1)])
    flow = ForcedFlow(ForcedSystem(system, load=[1, "1/2"], rayleigh=("1/50", "1/100")), 1.5)
    check_sensitivities(flow, [0.2, -0.1, 0.0, 0.3], 1.1)


def test_saltation_with_a_force_that_jumps():
    w0, zeta, F, eps, Om, gap, c = 1.0, 0.05, 1.0, 0.5, 1.3, 0.2, 0.3
    problem = ForcedOscillator("Max(0, u - b) + c*Heaviside(u - b)", omega0=w0, zeta=zeta, forcing=F, params={"b": gap, "c": c})
    flow = ForcedFlow(problem, eps)
    z0 = np.array([-0.3, 0.2])
    out, J_fd = check_sensitivities(flow, z0, Om)
    # independent reconstruction: arcs by scipy.linalg.expm between the switch times, with and without saltation
    T = 2 * math.pi / Om
    events = flow.solve(z0, T, Om).events
    A_free = np.array([[0, 1], [-w0**2, -2 * zeta * w0]])
    A_contact = np.array([[0, 1], [-w0**2 - eps, -2 * zeta * w0]])
    times = [0.0] + [e.time for e in events] + [T]
    inside = z0[0] > gap
    product, bare = np.eye(2), np.eye(2)
    for k, (start, end) in enumerate(zip(times, times[1:])):
        arc = scipy.linalg.expm((A_contact if inside else A_free) * (end - start))
        product, bare = arc @ product, arc @ bare
        if k < len(events):
            v = flow.solve(z0, events[k].time, Om).velocity[0]
            # entering: acceleration jumps by −εc; leaving: by +εc;  S = I + Δf nᵀ/(nᵀ f⁻), n = (1, 0), nᵀ f⁻ = u'
            jump = -eps * c if not inside else eps * c
            saltation = np.eye(2) + np.outer([0.0, jump], [1.0, 0.0]) / v
            product = saltation @ product
            inside = not inside
    assert np.max(np.abs(product - out.d_state)) < 1e-10
    # omitting the saltation matrices fails the finite-difference check by far
    assert np.max(np.abs(bare - J_fd)) > 1e3 * RTOL * (1 + np.max(np.abs(J_fd)))


# ----------------------------------------------------------------------------- bad input
def test_bad_input_names_the_fix():
    problem = ForcedSystem.one_dof(1, zeta="1/20", b="1/5")
    flow = ForcedFlow(problem, 0.5)
    with pytest.raises(ParameterError, match="Omega|frequency"):
        flow.period_map([0.0, 0.0], 0.0)
    with pytest.raises(ParameterError, match="frequency"):
        flow.solve([0.0, 0.0], 1.0, -1.0)
    with pytest.raises(ParameterError, match="epsilon"):
        ForcedFlow(problem, -0.1)
    with pytest.raises(ParameterError, match="epsilon"):
        ForcedFlow(problem, float("nan"))
    with pytest.raises(UnsupportedNonlinearityError, match="SmoothForcedFlow"):
        ForcedFlow(ForcedOscillator("u**3", omega0=1, zeta="1/20"), 0.1)
    with pytest.raises(UnsupportedNonlinearityError, match="DOP853"):
        ForcedFlow(ForcedOscillator("Max(0, u - 1/5)**(3/2)", omega0=1, zeta="1/20"), 0.1)
    with pytest.raises(ParameterError, match="numeric"):
        ForcedFlow(ForcedOscillator("Max(0, u - b)", zeta="1/20", params={"b": "1/5"}), 0.1)  # ω0 symbolic
    with pytest.raises(ProblemError, match="ForcedSystem"):
        ForcedFlow(UnilateralSystem.one_dof(1), 0.1)
    with pytest.raises(ProblemError, match="4 finite|2 finite"):
        flow.period_map([0.0], 1.0)
    with pytest.raises(ProblemError, match="zeta"):
        ForcedOscillator("Max(0, u)", omega0=1, zeta=-1)
    # exact resonance of an undamped state
    with pytest.raises(ResonanceError, match="damping"):
        ForcedFlow(ForcedSystem.one_dof(1, b=5), 0.5).period_map([0.0, 0.0], 1.0)


def test_sample_and_counters():
    flow = ForcedFlow(ForcedSystem.one_dof(1, zeta="1/20", b="1/5"), 0.8)
    t, z = flow.sample([0.3, 0.1], 1.3, periods=2, samples=64)
    assert t.shape == (64,) and z.shape == (64, 2) and t[-1] < 2 * 2 * math.pi / 1.3
    solved = flow.solve([0.3, 0.1], t[-1], 1.3)
    assert np.max(np.abs(z[-1] - np.concatenate([solved.position, solved.velocity]))) < 1e-13
    out = flow.period_map([0.3, 0.1], 1.3)
    assert {"arcs", "switches", "decompositions"} <= set(out.counters)


def test_flow_result_carries_and_exports_its_forced_problem():
    """A forced run's FlowResult holds its problem; to_json() exports it so that it rebuilds the same problem."""
    system = UnilateralSystem.chain(2, [(0, "1/10"), (1, "1/20", -1)])
    forced_system = ForcedSystem(system, load=[1, "1/2"], rayleigh=("1/50", "1/100"))
    oscillator = ForcedOscillator("Max(0, u - b) + c*Heaviside(u - b)", omega0=1, zeta="1/20", forcing="1/2",
                                  params={"b": "1/5", "c": "1/10"})
    for problem, z0 in ((forced_system, [0.2, -0.1, 0.0, 0.3]), (oscillator, [0.3, 0.0])):
        result = ForcedFlow(problem, 0.8).solve(z0, 12.0, 1.3)
        assert result.success and result.n_switches > 0
        assert result.system is problem and result.epsilon == 0.8
        data = json.loads(result.to_json())
        assert data["schema"] == "lindstedt.flow/1" and data["method"] == "exact-forced" and data["epsilon"] == 0.8
        assert data["n_switches"] == result.n_switches and len(data["events"]) == result.n_switches
        exported = data["system"]
        if isinstance(problem, ForcedSystem):
            assert exported == problem.to_json_dict()
            rebuilt = ForcedSystem.from_json_dict(exported)
            assert rebuilt.to_json_dict() == exported
        else:
            assert exported["description"] == problem.describe()
            rebuilt = ForcedOscillator(exported["f"], omega0=exported["omega0"], zeta=exported["zeta"],
                                       forcing=exported["forcing"], params=exported["params"])
            assert rebuilt == problem and rebuilt.describe() == exported["description"]
        # the rebuilt problem flows to the same trajectory, bit for bit
        again = ForcedFlow(rebuilt, 0.8).solve(z0, 12.0, 1.3)
        assert np.array_equal(again.position, result.position) and again.events == result.events
