"""Size and imports of the package's modules: the ten largest by lines, and the function-local imports.

    .venv/bin/python scripts/module_report.py [PACKAGE_DIR] [--list]

A function-local import is an ``import`` or ``from ... import`` statement inside a function (each statement
counted once); ``--list`` prints every one of the package's own (``from haptic...``) with its place.
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


def own(node: ast.Import | ast.ImportFrom, package: str) -> bool:
    if isinstance(node, ast.ImportFrom):
        return node.level > 0 or (node.module or "").split(".")[0] == package
    return any(a.name.split(".")[0] == package for a in node.names)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("package", nargs="?", default=str(Path(__file__).resolve().parents[1] / "haptic"))
    ap.add_argument("--list", action="store_true")
    args = ap.parse_args(argv)
    root = Path(args.package)
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
