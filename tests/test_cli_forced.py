"""``lindstedt forced``: the forced response from the command line (issue 15).

Reference: the linear law f = u, whose steady response to ε F cos Ωt is the textbook
u = Re(H e^{iΩt}), H = ε F / (ω0² + ε − Ω² + 2iζω0Ω) (exact); and the multiple-scales closed forms of
Duffing, whose first harmonic is the textbook 3A³/4.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from lindstedt.cli import main

EXAMPLE = str(Path(__file__).resolve().parents[1] / "examples" / "forced_chain2.json")


def textbook(omega: float, epsilon: float = 0.1, zeta: float = 0.05, forcing: float = 1.0) -> complex:
    return epsilon * forcing / (1 + epsilon - omega**2 + 2j * zeta * omega)


def test_exact_sweep_json_is_the_textbook_linear_resonance(capsys):
    assert main(["forced", "u", "--eps", "0.1", "--zeta", "0.05", "--from", "0.8", "--to", "1.3", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["schema"] == "lindstedt.frequency-response/1" and data["success"] is True
    omega = np.array([point["frequency"] for point in data["points"]])
    peak = np.array([point["amplitude"][0] for point in data["points"]])
    assert omega[0] == 0.8 and omega[-1] == pytest.approx(1.3, rel=1e-12) and len(omega) > 10
    # shooting to 1e-10, the peak refined between 512 samples
    assert np.allclose(peak, [abs(textbook(w)) for w in omega], rtol=1e-9)


def test_one_orbit_text_and_json(capsys):
    assert main(["forced", "u", "--eps", "0.1", "--zeta", "0.05", "--at", "1.05", "--format", "json"]) == 0
    orbit = json.loads(capsys.readouterr().out)
    H = textbook(1.05)
    assert orbit["harmonic_cos"][0] == pytest.approx(H.real, rel=1e-10)
    assert orbit["harmonic_sin"][0] == pytest.approx(-H.imag, rel=1e-10)  # Re(H e^{iΩt}) = Re H cos − Im H sin
    assert main(["forced", "u", "--eps", "0.1", "--zeta", "0.05", "--at", "1.05"]) == 0
    text = capsys.readouterr().out
    assert "periodic response at Ω = 1.05: converged" in text and "stable" in text


def test_sweep_table_lists_folds_of_duffing(capsys):
    # u'' + 0.1 u' + u + 0.2 u³ = 0.2 cos Ωt folds (hardening): the table names both folds
    assert main(["forced", "u**3", "--eps", "0.2", "--zeta", "0.05", "--from", "1.0", "--to", "1.3", "--format", "plain"]) == 0
    text = capsys.readouterr().out
    assert text.count("fold") == 2 and "Omega" in text and "stable" in text and " no" in text


def test_multiple_scales_prints_the_closed_form_and_the_amplitudes(capsys):
    assert main(["forced", "u**3", "--eps", "0.1", "--zeta", "0.01", "--method", "multiple-scales", "--format", "json",
                 "--from", "0.95", "--to", "1.1"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["schema"] == "lindstedt.frequency-response-curve/1"
    assert data["first_harmonic"].replace(" ", "") == "3*A**3/4"
    assert len(data["evaluated"]["points"]) > 2 and all(p["amplitudes"] for p in data["evaluated"]["points"])
    assert main(["forced", "u**3", "--eps", "0.1", "--method", "multiple-scales", "--format", "latex"]) == 0
    assert "\\sigma" in capsys.readouterr().out


def test_figure_of_a_sweep(tmp_path, capsys):
    pytest.importorskip("matplotlib", reason="figures need matplotlib: pip install 'lindstedt[plot]'")
    path = tmp_path / "frc.png"
    assert main(["forced", "Max(0, u - 1/10)", "--eps", "0.5", "--zeta", "0.02", "--from", "0.9", "--to", "1.2",
                 "--figure", str(path)]) == 0
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and f"figure written to {path}" in capsys.readouterr().out


@pytest.mark.parametrize("arguments, message", [
    (["--from", "1", "--to", "1"], "--from and --to must differ"),
    (["--at", "1", "--from", "0.9", "--to", "1.1"], "not both"),
    (["--from", "0.9"], "give --from OMEGA --to OMEGA"),
    (["--at", "0"], "--at must be a positive"),
    (["--at", "1", "--zeta", "-0.1"], "zeta must be ≥ 0"),
    (["--at", "1", "--order", "2"], "--order is the multiple-scales order"),
    (["--at", "1", "--method", "multiple-scales"], "--at is for --method exact"),
    (["--from", "0.9", "--to", "1.1", "--figure", "x.xyz"], "the suffix must name an image format"),
])
def test_bad_input_is_one_error_line(arguments, message, capsys):
    assert main(["forced", "u**3", "--eps", "0.1", *arguments]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and message in err and err.count("\n") == 1


def test_n_dof_forced_system_file_is_the_textbook_linear_response_below_its_gap(tmp_path, capsys):
    # the spring's gap (100) is never reached: X = Re(H e^{iΩt}), H = (K − Ω²M + iΩC)⁻¹ ε P (textbook)
    data = {"system": {"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]], "A": [[1, 0]], "b": ["100"]},
            "load": [1, 0], "rayleigh": ["0", "1/50"]}
    path = tmp_path / "forced.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    assert main(["forced", str(path), "--eps", "0.5", "--at", "1.3", "--format", "json"]) == 0
    orbit = json.loads(capsys.readouterr().out)
    K, M = np.array([[2.0, -1.0], [-1.0, 2.0]]), np.eye(2)
    H = np.linalg.solve(K - 1.3**2 * M + 1j * 1.3 * K / 50, 0.5 * np.array([1.0, 0.0]))
    assert np.allclose(orbit["harmonic_cos"], H.real, rtol=1e-10) and np.allclose(orbit["harmonic_sin"], -H.imag, rtol=1e-10)
    assert main(["forced", str(path), "--eps", "0.5", "--from", "1.2", "--to", "1.4", "--format", "plain"]) == 0
    assert "max|X1|" in capsys.readouterr().out


@pytest.mark.parametrize("arguments, message", [
    (["--zeta", "0.1"], "a FORCED.json file holds its own damping and load"),
    (["--method", "multiple-scales"], "--method multiple-scales is for one degree of freedom"),
])
def test_n_dof_file_refuses_one_dof_options(arguments, message, capsys):
    assert main(["forced", EXAMPLE, "--eps", "0.5", "--at", "1", *arguments]) == 2
    assert message in capsys.readouterr().err


# --------------------------------------------------------------------------- #
# sweeps in either direction (issue 22): u'' + 0.04 u' + u + (u − 1/5)_+ = 0.04 cos Ωt, the README's example
# --------------------------------------------------------------------------- #
GAP = ["forced", "Max(0, u - 1/5)", "--eps", "1", "--zeta", "0.02", "--forcing", "0.04", "--format", "json"]


def exact_period_residual(state, omega, zeta=0.02, forcing=0.04, gap=0.2):
    """|X(2π/Ω) − X(0)| by DOP853 (rtol 1e-12) restarted at every crossing of the kink u = 1/5 (independent of the
    package's flows); a periodic response gives ~1e-11."""
    from scipy.integrate import solve_ivp

    def field(t, y):
        return [y[1], -2 * zeta * y[1] - y[0] - max(0.0, y[0] - gap) + forcing * np.cos(omega * t)]

    def kink(t, y):
        return y[0] - gap

    t, y, end = 0.0, np.array(state, dtype=float), 2 * np.pi / omega
    while t < end:
        run = solve_ivp(field, (t, end), y, method="DOP853", rtol=1e-12, atol=1e-14, events=kink)
        t, y = run.t[-1], run.y[:, -1]
        if run.status == 1:  # stopped at the kink: step just across it
            t_event = run.t_events[0][0]
            t, y = t_event, run.y_events[0][0]
            nudge = solve_ivp(field, (t, min(t + 1e-9, end)), y, method="DOP853", rtol=1e-12, atol=1e-14)
            t, y = nudge.t[-1], nudge.y[:, -1]
    return float(np.max(np.abs(y - np.asarray(state))))


def _sweep(capsys, start, stop):
    status = main([*GAP, "--from", start, "--to", stop])
    captured = capsys.readouterr()
    assert status == 0 and "error" not in captured.err, captured.err
    return json.loads(captured.out)


def test_a_downward_sweep_succeeds_and_is_the_upward_branch(capsys):
    up, down = _sweep(capsys, "0.8", "1.2"), _sweep(capsys, "1.2", "0.8")
    assert up["success"] is True and down["success"] is True and "reached stop = 0.8" in down["message"]
    assert down["points"][0]["frequency"] == 1.2 and down["points"][-1]["frequency"] == pytest.approx(0.8, rel=1e-12)
    folds_up = sorted(b["frequency"] for b in up["bifurcations"] if b["kind"] == "fold")
    folds_down = sorted(b["frequency"] for b in down["bifurcations"] if b["kind"] == "fold")
    assert len(folds_up) == 2 and np.allclose(folds_down, folds_up, rtol=0, atol=1e-6)
    # every 5th point of the downward branch is a periodic response of the exact flow
    for point in down["points"][::5]:
        assert exact_period_residual(point["state"], point["frequency"]) < 1e-8 * max(1.0, max(point["amplitude"]))
    # the same responses at the common ends (Newton at the exact Ω, residual 1e-10), in reverse order
    for a, b in ((up["points"][0], down["points"][-1]), (up["points"][-1], down["points"][0])):
        assert a["frequency"] == pytest.approx(b["frequency"], rel=1e-12)
        assert np.allclose(a["state"], b["state"], rtol=1e-8, atol=1e-10) and a["stable"] == b["stable"]


def test_a_downward_sweep_from_inside_the_hysteresis_turns_back_through_start_and_succeeds(capsys):
    # Ω = 1.1 lies between the folds (1.0915, 1.1335): the branch through the response at 1.1 reaches the lower fold
    # and turns back up the unstable branch to 1.1; it was reported as a failure (exit 1)
    down, up = _sweep(capsys, "1.1", "0.8"), _sweep(capsys, "0.8", "1.6")
    assert down["success"] is True and "through start" in down["message"] and "from 0.8" in down["message"]
    assert [b["kind"] for b in down["bifurcations"]] == ["fold"]
    lower_fold = min(b["frequency"] for b in up["bifurcations"] if b["kind"] == "fold")
    assert down["bifurcations"][0]["frequency"] == pytest.approx(lower_fold, abs=1e-6)
    assert down["points"][0]["stable"] and not down["points"][-1]["stable"]
    for point in down["points"][::3]:
        assert exact_period_residual(point["state"], point["frequency"]) < 1e-8
