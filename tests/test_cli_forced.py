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
