"""Bounded reading of the JSON files of ``lindstedt nnm SYSTEM.json`` and ``lindstedt forced FORCED.json``.

A system file describes M X'' + K X + ε W (A X − b)_+ = 0 (and, for ``forced``, its damping and load):
matrices of N rows (the degrees of freedom) and S springs.  Every file is read with limits checked before
the work starts, so that a request either finishes in predictable time and memory or is refused up front:

* **size**: at most ``64 × (N_max + 1) × (N_max + S_max + 1)`` bytes (64 bytes an entry of the largest
  system allowed; 1.3 MB for the defaults), read as at most that many bytes plus one, so that a special
  file that never ends (``/dev/zero``) is refused after reading the limit, never read into memory whole;
* **depth**: at most :data:`MAX_DEPTH` nested arrays and objects (the schema needs 4);
* **entries**: no array longer than ``max(N_max, S_max)``, no object with more than :data:`MAX_KEYS`
  keys; the matrices at most ``N_max`` degrees of freedom (rows of M) and ``S_max`` springs (rows of A).

``N_max`` and ``S_max`` are the options ``--max-dof`` and ``--max-springs`` (default :data:`MAX_DOF` and
:data:`MAX_SPRINGS`: measured on two cores, a 100-dof chain takes 0.6 s and 100 MB for an NNM expansion,
0.9 s for ``--numeric`` and 28 s, 270 MB for a ``forced`` sweep; a 1000-dof chain already takes 7 s and 120 MB for
the expansion, and its sweep more than a minute).
"""

from __future__ import annotations

import json
from typing import Any, NoReturn

from .._errors import ProblemError

__all__ = ["MAX_DEPTH", "MAX_DOF", "MAX_KEYS", "MAX_SPRINGS", "BYTES_PER_ENTRY", "read_json_file", "check_system_size"]

#: default largest number of degrees of freedom of a system file (``--max-dof``)
MAX_DOF = 100
#: default largest number of unilateral springs of a system file (``--max-springs``)
MAX_SPRINGS = 100
#: the largest nesting of arrays and objects (the schema: object → system → matrix → row → entry is 4)
MAX_DEPTH = 8
#: the most keys of a JSON object (the schema has at most 5)
MAX_KEYS = 16
#: bytes allowed per matrix entry of the largest system (room for exact fractions and 17-digit floats)
BYTES_PER_ENTRY = 64
KNOBS = "--max-dof and --max-springs"


def size_limit(max_dof: int, max_springs: int) -> int:
    """The largest file size (bytes) for systems of at most ``max_dof`` dof and ``max_springs`` springs."""
    return BYTES_PER_ENTRY * (max_dof + 1) * (max_dof + max_springs + 1)


def read_json_file(path: str, what: str, *, max_dof: int = MAX_DOF, max_springs: int = MAX_SPRINGS) -> Any:
    """The JSON value of the file ``path`` (``what`` names it in errors), within the limits of this module.

    Raises ProblemError (one line naming the limit and the option that raises it) on an unreadable,
    oversized, too deep or too long file, on NaN/Infinity, and on invalid JSON or UTF-8.
    """
    for option, value in (("--max-dof", max_dof), ("--max-springs", max_springs)):
        if value < 1:
            raise ProblemError(f"{option} must be a positive integer, got {value}")
    limit = size_limit(max_dof, max_springs)
    try:
        with open(path, "rb") as handle:  # in chunks: a huge limit allocates nothing up front
            raw = bytearray()
            while len(raw) <= limit and (chunk := handle.read(min(1 << 20, limit + 1 - len(raw)))):
                raw += chunk
    except OSError as error:
        raise ProblemError(f"cannot read the {what} {path!r}: {error.strerror or error}") from None
    if len(raw) > limit:
        raise ProblemError(
            f"the {what} {path!r} is larger than {limit} bytes, the limit for systems of up to {max_dof} degrees of "
            f"freedom and {max_springs} springs ({BYTES_PER_ENTRY} bytes an entry); raise {KNOBS} to read a larger system"
        )
    try:
        data = json.loads(raw.decode("utf-8"), parse_constant=lambda name: _refuse_constant(name, what))
    except UnicodeDecodeError as error:
        raise ProblemError(f"the {what} {path!r} is not UTF-8 text: {error}") from None
    except json.JSONDecodeError as error:
        raise ProblemError(f"the {what} {path!r} is not valid JSON: {error}") from None
    except ValueError as error:  # an integer beyond Python's digit limit (sys.get_int_max_str_digits)
        raise ProblemError(f"the {what} {path!r} holds a number too long to read ({error}); "
                           "write every integer with at most 4300 digits") from None
    except RecursionError:
        _too_deep(path, what)
    _check_shape(data, path, what, max(max_dof, max_springs))
    return data


def _refuse_constant(name: str, what: str) -> NoReturn:
    raise ProblemError(f"the {what} contains {name}; every entry must be a finite real number")


def _too_deep(path: str, what: str) -> NoReturn:
    raise ProblemError(f"the {what} {path!r} nests arrays and objects deeper than {MAX_DEPTH} levels "
                       "(a system needs 4: object, key, matrix, row)")


def _check_shape(data: Any, path: str, what: str, max_items: int) -> None:
    """Depth and entry counts of a parsed value, iteratively (no recursion on hostile nesting)."""
    stack = [(data, 0)]
    while stack:
        value, depth = stack.pop()
        if isinstance(value, (list, dict)):
            if depth >= MAX_DEPTH:
                _too_deep(path, what)
            if isinstance(value, dict) and len(value) > MAX_KEYS:
                raise ProblemError(f"the {what} {path!r} has an object of {len(value)} keys; a system has at most {MAX_KEYS}")
            if isinstance(value, list) and len(value) > max_items:
                raise ProblemError(
                    f"the {what} {path!r} has an array of {len(value)} entries, more than the limit {max_items} "
                    f"(the larger of the degrees of freedom and springs allowed); raise --max-dof or --max-springs to {len(value)} "
                    "to read a larger system"
                )
            stack.extend((item, depth + 1) for item in (value.values() if isinstance(value, dict) else value))


def check_system_size(data: Any, what: str, *, max_dof: int = MAX_DOF, max_springs: int = MAX_SPRINGS) -> None:
    """Refuse a system mapping (keys M, K, A, b) with more than ``max_dof`` dof or ``max_springs`` springs."""
    if not isinstance(data, dict):
        return  # the problem's own validation names what is missing
    dof = len(data["M"]) if isinstance(data.get("M"), list) else 0
    springs = max((len(data[key]) for key in ("A", "b") if isinstance(data.get(key), list)), default=0)
    if dof > max_dof:
        raise ProblemError(f"the {what} has {dof} degrees of freedom, more than the limit {max_dof}; "
                           f"raise it with --max-dof {dof} (the cost grows like N³)")
    if springs > max_springs:
        raise ProblemError(f"the {what} has {springs} springs, more than the limit {max_springs}; "
                           f"raise it with --max-springs {springs}")
