"""The datasets layer imports without a circle: every module imports, and its import graph is acyclic.

Imports are read with ``ast`` from the source, at module level and inside functions alike (a
function-level import is still a dependency, only a later one), so a circle hidden behind a lazy
import fails here too.
"""

import ast
import importlib
import pkgutil
from pathlib import Path

import pytest

import igen_lerobot.datasets as package

PACKAGE = package.__name__
MODULES = sorted(f"{PACKAGE}.{m.name}" for m in pkgutil.iter_modules(package.__path__))


def _source(module: str) -> Path:
    return Path(package.__path__[0]) / f"{module.rsplit('.', 1)[1]}.py"


def internal_imports(module: str) -> set[str]:
    """Modules of the package that ``module`` imports anywhere in its source."""
    tree = ast.parse(_source(module).read_text(), filename=str(_source(module)))
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:  # relative: resolve against this package
                base = ".".join(module.split(".")[: -node.level])
                target = f"{base}.{node.module}" if node.module else base
            else:
                target = node.module or ""
            # ``from package import module`` names a module too
            names = [target, *(f"{target}.{alias.name}" for alias in node.names)]
        else:
            continue
        for name in names:
            parts = name.split(".")
            for i in range(len(parts), 0, -1):  # the longest prefix that is one of the package's modules
                if ".".join(parts[:i]) in MODULES:
                    found.add(".".join(parts[:i]))
                    break
    found.discard(module)
    return found


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` as a path (first node repeated at the end), or None."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return [*path[path.index(nxt) :], nxt]
            if nxt not in state and (cycle := visit(nxt)):
                return cycle
        path.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)):
            return cycle
    return None


@pytest.mark.parametrize("module", MODULES)
def test_every_datasets_module_imports(module):
    importlib.import_module(module)


def test_the_datasets_import_graph_has_no_cycle():
    graph = {module: internal_imports(module) for module in MODULES}
    assert graph[f"{PACKAGE}.writer"] and graph[f"{PACKAGE}.render"]  # the parser sees imports at all
    cycle = find_cycle(graph)
    assert cycle is None, "import circle in igen_lerobot/datasets: " + " -> ".join(cycle)


def test_the_metadata_module_imports_nothing_of_the_datasets_layer():
    assert internal_imports(f"{PACKAGE}.meta") == set()


def test_the_cycle_finder_finds_a_lazy_circle():
    """The check itself: the circle this layer had (writer -> render lazily, render -> writer) is found."""
    old = {"writer": {"render", "schema"}, "render": {"writer", "reader"}, "reader": {"schema"}, "schema": set()}
    assert find_cycle(old) in (["writer", "render", "writer"], ["render", "writer", "render"])
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": set()}) is None
