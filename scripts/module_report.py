"""Size and imports of the package's modules: the ten largest by lines, and the function-local imports.

    .venv/bin/python scripts/module_report.py [PACKAGE_DIR] [--list] [--literals SUBPACKAGE ...]

A function-local import is an ``import`` or ``from ... import`` statement inside a function (each statement
counted once); ``--list`` prints every one of the package's own (``from haptic...``) with its place.

``--literals`` counts, per module of the given subpackages (e.g. ``executor sim``), the numeric literals in
function bodies (nested functions' too; default arguments and module-level constants are not in a body) and
prints each with its place. Not counted: the values 0, 1, 2 and 0.5 (and their negatives: zero, unit,
double, half), booleans, and integers that are array shapes, sizes or indices (in a subscript, an argument
of numpy's array constructors, ``reshape`` or a random draw, or compared with ``.shape`` / ``.ndim``).
"""

from __future__ import annotations

import argparse
import ast
from pathlib import Path


def local_imports(tree: ast.AST) -> list[ast.Import | ast.ImportFrom]:
    """The import statements inside functions (nested functions' too), each once."""
    found: dict[int, ast.Import | ast.ImportFrom] = {}
    for fn in ast.walk(tree):
        if isinstance(fn, ast.FunctionDef | ast.AsyncFunctionDef):
            for node in ast.walk(fn):
                if isinstance(node, ast.Import | ast.ImportFrom):
                    found[id(node)] = node
    return list(found.values())


PLAIN = {0, 1, 2, 0.5}
"""Values not counted as literals with a meaning: zero, unit, double, half."""
SHAPE_CALLS = {"zeros", "ones", "empty", "eye", "reshape", "standard_normal", "normal", "uniform", "integers",
               "array2string"}  # fmt: skip
"""Calls whose integer arguments are shapes, sizes or display precision."""


def _shape_ints(tree: ast.AST) -> set[int]:
    """Ids of the integer constants in shape, size or index positions."""
    out: set[int] = set()

    def mark(node: ast.AST) -> None:
        out.update(id(n) for n in ast.walk(node) if isinstance(n, ast.Constant) and type(n.value) is int)

    for node in ast.walk(tree):
        if isinstance(node, ast.Subscript):
            mark(node.slice)
        elif isinstance(node, ast.Call):
            f = node.func
            name = f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else ""
            if name in SHAPE_CALLS:
                for a in [*node.args, *(k.value for k in node.keywords)]:
                    mark(a)
        elif isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            if any(isinstance(n, ast.Attribute) and n.attr in ("shape", "ndim") for x in sides for n in ast.walk(x)):
                for x in sides:
                    mark(x)
    return out


def body_literals(tree: ast.AST) -> list[ast.Constant]:
    """The numeric literals with a meaning in function bodies (module docstring: what is not counted)."""
    skip = _shape_ints(tree)
    found: dict[int, ast.Constant] = {}
    for fn in ast.walk(tree):
        if isinstance(fn, ast.FunctionDef | ast.AsyncFunctionDef):
            for stmt in fn.body:
                for n in ast.walk(stmt):
                    if (isinstance(n, ast.Constant) and type(n.value) in (int, float) and n.value not in PLAIN
                            and id(n) not in skip):  # fmt: skip
                        found[id(n)] = n
    return sorted(found.values(), key=lambda n: (n.lineno, n.col_offset))


def own(node: ast.Import | ast.ImportFrom, package: str) -> bool:
    if isinstance(node, ast.ImportFrom):
        return node.level > 0 or (node.module or "").split(".")[0] == package
    return any(a.name.split(".")[0] == package for a in node.names)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("package", nargs="?", default=str(Path(__file__).resolve().parents[1] / "haptic"))
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--literals", nargs="+", metavar="SUBPACKAGE", help="count numeric literals in function bodies")
    args = ap.parse_args(argv)
    root = Path(args.package)
    if args.literals:
        total = 0
        for sub in args.literals:
            for f in sorted((root / sub).rglob("*.py")):
                lits = body_literals(ast.parse(f.read_text()))
                total += len(lits)
                for n in lits:
                    print(f"{f.relative_to(root.parent)}:{n.lineno}: {n.value!r}")
        print(f"numeric literals in function bodies under {', '.join(args.literals)}: {total}")
        return 0
    sizes, mine, total = [], [], 0
    for f in sorted(root.rglob("*.py")):
        text = f.read_text()
        sizes.append((len(text.splitlines()), f.relative_to(root.parent)))
        nodes = local_imports(ast.parse(text))
        total += len(nodes)
        mine += [(f.relative_to(root.parent), n) for n in nodes if own(n, root.name)]
    print(f"function-local imports: {len(mine)} of the package's own modules, {total} in all")
    print("ten largest modules (lines):")
    for n, p in sorted(sizes, reverse=True)[:10]:
        print(f"  {n:5d}  {p}")
    if args.list:
        for p, n in sorted(mine, key=lambda x: (str(x[0]), x[1].lineno)):
            print(f"{p}:{n.lineno}: {ast.unparse(n)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
