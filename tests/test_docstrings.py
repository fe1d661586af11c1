"""Every docstring example in the package runs and prints what it says."""

import doctest
import importlib
import pkgutil

import pytest

import lindstedt

MODULES = sorted(name for _, name, _ in pkgutil.iter_modules(lindstedt.__path__, "lindstedt.") if not name.endswith("__main__"))


@pytest.mark.parametrize("module_name", ["lindstedt", *MODULES])
def test_docstring_examples(module_name):
    module = importlib.import_module(module_name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.failed == 0
