"""The public API: one facade (``lindstedt``) plus documented public subpackages, used by everything outside the package.

* tests, notebooks and benchmarks name no private module (a module whose name starts with an underscore), neither
  by importing it nor by naming its dotted path; two test files are converted later and are exempt for now;
* every name in the ``__all__`` of the facade and of each public subpackage resolves, is public, and the
  subpackages export exactly their ``__all__``;
* ``import lindstedt`` does not import the command-line interface.
"""

from __future__ import annotations

import ast
import importlib
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PUBLIC_MODULES = (
    "lindstedt",
    "lindstedt.algebra",
    "lindstedt.cli",
    "lindstedt.numerics",
    "lindstedt.references",
    "lindstedt.validate",
)
SUBPACKAGES = ("lindstedt.algebra", "lindstedt.limits", "lindstedt.numerics", "lindstedt.references", "lindstedt.validate")

#: the dotted path of a private module: lindstedt, dots, then a name with one leading underscore (dunders are public)
PRIVATE_PATH = re.compile(r"\blindstedt(?:\.\w+)*\._(?!_)\w*")


def _is_private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _private_imports(source: str) -> list[str]:
    """Imports of private modules or private names of lindstedt in Python source."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [alias.name for alias in node.names if alias.name.split(".")[0] == "lindstedt" and PRIVATE_PATH.search(alias.name)]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").split(".")[0] == "lindstedt":
            parts = node.module.split(".")
            if any(_is_private(part) for part in parts) or any(_is_private(alias.name) for alias in node.names):
                found.append(f"from {node.module} import {', '.join(alias.name for alias in node.names)}")
    return found


def _notebook_sources(path: Path) -> list[tuple[str, str]]:
    """(cell type, source) of every cell; IPython magics and shell lines are blanked in code cells."""
    cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
    sources = []
    for cell in cells:
        text = "".join(cell["source"])
        if cell["cell_type"] == "code":
            text = "\n".join("" if line.lstrip().startswith(("%", "!")) else line for line in text.splitlines())
        sources.append((cell["cell_type"], text))
    return sources


def _checked_files() -> list[Path]:
    files = sorted((ROOT / "tests").glob("*.py"))
    for directory in ("notebooks", "benchmarks", "derivations"):
        files += sorted(
            path
            for path in (ROOT / directory).rglob("*")
            # hidden folders are tooling (the benchmarks' cached peer venvs), not project files
            if path.is_file() and path.suffix in {".py", ".ipynb", ".md"} and not any(part.startswith(".") for part in path.relative_to(ROOT).parts)
        )
    return files


def test_the_scan_sees_the_files_it_must():
    names = {path.relative_to(ROOT).as_posix() for path in _checked_files()}
    assert {"tests/test_flow.py", "tests/test_contact_fourier.py", "tests/test_derivations.py", "benchmarks/run.py",
            "benchmarks/workers/lindstedt_duffing.py", "notebooks/backbone.ipynb", "derivations/gap.py"} <= names


def test_the_scan_catches_private_imports():
    flow = "lindstedt." + "_flow"  # spelled in two pieces so that this file passes its own scan
    assert _private_imports(f"from {flow} import ExactFlow")
    assert _private_imports(f"import {flow} as flow")
    assert _private_imports("from lindstedt import _codegen")
    assert _private_imports("from lindstedt.numerics import (\n    ExactFlow,\n    _first_exit,\n)")
    assert not _private_imports("from lindstedt import __version__\nimport lindstedt.references")
    assert PRIVATE_PATH.search(f"see `{flow}`") and not PRIVATE_PATH.search("lindstedt.__file__")


@pytest.mark.parametrize("path", _checked_files(), ids=lambda path: path.relative_to(ROOT).as_posix())
def test_no_private_module_is_used(path):
    if path.suffix == ".ipynb":
        sources = _notebook_sources(path)
        imports = [found for kind, text in sources if kind == "code" for found in _private_imports(text)]
        text = "\n".join(text for _, text in sources)
    else:
        text = path.read_text(encoding="utf-8")
        imports = _private_imports(text) if path.suffix == ".py" else []
    assert imports == [], f"{path.name} imports private names: {imports}"
    mentions = sorted({match.group(0) for match in PRIVATE_PATH.finditer(text)})
    assert mentions == [], f"{path.name} names private modules: {mentions}"


@pytest.mark.parametrize("module_name", PUBLIC_MODULES)
def test_every_exported_name_resolves(module_name):
    module = importlib.import_module(module_name)
    exported = module.__all__
    assert len(exported) == len(set(exported)), f"{module_name}.__all__ repeats a name"
    for name in exported:
        assert isinstance(name, str) and not name.startswith("_"), f"{module_name}.__all__ lists {name!r}"
        assert getattr(module, name, None) is not None, f"{module_name}.{name} does not resolve"
    namespace: dict = {}
    exec(f"from {module_name} import *", namespace)  # noqa: S102 - the star import honours __all__
    assert set(exported) <= set(namespace)


@pytest.mark.parametrize("package_name", SUBPACKAGES)
def test_subpackages_are_documented_and_export_exactly_their_all(package_name):
    package = importlib.import_module(package_name)
    assert package.__doc__ and ">>>" in package.__doc__, f"{package_name} needs a docstring with an example"
    public = {name for name, value in vars(package).items() if not name.startswith("_") and not isinstance(value, type(sys))}
    assert public == set(package.__all__)


def test_import_lindstedt_does_not_import_the_cli():
    script = (
        "import sys, lindstedt, lindstedt.algebra, lindstedt.numerics, lindstedt.references, lindstedt.validate\n"
        "print('lindstedt.cli' in sys.modules)"
    )
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, check=True)
    assert result.stdout.strip() == "False"


def test_cli_is_the_console_script_and_the_module_entry():
    pyproject = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    assert re.search(r'^lindstedt = "lindstedt\.cli:main"$', pyproject, flags=re.M)
    result = subprocess.run([sys.executable, "-m", "lindstedt", "--version"], capture_output=True, text=True, timeout=120, check=False)
    assert result.returncode == 0 and result.stdout.strip(), result.stderr


def test_import_lindstedt_does_not_load_scipy():
    # scipy (~0.25 s of import) is loaded by the numerical routines that use it, not by `import lindstedt`
    import subprocess
    import sys

    code = "import sys, lindstedt; print(sorted(name for name in sys.modules if name.split('.')[0] == 'scipy'))"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "[]"


def test_import_and_help_load_no_numerical_library():
    # the facade is lazy: `import lindstedt` and `lindstedt --help` load none of sympy, numpy, mpmath,
    # scipy; the first public name used loads its module (and every public name resolves)
    import subprocess
    import sys

    code = (
        "import sys, contextlib, io, lindstedt, lindstedt.cli\n"
        "with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):\n"
        "    lindstedt.cli.main(['--help'])\n"
        "heavy = ('sympy', 'numpy', 'mpmath', 'scipy')\n"
        "print(sorted({name.split('.')[0] for name in sys.modules if name.split('.')[0] in heavy}))\n"
        "print(all(getattr(lindstedt, name) is not None for name in lindstedt.__all__))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.split("\n")[:2] == ["[]", "True"], result.stdout + result.stderr


# --------------------------------------------------------------------------- the facade, __all__ and the API reference
API_PAGE = ROOT / "docs" / "api.rst"


def _automodule_blocks(text: str) -> dict[str, dict[str, str]]:
    """``.. automodule::`` directives of an rst page: module → its options (continuation lines joined)."""
    blocks: dict[str, dict[str, str]] = {}
    current = None
    option = None
    for line in text.splitlines():
        match = re.match(r"^\.\. automodule:: (\S+)\s*$", line)
        if match:
            current = blocks.setdefault(match.group(1), {})
            option = None
        elif current is not None and (found := re.match(r"^   :([\w-]+):(.*)$", line)):
            option = found.group(1)
            current[option] = found.group(2).strip()
        elif current is not None and option and re.match(r"^ {4,}\S", line):
            current[option] += " " + line.strip()
        elif line.strip():
            current = option = None
    return blocks


def _documented_names(module_name: str, options: dict[str, str]) -> set[str]:
    """The names an ``automodule`` documents: the module's ``__all__`` (``:members:`` without a list honours it)."""
    module = importlib.import_module(module_name)
    assert "members" in options and not options["members"], f"{module_name}: document its __all__ (:members: with no list)"
    excluded = {name.strip() for name in options.get("exclude-members", "").split(",") if name.strip()}
    return set(module.__all__) - excluded


