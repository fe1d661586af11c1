"""Generated code is safe: a private, verified cache of compiled C and names that cannot collide.

* compiled libraries live in a per-user cache directory that must be ours and
  private; a planted, corrupted or truncated library is never loaded but rebuilt;
  files appear atomically (no partial file is left behind);
* a parameter whose name is reserved in C or Python (``index``, ``double``,
  ``y0``, ``lambda``, ``numpy``...) or equal to an internal name of the
  generated code (``common_0``, ``count``, ``output``) round-trips exactly.
"""

import hashlib
import json
import os
import shutil
import stat
import subprocess
import tempfile

import numpy as np
import pytest

import lindstedt
from lindstedt import CodeGenerationError, GeneratedCode

COMPILER = shutil.which("cc") or shutil.which("gcc")
needs_compiler = pytest.mark.skipif(COMPILER is None, reason="no C compiler (cc or gcc) on PATH")
posix_only = pytest.mark.skipif(not hasattr(os, "getuid"), reason="owner and mode checks are POSIX only")
LANGUAGES = ["numpy", pytest.param("c", marks=needs_compiler)]
EXPECTED = 1.0366796875  # ω(0.1) of u'' + u + ε u³ = 0 with a0 = 1, to order 2


@pytest.fixture
def cache(tmp_path, monkeypatch):
    directory = tmp_path / "cache"
    monkeypatch.setenv("LINDSTEDT_CACHE_DIR", str(directory))
    return directory


def _code():
    return lindstedt.generate_code(lindstedt.expand("u**3", order=2, a0=1, omega0=1), "frequency", "c")


def _stem(directory, code):
    return directory / f"{code.function_name}-{hashlib.sha256(code.source.encode()).hexdigest()}"


def _planted_library(tmp_path, canary):
    """A library exporting lindstedt_frequency that writes ``canary`` when loaded or called and returns 42."""
    source = tmp_path / "planted.c"
    source.write_text(
        "#include <stdio.h>\n"
        f"static void touch(void) {{ FILE *f = fopen({json.dumps(str(canary))}, \"w\"); if (f) fclose(f); }}\n"
        "__attribute__((constructor)) static void on_load(void) { touch(); }\n"
        "void lindstedt_frequency(const double *x, double *y, long n) { touch(); for (long i = 0; i < n; ++i) y[i] = 42.0; }\n"
    )
    library = tmp_path / "planted.so"
    subprocess.run([COMPILER, "-shared", "-fPIC", "-o", str(library), str(source)], check=True, capture_output=True)
    return library


def _no_partial_files(directory):
    return not [name for name in os.listdir(directory) if name.startswith(".partial-")]


# -- the cache directory ----------------------------------------------------------------------------


@needs_compiler
@posix_only
def test_cache_is_private_and_holds_source_library_and_hash_record(cache):
    code = _code()
    assert code.compile()(0.1) == pytest.approx(EXPECTED, rel=1e-15)
    stem = _stem(cache, code)
    names = {stem.name + suffix for suffix in (".c", ".so", ".so.sha256")}
    assert set(os.listdir(cache)) == names
    assert stat.S_IMODE(os.stat(cache).st_mode) == 0o700
    assert not any(stat.S_IMODE(os.stat(cache / name).st_mode) & 0o077 for name in names)
    recorded = (cache / (stem.name + ".so.sha256")).read_text().strip()
    assert recorded == hashlib.sha256((cache / (stem.name + ".so")).read_bytes()).hexdigest()


