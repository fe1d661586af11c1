"""Packaging: the MIT license is declared as an SPDX expression and shipped (PEP 639), and ``python -m build``
builds the sdist and the wheel without a warning."""

from __future__ import annotations

import os
import pathlib
import subprocess
import sys
import tarfile
import zipfile

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent


def _project() -> dict:
    tomllib = pytest.importorskip("tomllib", reason="tomllib is in the standard library from Python 3.11 on")
    return tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def test_the_license_is_mit_by_spdx_and_a_file():
    project = _project()
    text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert text.startswith("MIT License\n") and "Copyright (c) 2026 The lindstedt maintainers" in text
    assert project["project"]["license"] == "MIT" and project["project"]["license-files"] == ["LICENSE"]
    # the license classifier is deprecated next to an SPDX expression
    assert not [c for c in project["project"]["classifiers"] if c.startswith("License ::")]
    assert any(requirement.startswith("setuptools>=77") for requirement in project["build-system"]["requires"])


@pytest.mark.slow
def test_build_is_free_of_warnings_and_ships_the_license(tmp_path):
    pytest.importorskip("build", reason="the dev extra: pip install -e '.[dev]'")
    # setuptools says "warning: byte-compiling is disabled" when the environment disables bytecode: not ours
    env = {key: value for key, value in os.environ.items() if key != "PYTHONDONTWRITEBYTECODE"}
    result = subprocess.run([sys.executable, "-m", "build", "--outdir", str(tmp_path), str(ROOT)],
                            capture_output=True, text=True, env=env, timeout=1800, check=False)
    output = (result.stdout + result.stderr).replace(str(tmp_path), "<out>")  # the test's name says "warnings"
    assert result.returncode == 0, output[-3000:]
    warnings = [line for line in output.splitlines() if "warning" in line.lower()]
    assert warnings == [], warnings
    (wheel,) = tmp_path.glob("lindstedt-*.whl")
    (sdist,) = tmp_path.glob("lindstedt-*.tar.gz")
    license_text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    with zipfile.ZipFile(wheel) as archive:
        names = archive.namelist()
        (licensed,) = [name for name in names if name.endswith(".dist-info/licenses/LICENSE")]
        assert archive.read(licensed).decode() == license_text
        (metadata,) = [name for name in names if name.endswith(".dist-info/METADATA")]
        lines = archive.read(metadata).decode().splitlines()
        assert "License-Expression: MIT" in lines and "License-File: LICENSE" in lines
        assert not [line for line in lines if line.startswith("Classifier: License ::")]
        assert any(name.endswith("lindstedt/py.typed") for name in names)
    with tarfile.open(sdist) as archive:
        assert any(name.endswith("/LICENSE") for name in archive.getnames())
