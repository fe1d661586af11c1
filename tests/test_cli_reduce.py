"""``lindstedt nnm MODEL.json --reduce K``: finite-element models from matrix files, reduced before the NNM.

Reference: the full model's strained-coordinates NNM (every mode, 30 digits) on the same matrices — a kept mode's
ω₀, ω₁ are the full model's to the working precision whatever the reduction.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.io
import sympy

import lindstedt
from lindstedt.cli import main


@pytest.fixture(scope="module")
def beam_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("beam")
    beam = lindstedt.EulerBernoulliBeam(20, cracks=[(5, 10)])
    scipy.io.mmwrite(str(folder / "M.mtx"), beam.M)
    np.savez(folder / "beam.npz", M=beam.M.toarray(), K=beam.K.toarray())
    minus, plus = beam.index("theta5-"), beam.index("theta5+")
    model = {"matrices": {"M": "M.mtx", "K": "beam.npz"}, "elements": [{"a": {str(plus): 1, str(minus): "-1"}}]}
    (folder / "beam.json").write_text(json.dumps(model))
    # the full model on the same float matrices (the files hold binary floats: exactly these numbers)
    row = sympy.zeros(1, beam.n_dof)
    row[0, plus], row[0, minus] = 1, -1
    full = lindstedt.UnilateralSystem(beam.M.toarray(), beam.K.toarray(), row, [0])
    return folder, lindstedt.nnm(full, 1, a0=1, order=2).omega


def _omega(output: str) -> list[float]:
    data = json.loads(output)
    return data, [float(value) for value in data["omega"]]


def test_reduced_file_model_keeps_the_full_models_frequencies(beam_files, capsys):
    folder, full = beam_files
    assert main(["nnm", str(folder / "beam.json"), "--mode", "1", "--a0", "1", "--reduce", "4", "--format", "json"]) == 0
    data, omega = _omega(capsys.readouterr().out)
    assert data["reduction"]["n_dof"] == 41 and data["reduction"]["reduced_dof"] == 5
    assert abs(omega[0] / float(full[0]) - 1) < 1e-15 and abs(omega[1] / float(full[1]) - 1) < 1e-15
    assert abs(omega[2] / float(full[2]) - 1) < 1e-3  # the truncation (3.5e-7 measured at K = 4 on 201 dof)
    assert main(["nnm", str(folder / "beam.json"), "--mode", "1", "--a0", "1", "--reduce", "4"]) == 0
    assert capsys.readouterr().out.startswith("reduced: 41 dof → 5 (4 modes + residual vectors;")


def test_a_json_system_can_be_reduced_too(tmp_path, capsys):
    chain = lindstedt.UnilateralSystem.chain(12, unilateral=[(3, "1/10")])
    (tmp_path / "chain.json").write_text(json.dumps(chain.to_json_dict()))
    full = lindstedt.nnm(chain, 1, a0=1, order=2).omega
    assert main(["nnm", str(tmp_path / "chain.json"), "--mode", "1", "--a0", "1", "--reduce", "3", "--format", "json"]) == 0
    _, omega = _omega(capsys.readouterr().out)
    assert abs(omega[0] / float(full[0]) - 1) < 1e-15 and abs(omega[1] / float(full[1]) - 1) < 1e-15


@pytest.mark.parametrize("model, options, message", [
    ({"matrices": "beam.npz", "elements": [{"a": {"3": 1}}]}, [], "give --reduce K"),
    ({"matrices": "beam.npz", "elements": [{"a": {"3": 1}}], "couplings": ["x1**3"]}, ["--reduce", "2"], "unknown keys"),
    ({"matrices": "beam.npz", "elements": [{"a": {"x": 1}}]}, ["--reduce", "2"], "degree-of-freedom indices"),
    ({"matrices": "beam.npz", "elements": [{"a": {"99": 1}}]}, ["--reduce", "2"], "degree-of-freedom indices"),
    ({"matrices": "beam.npz", "elements": [{"a": [1, 2]}]}, ["--reduce", "2"], "has 2 entries"),
    ({"matrices": "beam.npz", "elements": [{"a": {"3": 0}}]}, ["--reduce", "2"], "is zero"),
    ({"matrices": "beam.npz", "elements": [{"a": {"3": "nan"}}]}, ["--reduce", "2"], "finite real number"),
    ({"matrices": "beam.npz", "elements": []}, ["--reduce", "2"], "needs 'elements'"),
    ({"matrices": "missing.npz", "elements": [{"a": {"3": 1}}]}, ["--reduce", "2"], "missing.npz"),
    ({"matrices": ["beam.npz"], "elements": [{"a": {"3": 1}}]}, ["--reduce", "2"], "'matrices' must be a file name"),
    ({"matrices": "beam.npz", "elements": [{"a": {"3": 1}}]}, ["--reduce", "0"], "modes must be a positive integer"),
])
def test_bad_models(beam_files, capsys, model, options, message):
    folder, _ = beam_files
    path = folder / "bad.json"
    path.write_text(json.dumps(model))
    assert main(["nnm", str(path), "--mode", "1", "--a0", "1", *options]) != 0
    error = capsys.readouterr().err
    assert error.startswith("error:") and message in error and error.count("\n") == 1
