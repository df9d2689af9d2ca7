"""Issue 35's figures of the house, measured from the source (``ast``) and the import graph
(grimp, installed with import-linter): nothing of the library is run.

    python benchmarks/house_figures.py           # the figures as a table
    python benchmarks/house_figures.py --json    # the same as JSON
    python benchmarks/house_figures.py --duplicates   # also count duplicated pairs (slow)

The figures (docs/architecture.md keeps them, before and now):

- ``run_design``: parameters (``*args``/``**kwargs`` count one each) and lines (``def`` to
  its last line, and without the docstring);
- the longest public signatures (functions and methods whose module and name have no leading
  underscore, ``__init__`` of a public class included; ``self``/``cls`` not counted), and how
  many take more than 12;
- the kernels' arguments (every top-level function of the two kernel backends
  ``mechanics/_compiled.py``, ``mechanics/_numpy_kernels.py``, the generated
  ``mechanics/_spring_loop.py`` and the selector ``mechanics/kernels.py``), and how many take
  more than 10;
- functions that return a bare tuple of 4 or more (a ``return a, b, c, d`` or a
  ``-> tuple[A, B, C, D]`` annotation) and are used from another module of the library (imported
  by name, or a method called by name there), counted;
- the names of each layer's face (``__all__``) and of the top-level face;
- import circles: the strongly connected groups of the module graph that grimp builds of the
  package as installed (the layer folders become ``holofold.<layer>`` only when installed, so
  the package is built into a temporary folder, as ``.ci/lint-imports`` does), with every
  import and with module-level imports only, and the function-local imports that close a
  circle (an import inside a function from a module that reaches back to the importer);
  ``if TYPE_CHECKING`` imports are left out. The layer faces load their names lazily
  (lazy_loader), so an import through a face is an arrow to the face only;
- duplicated pairs (``--duplicates``): the first line of the ``duplicates`` command over the
  whole checkout, where that command is on PATH (pairs of places sharing 6 or more identical
  or same-shape lines).
"""

from __future__ import annotations

import argparse
import ast
import json
import shutil
import subprocess
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: repository folder -> the package it installs as (pyproject.toml's package-dir)
LAYERS = {
    "geometry": "holofold.geometry",
    "fitting": "holofold.fitting",
    "mechanics": "holofold.mechanics",
    "design": "holofold.design",
    "holofold": "holofold",
}
KERNEL_FILES = (
    "mechanics/kernels.py",
    "mechanics/_compiled.py",
    "mechanics/_numpy_kernels.py",
    "mechanics/_spring_loop.py",
)
#: the issue's figures, measured on de38fbf
BEFORE = {
    "run_design parameters": 23,
    "run_design lines": 277,
    "public signatures over 12 parameters": "newton_increments 34, ForestRuleMiner 25, ...",
    "largest kernel arguments": 34,
    "bare tuples of 4+ across modules": 24,
    "face names geometry/fitting/mechanics/design/top": "121/56/75/130/28",
    "import circles (closed by function-local imports)": 6,
    "duplicated pairs": 118,
}


def library_files() -> dict[str, Path]:
    """module name -> source file, for every module of the library."""
    out = {}
    for folder, package in LAYERS.items():
        for path in sorted((ROOT / folder).rglob("*.py")):
            rel = path.relative_to(ROOT / folder).with_suffix("")
            parts = [p for p in rel.parts if p != "__init__"]
            out[".".join([package, *parts])] = path
    return out


def _params(fn: ast.FunctionDef | ast.AsyncFunctionDef, method: bool) -> int:
    a = fn.args
    names = [*a.posonlyargs, *a.args, *a.kwonlyargs]
    static = any(getattr(d, "id", None) == "staticmethod" for d in fn.decorator_list)
    if method and not static and names and names[0].arg in ("self", "cls"):
        names = names[1:]
    return len(names) + (a.vararg is not None) + (a.kwarg is not None)


def _functions(tree: ast.Module):
    """(qualified name, node, is method, owner class or None) of top-level functions and of
    the methods of top-level classes."""
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            yield node.name, node, False, None
        elif isinstance(node, ast.ClassDef):
            for item in node.body:
                if isinstance(item, ast.FunctionDef | ast.AsyncFunctionDef):
                    yield f"{node.name}.{item.name}", item, True, node.name


def _public_module(module: str) -> bool:
    return not any(p.startswith("_") for p in module.split("."))


def run_design_figures(trees: dict) -> dict:
    tree = trees["holofold.design.loop.design_loop"]
    fn = next(n for q, n, _, _ in _functions(tree) if q == "run_design")
    body = fn.body
    has_doc = isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)
    first = body[1].lineno if has_doc and len(body) > 1 else body[0].lineno
    doc = body[0].end_lineno - body[0].lineno + 1 if has_doc else 0
    return {
        "parameters": _params(fn, False),
        "lines": fn.end_lineno - fn.lineno + 1,
        "lines without docstring": fn.end_lineno - fn.lineno + 1 - doc,
        "body lines after the docstring": fn.end_lineno - first + 1,
    }


