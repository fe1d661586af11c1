"""The numerical NNM (shooting on the exact flow) and the strained-coordinates NNM agree with an ε³ residual."""

import json

import numpy as np
import pytest

import lindstedt
from lindstedt.cli import main


@pytest.mark.parametrize("mode", [1, 2, 3])
def test_shooting_and_expansion_agree_to_third_order(mode):
    system = lindstedt.UnilateralSystem.chain(3, unilateral=[(0, 0.1), (2, -0.05)])
    expansion = lindstedt.nnm(system, mode=mode, a0=1.0, order=2)
    omega = [float(value) for value in expansion.omega]
    a_k = np.array([float(value) for value in expansion.a_k])
    epsilons = np.geomspace(0.002, 0.016, 4) * omega[0] ** 2
    residuals, release_errors = [], []
    for epsilon in epsilons:
        point = lindstedt.nnm_point(system, epsilon, mode, modal_amplitude=1.0)
        assert point.success, point.message
        residuals.append(abs(point.frequency - (omega[0] + omega[1] * epsilon + omega[2] * epsilon**2)))
        others = np.delete(point.modal_coordinates, mode - 1)
        release_errors.append(np.max(np.abs(others / epsilon - a_k)))
    assert np.polyfit(np.log(epsilons), np.log(residuals), 1)[0] == pytest.approx(3, abs=0.25)
    assert np.polyfit(np.log(epsilons), np.log(release_errors), 1)[0] == pytest.approx(1, abs=0.25)


def test_cli_numeric_nnm(tmp_path, capsys):
    path = tmp_path / "system.json"
    path.write_text(json.dumps({"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]], "A": [[1, 0]], "b": ["1/10"]}))
    assert main(["nnm", str(path), "--mode", "1", "--numeric", "--a0", "1", "--eps", "0.01", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["success"] and len(data["floquet_multipliers"]) == 4
    expansion = lindstedt.nnm(lindstedt.UnilateralSystem.from_json_dict(json.loads(path.read_text())), mode=1, a0=1)
    assert data["frequency"] == pytest.approx(float(expansion.frequency(0.01)), abs=1e-5)
    assert main(["nnm", str(path), "--mode", "1", "--numeric", "--eps", "0.01"]) == 2
    assert "exactly one of" in capsys.readouterr().err
    assert main(["nnm", str(path), "--mode", "1", "--numeric", "--energy", "0.5"]) == 2
    assert "--eps" in capsys.readouterr().err