def _facade_names() -> set[str]:
    """What ``dir(lindstedt)`` offers a user: no dunder (``__version__``), no private name, no submodule."""
    import lindstedt

    return {name for name in dir(lindstedt) if not name.startswith("_") and not isinstance(getattr(lindstedt, name), type(sys))}


def test_the_facade_offers_exactly_its_all():
    import lindstedt

    names = _facade_names()
    assert names == set(lindstedt.__all__), (
        f"in dir(lindstedt), not in __all__: {sorted(names - set(lindstedt.__all__))}; "
        f"in __all__, not in dir: {sorted(set(lindstedt.__all__) - names)}")
    # the forced-response API is part of the facade
    assert {"ForcedOscillator", "ForcedSystem", "MultipleScales", "frequency_response_curve", "FrequencyResponseCurve",
            "forced_flow", "forced_periodic_orbit", "ForcedOrbit", "frequency_response", "FrequencyResponse",
            "switch_period_doubling"} <= names


def test_the_api_reference_documents_every_public_name_once():
    blocks = _automodule_blocks(API_PAGE.read_text(encoding="utf-8"))
    assert set(blocks) == {"lindstedt", "lindstedt.plot", *SUBPACKAGES}, sorted(blocks)
    import lindstedt

    facade = _documented_names("lindstedt", blocks["lindstedt"])
    assert facade == _facade_names(), sorted(facade ^ _facade_names())
    for module_name, options in blocks.items():
        assert "no-index" not in options, f"{module_name}: indexed, so that its entries can be linked"
    for module_name in SUBPACKAGES:
        module = importlib.import_module(module_name)
        documented = _documented_names(module_name, blocks[module_name])
        # a name left out of a subpackage's section is the facade's own object, documented there
        skipped = sorted(name for name in set(module.__all__) - documented
                         if getattr(module, name) is not getattr(lindstedt, name, None))
        assert skipped == [], f"{module_name} leaves out names that the facade does not document: {skipped}"
        # and one object is documented once
        twice = sorted(name for name in documented if getattr(module, name) is getattr(lindstedt, name, None))
        assert twice == [], f"{module_name} documents the facade's objects again: {twice}"


def test_the_automodule_reader_reads_options():
    text = ".. automodule:: a.b\n   :members:\n   :exclude-members: x, y,\n                     z\n\nProse\n"
    assert _automodule_blocks(text) == {"a.b": {"members": "", "exclude-members": "x, y, z"}}
