"""The layers of the code base, read from the source (every import statement,
also those inside functions and under TYPE_CHECKING): no module imports from a
package above its own (analytic < scenes < engines < compare < benchmarks), and
no two modules import each other, directly or round a longer circle."""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

from tests.support.paths import ROOT
LAYERS = ("analytic", "scenes", "engines", "compare", "benchmarks")
ROOT_NAME = "trilith_xval."  # the installed import name: graph nodes are named without it


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _modules() -> dict[str, Path]:
    return {_module_name(p): p for layer in LAYERS for p in (ROOT / layer).rglob("*.py")}


MODULES = _modules()


def _imports(name: str, path: Path) -> set[str]:
    """The project modules ``name`` imports (a package's submodule when the
    imported name is one, else the package)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            targets = [a.name.removeprefix(ROOT_NAME) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = package.split(".")[:len(package.split(".")) - node.level + 1]
                base = ".".join(up + ([base] if base else []))
            base = "" if base == ROOT_NAME[:-1] else base.removeprefix(ROOT_NAME)
            targets = [f"{base}.{a.name}".lstrip(".") if f"{base}.{a.name}".lstrip(".") in MODULES
                       else base for a in node.names]
        else:
            continue
        for target in targets:
            while target and target not in MODULES:  # 'engines.base.Engine' -> 'engines.base'
                target = target.rpartition(".")[0]
            if target and target != name:
                found.add(target)
    return found


GRAPH = {name: _imports(name, path) for name, path in MODULES.items()}


def _layer(module: str) -> int:
    return LAYERS.index(module.split(".")[0])


@pytest.mark.parametrize("layer", LAYERS)
def test_no_package_imports_one_above_it(layer):
    wrong = sorted(f"{m} -> {t}" for m, targets in GRAPH.items() if m.split(".")[0] == layer
                   for t in targets if _layer(t) > _layer(m))
    assert not wrong, wrong


def test_no_circular_imports():
    # Tarjan's strongly connected components: any with two or more modules is a circle.
    index, low, stack, on_stack, circles = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(GRAPH[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                circles.append(sorted(component))

    for v in sorted(GRAPH):
        if v not in index:
            visit(v)
    assert not circles, circles


def test_the_graph_sees_the_imports():
    # The checks above mean something only if imports are found: a few known edges.
    assert "analytic.bounds" in GRAPH["engines.base"]
    assert "engines.geometry" in GRAPH["engines.pymunk_.world"]
    assert "engines.pybullet_.bodies" in GRAPH["engines.pybullet_.world"]
