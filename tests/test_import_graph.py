"""The import graph of the package has no circle, and no module is over 800 lines (issue 24: a house without circles).

Every ``import`` and ``from … import`` of every module of ``lindstedt/`` — at module level and inside functions
alike (a deferred import is still a dependency) — is read from the source with ``ast``, and the strongly connected
components of the graph are the import circles: there is none.  The layers depend one way — problems, engine and
algebra below the methods, the methods build results, results never import a method (an unpickled result is
derived again by the method object it keeps) nor the export layer (their display and JSON primitives are in
``render``, their compiled float machinery in ``compiled``, both below them), and the export layer reads results;
among the numerics the flows report what the drivers need (their linear frequencies) and the drivers import the
flows.
"""

from __future__ import annotations

import ast
import pathlib

import lindstedt

PACKAGE = pathlib.Path(lindstedt.__file__).resolve().parent

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


def test_no_import_circle():
    circles = _circles(_graph())
    assert circles == [], sorted(sorted(circle) for circle in circles)


def test_results_import_no_method():
    graph = _graph()
    for name, targets in graph.items():
        if name.startswith("lindstedt.results"):
            assert not [target for target in targets if target.startswith("lindstedt.methods")], name


def test_results_import_no_export():
    graph = _graph()
    for name, targets in graph.items():
        if name.startswith("lindstedt.results"):
            assert not [target for target in targets if target.startswith("lindstedt.export")], name


#: no module of the package is longer than this (issue 24: a module per concept)
MAX_MODULE_LINES = 800


def test_no_module_is_over_the_size_limit():
    sizes = {path.relative_to(PACKAGE).as_posix(): len(path.read_text(encoding="utf-8").splitlines())
             for path in PACKAGE.rglob("*.py")}
    assert len(sizes) > 50  # the walk sees the package
    assert {name: lines for name, lines in sizes.items() if lines > MAX_MODULE_LINES} == {}
