"""The import graph of ``haptic``: module-level and function-level imports, and imports of modules named by
string literals (``__import__``, ``importlib.import_module``), read with ``ast``.

It has no cycle, between modules or between layers, and the pure core (geometry, matching, planning, learning)
imports nothing of the layers built on it, nor a simulator or a viewer.
"""

from __future__ import annotations

import ast
from pathlib import Path

import networkx as nx
import pytest

import haptic

CORE = ("haptic.geometry", "haptic.matching", "haptic.planning", "haptic.learning")
OUTER = ("haptic.sim", "haptic.executor", "haptic.episode", "haptic.bench", "haptic.recording", "haptic.env")
HEAVY = ("mujoco", "dm_control", "mink", "rerun", "gymnasium")
"""Third-party packages the pure core must not import."""


def _modules(root: Path) -> dict[str, Path]:
    """Module name -> file, for every module of the package at ``root``."""
    out = {}
    for f in root.rglob("*.py"):
        parts = list(f.relative_to(root.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = f
    return out


DYNAMIC_IMPORTS = ("__import__", "import_module")
"""Functions that import a module named by a string: ``__import__(name)``, ``importlib.import_module(name)``."""


def _dynamic_import(call: ast.Call) -> bool:
    f = call.func
    name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else None
    return name in DYNAMIC_IMPORTS and bool(call.args)


def _literal_loops(tree: ast.AST) -> dict[str, list[str]]:
    """Loop variables that run over a tuple or list of string literals: name -> the strings."""
    out: dict[str, list[str]] = {}
    for node in ast.walk(tree):
        over = isinstance(node, ast.For) and isinstance(node.iter, ast.Tuple | ast.List)
        if over and isinstance(node.target, ast.Name):
            names = [e.value for e in node.iter.elts if isinstance(e, ast.Constant) and isinstance(e.value, str)]
            out.setdefault(node.target.id, []).extend(names)
    return out


def _literal_names(arg: ast.expr, loops: dict[str, list[str]]) -> list[str]:
    """The module names a dynamic import's argument can hold: a string literal, or a loop variable over
    string literals."""
    if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
        return [arg.value]
    if isinstance(arg, ast.Name):
        return loops.get(arg.id, [])
    return []


def import_graph(root: Path) -> tuple[nx.DiGraph, dict[str, set[str]]]:
    """The package's modules and the imports between them (every ``import`` and ``from ... import``, at module
    level or inside functions, and every ``__import__`` / ``importlib.import_module`` of a string literal or of
    a loop variable over string literals), and the top-level third-party packages each module imports."""
    mods = _modules(root)
    pkg = root.name
    graph, external = nx.DiGraph(), {}

    def resolve(name: str) -> str | None:
        while name and name not in mods:
            name = name.rpartition(".")[0]
        return name or None

    for mod, path in mods.items():
        graph.add_node(mod)
        external[mod] = set()
        tree = ast.parse(path.read_text(), filename=str(path))
        loops = _literal_loops(tree)
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.Call) and _dynamic_import(node):
                targets = _literal_names(node.args[0], loops)
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    here = mod if path.name == "__init__.py" else mod.rpartition(".")[0]
                    for _ in range(node.level - 1):
                        here = here.rpartition(".")[0]
                    base = f"{here}.{base}" if base else here
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base for a in node.names]
            else:
                continue
            for t in targets:
                if t.split(".")[0] != pkg:
                    external[mod].add(t.split(".")[0])
                elif (target := resolve(t)) is not None and target != mod:
                    graph.add_edge(mod, target)
    return graph, external


def layer(module: str) -> str:
    """The layer of a module: ``haptic.planning.policies`` -> ``haptic.planning``."""
    return ".".join(module.split(".")[:2])


@pytest.fixture(scope="module")
def graph():
    return import_graph(Path(haptic.__file__).parent)


def test_no_module_imports_another_that_imports_it_back(graph):
    g, _ = graph
    assert len(g) > 50
    cycles = sorted(nx.simple_cycles(g), key=len)
    assert not cycles, "import cycles: " + "; ".join(" -> ".join(c) for c in cycles[:10])


