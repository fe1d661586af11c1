"""The import graph of the package has no new circle (issue 24: a house without circles).

Every ``import`` and ``from … import`` of every module of ``lindstedt/`` — at module level and inside functions
alike (a deferred import is still a dependency) — is read from the source with ``ast``, and the strongly connected
components of the graph are the import circles.  The numerics (free and forced periodic orbits, their flows), the
budget and cost model, the problems, the engine and the algebra have none; the two circles between the results,
the methods and the export layer are the ones issue 24 still has to cut, listed here so that no other can appear.
"""

from __future__ import annotations

import ast
import pathlib

import lindstedt

PACKAGE = pathlib.Path(lindstedt.__file__).resolve().parent

#: the circles left (issue 24: results must not import methods or export); none may grow or appear
REMAINING = {
    frozenset({"lindstedt.export.codegen", "lindstedt.methods.lindstedt_poincare", "lindstedt.methods.multiple_scales",
               "lindstedt.results.expansion", "lindstedt.results.frequency_response"}),
    frozenset({"lindstedt.methods.strained_coordinates", "lindstedt.results.nnm"}),
}


def _name(path: pathlib.Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _graph() -> dict[str, set[str]]:
    modules = {_name(path): path for path in PACKAGE.rglob("*.py")}
    graph: dict[str, set[str]] = {name: set() for name in modules}
    for name, path in modules.items():
        package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package[: len(package) - node.level + 1]
                    target = ".".join(base + ([node.module] if node.module else []))
                elif node.module and node.module.split(".")[0] == "lindstedt":
                    target = node.module
                else:
                    continue
                candidates = [f"{target}.{alias.name}" for alias in node.names] + [target]
            elif isinstance(node, ast.Import):
                candidates = [alias.name for alias in node.names if alias.name.split(".")[0] == "lindstedt"]
            else:
                continue
            for candidate in candidates:  # a submodule imported by name, else the module the names come from
                if candidate in modules:
                    graph[name].add(candidate)
                    if isinstance(node, ast.ImportFrom):
                        break
    return graph


def _circles(graph: dict[str, set[str]]) -> list[frozenset[str]]:
    """The strongly connected components of more than one module (Tarjan, iteratively)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    circles = []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, successors = work[-1]
            for successor in successors:
                if successor not in index:
                    index[successor] = low[successor] = len(index)
                    stack.append(successor)
                    on_stack.add(successor)
                    work.append((successor, iter(sorted(graph[successor]))))
                    break
                if successor in on_stack:
                    low[node] = min(low[node], index[successor])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = set()
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.add(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        circles.append(frozenset(component))
    return circles


def test_the_reader_finds_a_circle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert _circles(graph) == [frozenset({"a", "b", "c"})]
    assert _circles({"a": {"b"}, "b": set()}) == []


def test_the_reader_sees_deferred_imports():
    graph = _graph()
    # forced_setup builds the flows inside functions: the edges are there all the same
    assert {"lindstedt.numerics.forced_flow", "lindstedt.numerics.forced_smooth"} <= graph["lindstedt.numerics.forced_setup"]


def test_no_import_circle_beyond_the_ones_issue_24_cuts():
    circles = set(_circles(_graph()))
    assert circles <= REMAINING, sorted(sorted(circle) for circle in circles - REMAINING)
    for circle in circles:
        assert not any(name.split(".")[1] in ("numerics", "problems", "engine", "algebra", "limits", "_budget", "_cost")
                       for name in circle), sorted(circle)
