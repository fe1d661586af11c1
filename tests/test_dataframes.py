"""Sweeps and branches as pandas tables: one row per point, the numbers of the results themselves,
checked against the bilinear closed form ω = 2√(1+ε)/(1 + √(1+ε)) of u'' + u + ε u_+ = 0."""

import sys

import numpy as np
import pytest

import lindstedt
from lindstedt.numerics import to_dataframe

pandas = pytest.importorskip("pandas", reason="tables are optional: pip install 'lindstedt[pandas]'")


def bilinear(epsilon):
    stiff = np.sqrt(1 + np.asarray(epsilon))
    return 2 * stiff / (1 + stiff)


def test_sweep_table_holds_every_point():
    epsilons = [0.1, 0.3, 0.9]
    points = lindstedt.nnm_sweep(lindstedt.UnilateralSystem.one_dof(1), 1, epsilons, modal_amplitude=1.0)
    table = to_dataframe(points)
    assert len(table) == 3 and table["success"].all()
    assert np.allclose(table["epsilon"], epsilons, rtol=0, atol=0)
    assert np.allclose(table["frequency"], bilinear(epsilons), rtol=1e-12)
    assert np.allclose(table["period"], 2 * np.pi / bilinear(epsilons), rtol=1e-12)
    assert list(table["n_switches"]) == [point.n_switches for point in points]


def test_branch_table_starts_with_its_parameter():
    branch = lindstedt.continue_nnm(lindstedt.UnilateralSystem.one_dof(1), 1, start=0.0, stop=0.5, modal_amplitude=1.0)
    table = branch.to_dataframe()
    assert table.columns[0] == "epsilon" and len(table) == len(branch.points)
    assert np.allclose(table["frequency"], bilinear(table["epsilon"]), rtol=1e-11)
    assert not table["jump_after"].any()  # one dof: no internal resonance to jump across


def test_without_pandas_the_error_names_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(lindstedt.LindstedtError, match="pip install pandas"):
        to_dataframe([])
