"""The package's imports run one way: no import circles, no import up the layers.

The layers, lowest first, are the folders of ``rolling_cli`` (see the package
docstring and the README's code map). A module may import its own layer and
any layer below; the graph is read from the source with :mod:`ast` (imports
inside functions and ``TYPE_CHECKING`` blocks count too: a lazy import is a
dependency all the same).
"""

from __future__ import annotations

import ast
import pathlib

import pytest

PACKAGE = pathlib.Path(__file__).resolve().parents[1] / "rolling_cli"

#: lowest first; "" is the package itself (the public API), at the top with the CLI
LAYERS = [
    {"errors", "_version", "blas", "table"},
    {"references"},
    {"model"},
    {"influence"},
    {"case"},
    {"solver"},
    {"result"},
    {"adapt"},
    {"stresses"},
    {"pipeline"},
    {"files"},
    {"report"},
    {"study"},
    {"terminal", "process"},
    {"cli", "__main__", ""},
]


def modules(root: pathlib.Path) -> dict[str, tuple[pathlib.Path, bool]]:
    """Dotted module name -> (file, is a package) for every module under ``root``."""
    out = {}
    for path in root.rglob("*.py"):
        parts = list(path.relative_to(root.parent).with_suffix("").parts)
        is_pkg = parts[-1] == "__init__"
        if is_pkg:
            parts = parts[:-1]
        out[".".join(parts)] = (path, is_pkg)
    return out


def import_graph(root: pathlib.Path) -> dict[str, set[str]]:
    """Module -> the package modules it imports (anywhere in its source)."""
    mods = modules(root)
    top = root.name
    graph: dict[str, set[str]] = {}
    for name, (path, is_pkg) in mods.items():
        targets = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                targets.update(a.name for a in node.names if a.name.split(".")[0] == top)
            elif isinstance(node, ast.ImportFrom):
                if node.level == 0:
                    if (node.module or "").split(".")[0] != top:
                        continue
                    base = node.module
                else:
                    package = name.split(".") if is_pkg else name.split(".")[:-1]
                    package = package[: len(package) - (node.level - 1)]
                    base = ".".join(package + ([node.module] if node.module else []))
                for alias in node.names:
                    full = f"{base}.{alias.name}"
                    targets.add(full if full in mods else base)
        graph[name] = {t for t in targets if t in mods and t != name}
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The import circles: strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
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
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def layer(module: str) -> int:
    """The layer of a module: the position of its folder (or top-level module) in :data:`LAYERS`."""
    parts = module.split(".")
    head = parts[1] if len(parts) > 1 else ""
    for rank, names in enumerate(LAYERS):
        if head in names:
            return rank
    raise KeyError(f"{module} is in no layer: add its folder to LAYERS (and to the README's code map)")


def upward(graph: dict[str, set[str]]) -> list[tuple[str, str]]:
    """Imports from a lower layer into a higher one."""
    return sorted((a, b) for a, targets in graph.items() for b in targets if layer(b) > layer(a))


def test_no_import_circles():
    assert cycles(import_graph(PACKAGE)) == []


def test_imports_run_down_the_layers():
    assert upward(import_graph(PACKAGE)) == []


def test_every_module_has_a_layer():
    for module in import_graph(PACKAGE):
        layer(module)


def _package(tmp_path, files: dict[str, str]) -> pathlib.Path:
    root = tmp_path / "rolling_cli"
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return root


def test_a_constructed_circle_is_found(tmp_path):
    root = _package(
        tmp_path,
        {
            "__init__.py": "",
            "model/__init__.py": "",
            "model/a.py": "from . import b\n",
            "model/b.py": "def f():\n    from .a import g\n",
        },
    )
    assert cycles(import_graph(root)) == [["rolling_cli.model.a", "rolling_cli.model.b"]]


def test_a_constructed_upward_import_is_found(tmp_path):
    root = _package(
        tmp_path,
        {
            "__init__.py": "",
            "model/__init__.py": "",
            "model/grid.py": "from ..files import writer\n",
            "files/__init__.py": "",
            "files/writer.py": "from ..model import grid\n",
        },
    )
    graph = import_graph(root)
    assert upward(graph) == [("rolling_cli.model.grid", "rolling_cli.files.writer")]
    assert cycles(graph) == [["rolling_cli.files.writer", "rolling_cli.model.grid"]]


def test_an_unplaced_folder_is_refused():
    with pytest.raises(KeyError, match="no layer"):
        layer("rolling_cli.newfolder.x")