def test_layers_depend_one_way(graph):
    g, _ = graph
    layers = nx.DiGraph((layer(a), layer(b)) for a, b in g.edges if layer(a) != layer(b))
    assert not list(nx.simple_cycles(layers)), sorted(layers.edges)


def test_the_pure_core_imports_no_outer_layer_and_no_simulator(graph):
    g, external = graph
    up = sorted((a, b) for a, b in g.edges if a.startswith(CORE) and b.startswith(OUTER))
    assert not up, f"the pure core imports outer layers: {up}"
    heavy = sorted((m, p) for m, pkgs in external.items() if m.startswith(CORE) for p in pkgs if p in HEAVY)
    assert not heavy, f"the pure core imports a simulator, viewer or environment package: {heavy}"


def test_planning_settings_hypotheses_and_table_checks_sit_below_prediction(graph):
    """Inside planning: ``config`` and ``hypothesis`` below ``table``, and ``table`` below ``predict`` and
    ``reach`` (the workspace side needs neither prediction nor reach)."""
    g, _ = graph
    below = {
        "haptic.planning.config": ("haptic.planning.table", "haptic.planning.predict"),
        "haptic.planning.hypothesis": ("haptic.planning.table", "haptic.planning.predict"),
        "haptic.planning.table": ("haptic.planning.predict", "haptic.planning.reach"),
    }
    for low, highs in below.items():
        for high in highs:
            assert nx.has_path(g, high, low), f"{high} does not build on {low}"
            assert not nx.has_path(g, low, high), f"{low} imports {high}, above it"


def test_the_graph_sees_function_level_and_relative_imports(tmp_path):
    """The checks could fail: a cycle hidden in a function, and an upward relative import, are found."""
    pkg = tmp_path / "pkg"
    (pkg / "core").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "core" / "__init__.py").write_text("")
    (pkg / "core" / "a.py").write_text("def f():\n    from pkg.core import b\n")
    (pkg / "core" / "b.py").write_text("from . import a\nfrom ..sim import thing\nimport mujoco\n")
    (pkg / "sim.py").write_text("")
    g, external = import_graph(pkg)
    assert [sorted(c) for c in nx.simple_cycles(g)] == [["pkg.core.a", "pkg.core.b"]]
    assert g.has_edge("pkg.core.b", "pkg.sim")
    assert external["pkg.core.b"] == {"mujoco"}


def test_the_graph_sees_imports_of_modules_named_by_strings(tmp_path):
    """A cycle closed through ``__import__`` or ``importlib.import_module`` (of a literal, or of a loop variable
    over literals) is found; a name computed at run time is not guessed at."""
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "cli.py").write_text(
        "def commands():\n"
        "    for module in ('pkg.sub', 'pkg.other'):\n"
        "        __import__(module, fromlist=['add_parser'])\n"
    )
    (pkg / "sub.py").write_text("def run():\n    from pkg.cli import commands\n")
    (pkg / "other.py").write_text("import importlib\n\ndef f():\n    importlib.import_module('pkg.leaf')\n")
    (pkg / "leaf.py").write_text("def g(name):\n    return __import__(name)\n")
    g, _ = import_graph(pkg)
    assert [sorted(c) for c in nx.simple_cycles(g)] == [["pkg.cli", "pkg.sub"]]
    assert g.has_edge("pkg.cli", "pkg.other") and g.has_edge("pkg.other", "pkg.leaf")
    assert list(g.successors("pkg.leaf")) == []


def test_the_command_reaches_its_subcommands_one_way(graph):
    """``haptic.cli`` loads its subcommands by name; none of them imports it back."""
    g, _ = graph
    for sub in ("haptic.sim.cli", "haptic.episode_cli", "haptic.bench.cli"):
        assert g.has_edge("haptic.cli", sub)
        assert not nx.has_path(g, sub, "haptic.cli"), f"{sub} imports haptic.cli back"
