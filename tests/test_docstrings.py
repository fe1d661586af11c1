"""Every docstring example in the package runs and prints what it says."""

import doctest
import importlib
import pkgutil

import pytest

import lindstedt

#: every module and subpackage of lindstedt, at any depth (walk_packages imports the subpackages to look inside)
MODULES = sorted(
    name for _, name, _ in pkgutil.walk_packages(lindstedt.__path__, "lindstedt.") if not name.endswith("__main__")
)
PUBLIC_SUBPACKAGES = ("lindstedt.algebra", "lindstedt.numerics", "lindstedt.plot", "lindstedt.references", "lindstedt.validate")


@pytest.mark.parametrize("module_name", ["lindstedt", *MODULES])
def test_docstring_examples(module_name):
    module = importlib.import_module(module_name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.failed == 0


def test_subpackages_are_walked():
    assert set(PUBLIC_SUBPACKAGES) <= set(MODULES)


@pytest.mark.parametrize("package_name", PUBLIC_SUBPACKAGES)
def test_public_subpackages_have_runnable_examples(package_name):
    package = importlib.import_module(package_name)
    tests = doctest.DocTestFinder().find(package)
    assert sum(len(test.examples) for test in tests if test.name == package_name) > 0