def public_signatures(trees: dict, files: dict) -> list[tuple[int, str]]:
    out = []
    for module, tree in trees.items():
        if not _public_module(module):
            continue
        for qual, fn, method, owner in _functions(tree):
            name = qual.rsplit(".", 1)[-1]
            if (owner or "").startswith("_"):
                continue
            if name.startswith("_") and name != "__init__":
                continue
            out.append((_params(fn, method), f"{module}.{qual}"))
    return sorted(out, reverse=True)


def kernel_arguments() -> list[tuple[int, str]]:
    out = []
    for rel in KERNEL_FILES:
        tree = ast.parse((ROOT / rel).read_text(encoding="utf-8"))
        for node in tree.body:
            if isinstance(node, ast.FunctionDef):
                out.append((_params(node, False), f"{rel}:{node.name}"))
    return sorted(out, reverse=True)


def _tuple_width(node) -> int:
    """Elements of a literal tuple, or of a ``tuple[...]`` annotation (0 if neither)."""
    if isinstance(node, ast.Tuple) and not any(isinstance(e, ast.Starred) for e in node.elts):
        return len(node.elts)
    if isinstance(node, ast.Subscript) and getattr(node.value, "id", None) in ("tuple", "Tuple"):
        s = node.slice
        if isinstance(s, ast.Tuple) and not any(
            isinstance(e, ast.Constant) and e.value is Ellipsis for e in s.elts
        ):
            return len(s.elts)
    return 0


def _returns(fn) -> list:
    """The ``return`` statements of ``fn`` itself (not of functions nested in it)."""
    out, todo = [], list(fn.body)
    while todo:
        node = todo.pop()
        if isinstance(node, ast.Return) and node.value is not None:
            out.append(node.value)
        elif not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda):
            todo.extend(ast.iter_child_nodes(node))
    return out


def wide_tuples(trees: dict) -> list[str]:
    """Functions returning a bare tuple of 4+ that another module of the library uses: a
    function imported by name from its module or from its layer's face, a method (or a
    function) called as ``.name`` in another module (by name only: an over-count is possible
    for common method names)."""
    imported = defaultdict(set)  # (module imported from, name) -> modules importing it
    attributes = defaultdict(set)  # attribute name -> modules using it
    for module, tree in trees.items():
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module:
                for a in node.names:
                    imported[(node.module, a.name)].add(module)
            elif isinstance(node, ast.Attribute):
                attributes[node.attr].add(module)
    out = []
    for module, tree in trees.items():
        face = ".".join(module.split(".")[:2])
        for qual, fn, method, _ in _functions(tree):
            width = max([_tuple_width(fn.returns)] + [_tuple_width(r) for r in _returns(fn)])
            if width < 4:
                continue
            name = qual.rsplit(".", 1)[-1]
            users = set(attributes[name])
            if not method:
                users |= imported[(module, name)] | imported[(face, name)]
                if name.startswith("_"):  # a private function: only an import crosses
                    users = imported[(module, name)]
            if users - {module}:
                out.append(f"{module}.{qual} ({width})")
    return sorted(out)


def _all_names(tree: ast.Module) -> list[str] | None:
    for node in tree.body:
        if not isinstance(node, ast.Assign):
            continue
        targets = node.targets[0]
        elts = targets.elts if isinstance(targets, ast.Tuple) else [targets]
        if not any(getattr(t, "id", None) == "__all__" for t in elts):
            continue
        value = node.value
        if isinstance(value, ast.List | ast.Tuple):
            return [e.value for e in value.elts if isinstance(e, ast.Constant)]
        if isinstance(value, ast.Call):  # lazy_loader.attach(__name__, submodules, submod_attrs)
            names = []
            for kw in value.keywords:
                if kw.arg == "submodules":
                    names += [e.value for e in kw.value.elts]
                elif kw.arg == "submod_attrs":
                    for v in kw.value.values:
                        names += [e.value for e in v.elts]
            return names
    return None


def face_names(trees: dict) -> dict[str, int]:
    faces = ["holofold", *(p for p in LAYERS.values() if p != "holofold")]
    faces += ["holofold.design.rules", "holofold.design.scenarios", "holofold.mechanics.solvers"]
    return {f: len(_all_names(trees[f]) or []) for f in faces}


