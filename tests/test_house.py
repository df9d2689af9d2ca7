"""Issue 35's targets that a test can hold (benchmarks/house_figures.py measures them all):

- import circles inside the library: the modules that import each other, function-local
  imports counted (a local import that closes a circle only hides it); the circles left are
  listed, and a new one, or a member added to one, fails here;
- public functions over 12 parameters: those left are listed, and no other may join them."""

from __future__ import annotations

import ast
from pathlib import Path

import networkx as nx
from test_design_records import _signatures

ROOT = Path(__file__).resolve().parents[1]
LAYERS = {"geometry": "holofold.geometry", "fitting": "holofold.fitting",
          "mechanics": "holofold.mechanics", "design": "holofold.design",
          "holofold": "holofold"}  # fmt: skip

#: the circles still there (docs/architecture.md says why), to be broken, never to grow
LEFT: list[set[str]] = []


def _modules() -> dict[str, Path]:
    out = {}
    for folder, package in LAYERS.items():
        for path in (ROOT / folder).rglob("*.py"):
            parts = [p for p in path.relative_to(ROOT / folder).with_suffix("").parts
                     if p != "__init__"]  # fmt: skip
            out[".".join([package, *parts])] = path
    return out


def _is_package(path: Path) -> bool:
    return path.name == "__init__.py"


def _type_checking_imports(tree: ast.AST) -> list[ast.AST]:
    """The import statements under ``if TYPE_CHECKING:`` (they never run)."""
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            out += [n for b in node.body for n in ast.walk(b)
                    if isinstance(n, ast.Import | ast.ImportFrom)]  # fmt: skip
    return out


def _graph() -> nx.DiGraph:
    """module -> module it imports (any import statement, wherever it stands; names
    imported from a package that are its modules count as those modules)."""
    mods = _modules()
    g = nx.DiGraph()
    for name, path in mods.items():
        pkg = name if _is_package(path) else name.rpartition(".")[0]
        tree = ast.parse(path.read_text(encoding="utf-8"))
        typing_only = {id(n) for n in _type_checking_imports(tree)}
        for node in ast.walk(tree):
            if id(node) in typing_only:  # never runs: names for the annotations only
                continue
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = pkg.split(".")[: len(pkg.split(".")) - node.level + 1]
                    base = ".".join([*up, *([base] if base else [])])
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base
                           for a in node.names]  # fmt: skip
            else:
                continue
            for t in targets:
                if t in mods and t != name:
                    g.add_edge(name, t)
    return g


def test_the_module_graph_is_read():
    g = _graph()
    assert g.number_of_nodes() > 150
    assert g.has_edge("holofold.design.scenarios.files", "holofold.design.scenarios.paper")
    assert g.has_edge("holofold.geometry.thick_part", "holofold.geometry.printable")


def test_no_import_circle_but_those_left():
    circles = [c for c in nx.strongly_connected_components(_graph()) if len(c) > 1]
    assert sorted(map(sorted, circles)) == sorted(map(sorted, LEFT))


#: public functions still over 12 parameters: the forest's hyperparameters (a scikit-learn
#: estimator's are its __init__'s, as RandomForestClassifier's 19)
OVER_12 = {"design/rules/miner.py __init__"}


def test_no_public_function_takes_over_12_parameters_but_those_left():
    over = set()
    for folder in ("geometry", "fitting", "mechanics", "design", "holofold"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            rel = path.relative_to(ROOT)
            if any(p.startswith("_") and p != "__init__.py" for p in rel.parts):
                continue
            for node, n in _signatures(path):
                if n > 12 and (not node.name.startswith("_") or node.name == "__init__"):
                    over.add(f"{rel} {node.name}")
    assert over == OVER_12