@needs_compiler
@posix_only
def test_default_cache_directories(tmp_path, monkeypatch):
    monkeypatch.delenv("LINDSTEDT_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    _code().compile()
    assert stat.S_IMODE(os.stat(tmp_path / "xdg" / "lindstedt" / "codegen").st_mode) == 0o700
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    _code().compile()
    assert os.listdir(tmp_path / "home" / ".cache" / "lindstedt" / "codegen")


@needs_compiler
@posix_only
def test_cache_directory_open_to_others_is_refused(cache):
    cache.mkdir()
    cache.chmod(0o777)
    with pytest.raises(CodeGenerationError, match="chmod 700") as error:
        _code().compile()
    assert str(cache) in str(error.value)
    cache.chmod(0o750)
    with pytest.raises(CodeGenerationError, match="accessible to other users"):
        _code().compile()
    assert os.listdir(cache) == []


@needs_compiler
@posix_only
def test_cache_directory_of_another_user_is_refused(cache, monkeypatch):
    cache.mkdir(mode=0o700)
    owner = os.stat(cache).st_uid
    monkeypatch.setattr(os, "getuid", lambda: owner + 1)
    with pytest.raises(CodeGenerationError, match="LINDSTEDT_CACHE_DIR") as error:
        _code().compile()
    assert str(cache) in str(error.value) and "not to you" in str(error.value)
    assert os.listdir(cache) == []


# -- planted, corrupted and truncated libraries -----------------------------------------------------


@needs_compiler
@pytest.mark.parametrize("record", ["missing", "wrong", "other users may write"])
def test_planted_library_is_never_loaded(cache, tmp_path, record):
    canary = tmp_path / "canary"
    planted = _planted_library(tmp_path, canary)
    code = _code()
    cache.mkdir(mode=0o700)
    library = _stem(cache, code).with_suffix(".so")
    shutil.copy(planted, library)
    if record == "wrong":
        library.with_suffix(".so.sha256").write_text("0" * 64 + "\n")
    elif record == "other users may write":  # a matching hash does not help a file others can write
        library.with_suffix(".so.sha256").write_text(hashlib.sha256(planted.read_bytes()).hexdigest() + "\n")
        library.chmod(0o777)
    assert code.compile()(0.1) == pytest.approx(EXPECTED, rel=1e-15)
    assert not canary.exists()
    assert library.read_bytes() != planted.read_bytes()


@needs_compiler
def test_library_at_the_old_shared_temp_path_is_ignored(cache, tmp_path, monkeypatch):
    canary = tmp_path / "canary"
    planted = _planted_library(tmp_path, canary)
    code = _code()
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    old = tmp_path / "lindstedt-codegen"
    old.mkdir()
    digest = hashlib.sha256(code.source.encode()).hexdigest()[:16]
    shutil.copy(planted, old / f"{code.function_name}_{digest}.so")
    assert code.compile()(0.1) == pytest.approx(EXPECTED, rel=1e-15)
    assert not canary.exists()


@needs_compiler
@pytest.mark.parametrize("record", ["missing", "of the complete library"])
def test_truncated_library_is_rebuilt(cache, tmp_path, monkeypatch, record):
    code = _code()
    code.compile()
    stem = _stem(cache, code)
    good = stem.with_suffix(".so").read_bytes()
    # A loaded library must never be changed in place (that crashes its users): damage a copy in a new directory.
    damaged = tmp_path / "damaged"
    damaged.mkdir(mode=0o700)
    library = damaged / (stem.name + ".so")
    library.write_bytes(good[: len(good) // 2])  # a build killed half way...
    library.chmod(0o700)
    if record != "missing":  # ...or a file damaged after it was recorded
        library.with_suffix(".so.sha256").write_text(hashlib.sha256(good).hexdigest() + "\n")
    monkeypatch.setenv("LINDSTEDT_CACHE_DIR", str(damaged))
    assert code.compile()(0.1) == pytest.approx(EXPECTED, rel=1e-15)
    assert library.read_bytes() == good
    assert library.with_suffix(".so.sha256").read_text().strip() == hashlib.sha256(good).hexdigest()


@needs_compiler
def test_library_that_ctypes_cannot_load_is_rebuilt_once(cache):
    code = _code()
    cache.mkdir(mode=0o700)
    library = _stem(cache, code).with_suffix(".so")
    library.write_bytes(b"\x7fELF truncated")  # the record matches, yet dlopen fails
    library.chmod(0o700)
    library.with_suffix(".so.sha256").write_text(hashlib.sha256(library.read_bytes()).hexdigest() + "\n")
    assert code.compile()(0.1) == pytest.approx(EXPECTED, rel=1e-15)
    assert library.read_bytes().startswith(b"\x7fELF") and library.stat().st_size > 1000


@needs_compiler
def test_persistent_load_failure_is_reported(cache, monkeypatch):
    import ctypes

    def refuse(path, *args, **kwargs):
        raise OSError(f"{path}: cannot open shared object file")

    monkeypatch.setattr(ctypes, "CDLL", refuse)
    with pytest.raises(CodeGenerationError, match="even after a rebuild"):
        _code().compile()


# -- atomic writes ------------------------------------------------------------------------------------


@needs_compiler
def test_failed_build_leaves_no_partial_files(cache):
    broken = GeneratedCode("c", "frequency", "lindstedt_frequency", ("epsilon",), "this is not C\n")
    with pytest.raises(CodeGenerationError, match="compiler failed"):
        broken.compile()
    assert _no_partial_files(cache)
    assert not [name for name in os.listdir(cache) if name.endswith((".so", ".sha256"))]


@needs_compiler
@pytest.mark.parametrize("where", ["compiler", "rename"])
def test_interrupted_build_leaves_no_partial_files(cache, monkeypatch, where):
    # interrupt the build from the outside: the compiler run (subprocess.run) or the final rename (os.replace)
    with monkeypatch.context() as patch:
        if where == "compiler":
            def interrupted(*args, **kwargs):
                raise KeyboardInterrupt

            patch.setattr(subprocess, "run", interrupted)
        else:
            replace = os.replace

            def interrupted(source, target):
                if str(target).endswith(".so"):
                    raise KeyboardInterrupt
                replace(source, target)

            patch.setattr(os, "replace", interrupted)
        with pytest.raises(KeyboardInterrupt):
            _code().compile()
    assert _no_partial_files(cache)
    assert not [name for name in os.listdir(cache) if name.endswith((".so", ".sha256"))]
    assert _code().compile()(0.1) == pytest.approx(EXPECTED, rel=1e-15)
    assert _no_partial_files(cache)


# -- reserved and colliding names -----------------------------------------------------------------------

# Python keywords cannot be parameter names (the problem stage refuses them); C keywords, math.h and libc names can.
NAMES = ["index", "double", "int", "y0", "j0", "gamma", "pow", "NAN", "HUGE_VAL", "M_PI", "errno",
         "numpy", "float", "sum", "common_0", "count", "output", "input", "unix"]


def _expansion_with_parameter(name):
    """``u**3 + name*u**5`` with the parameter left symbolic."""
    return lindstedt.expand(f"u**3 + {name}*u**5", order=2, params={name: None})


@pytest.mark.parametrize("language", LANGUAGES)
@pytest.mark.parametrize("name", NAMES)
def test_reserved_parameter_names_round_trip(name, language, cache):
    expansion = _expansion_with_parameter(name)
    values = {"a0": 1, "omega0": 1, name: 0.5}
    code = lindstedt.generate_code(expansion, "frequency", language)
    assert len(code.arguments) == 4 and code.arguments[0] == "epsilon"
    if language == "numpy":
        assert code.source.startswith(f"def {code.function_name}({', '.join(code.arguments)}):")
    else:
        assert all(f"double {argument}" in code.source for argument in code.arguments[1:])
    mangled = [argument for argument in code.arguments if argument not in ("epsilon", "a0", "omega0")]
    assert mangled[0].rstrip("_") == name
    generated = code.compile()(0.1, *[values[str(symbol)] for symbol in expansion.arguments])
    np.testing.assert_allclose(generated, expansion.frequency(0.1, values=values), rtol=1e-13, atol=0)


@pytest.mark.parametrize("language", LANGUAGES)
def test_mangled_names_stay_distinct(language, cache):
    # `double` is reserved in C only, `float` in both; a mangled name never takes another parameter's name
    expansion = lindstedt.expand("u**3 + double*u**5 + double_*u**7 + float*u**9", order=2,
                                 params={"double": None, "double_": None, "float": None})
    code = lindstedt.generate_code(expansion, "frequency", language)
    assert code.arguments[0] == "epsilon"
    names = dict(zip((str(symbol) for symbol in expansion.arguments), code.arguments[1:], strict=True))
    if language == "c":
        assert (names["double"], names["double_"], names["float"]) == ("double__", "double_", "float_")
    else:
        assert (names["double"], names["double_"], names["float"]) == ("double", "double_", "float_")
    assert len(set(code.arguments)) == len(code.arguments)
    values = {"a0": 1, "omega0": 1, "double": 0.5, "double_": -0.25, "float": 0.125}
    generated = code.compile()(0.1, *[values[str(symbol)] for symbol in expansion.arguments])
    np.testing.assert_allclose(generated, expansion.frequency(0.1, values=values), rtol=1e-13, atol=0)


def test_internal_names_cannot_be_parameter_names():
    with pytest.raises(lindstedt.ProblemError):
        lindstedt.expand("u**3 + _index*u**5", order=1, params={"_index": None})
    source = lindstedt.generate_code(lindstedt.expand("u**3 + c*u**5", order=2, params={"c": None}), "frequency", "c").source
    assert "_index" in source and "_common0" in source and " index" not in source


# -- issue 23, item 6: stale partial files, ASCII identifiers ------------------------------------------------------


@needs_compiler
@posix_only
def test_stale_partial_files_of_a_killed_build_are_removed(cache):
    _code().compile()  # creates the cache
    stale, fresh = cache / ".partial-killed.so", cache / ".partial-running.so"
    for path in (stale, fresh):
        path.write_bytes(b"half a library")
    hours_ago = os.stat(stale).st_mtime - 2 * 3600
    os.utime(stale, (hours_ago, hours_ago))
    assert _code().compile()(0.1) == pytest.approx(EXPECTED, rel=1e-15)
    assert not stale.exists()
    assert fresh.exists()  # a concurrent build's file is left alone


GREEK = {"α": 0.5, "u03b1": 0.25, "Α": 0.125}  # a non-ASCII name, its mangled form as a name, and a capital


@pytest.mark.parametrize("language", ["numpy", "jax", "c", "fortran", "octave", "julia", "rust"])
def test_generated_identifiers_are_ascii_and_distinct(language):
    expansion = lindstedt.expand("u**3 + α*u**5 + u03b1*u**7 + Α*u", order=2, params=dict.fromkeys(GREEK))
    code = lindstedt.generate_code(expansion, "frequency", language)
    assert code.source.isascii() and all(argument.isascii() for argument in code.arguments)
    fold = str.lower if language == "fortran" else str
    assert len({fold(argument) for argument in code.arguments}) == len(code.arguments)
    # deterministic: the same expansion gives the same code
    assert lindstedt.generate_code(expansion, "frequency", language).source == code.source


@pytest.mark.parametrize("language", LANGUAGES)
def test_non_ascii_parameter_names_round_trip(language, cache):
    expansion = lindstedt.expand("u**3 + α*u**5 + u03b1*u**7 + Α*u", order=2, params=dict.fromkeys(GREEK))
    values = {"a0": 1, "omega0": 1, **GREEK}
    code = lindstedt.generate_code(expansion, "frequency", language)
    generated = code.compile()(0.1, *[values[str(symbol)] for symbol in expansion.arguments])
    np.testing.assert_allclose(generated, expansion.frequency(0.1, values=values), rtol=1e-13, atol=0)


@pytest.mark.skipif(shutil.which("gfortran") is None, reason="no gfortran on PATH")
def test_non_ascii_parameter_names_compile_in_fortran(tmp_path):
    expansion = lindstedt.expand("u**3 + α*u**5", order=2, params={"α": None})
    source = tmp_path / "frequency.f90"
    source.write_text(lindstedt.generate_code(expansion, "frequency", "fortran").source)
    run = subprocess.run(["gfortran", "-c", str(source), "-o", str(tmp_path / "frequency.o")], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