def _local_imports(trees: dict, files: dict) -> dict[str, set[int]]:
    """module -> line numbers of its imports made inside a function."""
    out = defaultdict(set)
    for module, tree in trees.items():
        for fn in ast.walk(tree):
            if isinstance(fn, ast.FunctionDef | ast.AsyncFunctionDef):
                for node in ast.walk(fn):
                    if isinstance(node, ast.Import | ast.ImportFrom):
                        out[module].add(node.lineno)
    return out


def _installed_graph(tmp: str):
    """grimp's graph of holofold as installed (built into ``tmp`` without dependencies)."""
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--no-compile",
         "--target", tmp, str(ROOT)],
        check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    import grimp

    sys.path.insert(0, tmp)
    try:
        return grimp.build_graph("holofold", cache_dir=None, exclude_type_checking_imports=True)
    finally:
        sys.path.remove(tmp)


def _groups(edges: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected groups of two modules or more (Tarjan, iterative)."""
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]
    nodes = set(edges) | {b for bs in edges.values() for b in bs}
    for root in sorted(nodes):
        if root in index:
            continue
        work = [(root, iter(sorted(edges.get(root, ()))))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(edges.get(w, ())))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                group = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    group.append(w)
                    if w == v:
                        break
                if len(group) > 1:
                    out.append(sorted(group))
    return sorted(out, key=len, reverse=True)


def import_circles(trees: dict, files: dict) -> dict:
    local = _local_imports(trees, files)
    with tempfile.TemporaryDirectory() as tmp:
        graph = _installed_graph(tmp)
        every, top = defaultdict(set), defaultdict(set)
        local_edges = []
        for a in graph.modules:
            for b in graph.find_modules_directly_imported_by(a):
                lines = {d["line_number"] for d in graph.get_import_details(importer=a, imported=b)}
                every[a].add(b)
                if lines - local.get(a, set()):
                    top[a].add(b)
                else:
                    local_edges.append((a, b))
    groups = _groups(every)
    member = {m: i for i, g in enumerate(groups) for m in g}
    closing = sorted(
        f"{a} -> {b}" for a, b in local_edges if a in member and member[a] == member.get(b)
    )
    return {
        "modules": len(graph.modules),
        "circles with function-local imports": [len(g) for g in groups],
        "circle members": groups,
        "circles at import time (module-level imports)": [len(g) for g in _groups(top)],
        "function-local imports closing a circle": closing,
        "function-local imports in all": sum(len(v) for v in local.values()),
    }


def duplicated_pairs() -> str | None:
    exe = shutil.which("duplicates")
    if exe is None:
        return None
    run = subprocess.run(
        [exe, "--seconds", "300", "--most", "1"], cwd=ROOT, capture_output=True, text=True
    )
    return run.stdout.splitlines()[0] if run.stdout else run.stderr.strip()


def figures(duplicates: bool = False) -> dict:
    files = library_files()
    trees = {m: ast.parse(p.read_text(encoding="utf-8"), str(p)) for m, p in files.items()}
    sigs = public_signatures(trees, files)
    kernels = kernel_arguments()
    tuples = wide_tuples(trees)
    out = {
        "library modules": len(files),
        "library lines": sum(
            len(p.read_text(encoding="utf-8").splitlines()) for p in files.values()
        ),
        "run_design": run_design_figures(trees),
        "public signatures over 12 parameters": [f"{s} ({n})" for n, s in sigs if n > 12],
        "longest public signatures": [f"{s} ({n})" for n, s in sigs[:8]],
        "kernels over 10 arguments": [f"{s} ({n})" for n, s in kernels if n > 10],
        "longest kernels": [f"{s} ({n})" for n, s in kernels[:6]],
        "bare tuples of 4+ across modules": tuples,
        "face names": face_names(trees),
        "imports": import_circles(trees, files),
    }
    if duplicates:
        out["duplicated pairs"] = duplicated_pairs()
    return out


def _table(fig: dict) -> str:
    lines = []
    for key, value in fig.items():
        if isinstance(value, dict):
            lines.append(f"{key}:")
            lines += [f"    {k}: {v}" for k, v in value.items() if k != "circle members"]
            if "circle members" in value:
                lines += [f"    circle: {' '.join(g)}" for g in value["circle members"]]
        elif isinstance(value, list):
            lines.append(f"{key}: {len(value)}")
            lines += [f"    {v}" for v in value]
        else:
            lines.append(f"{key}: {value}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--duplicates", action="store_true", help="count duplicated pairs too")
    args = p.parse_args(argv)
    fig = figures(args.duplicates)
    print(json.dumps(fig, indent=1) if args.json else _table(fig))
    return 0


if __name__ == "__main__":
    sys.exit(main())
