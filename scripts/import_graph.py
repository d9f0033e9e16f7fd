"""The package's import graph, drawn from the code: circles, wing edges, library imports of cli/.

Usage::

    python scripts/import_graph.py [--edges]

Reads every module of ``shadowcam/`` with :mod:`ast` (nothing is imported or run), resolves
``import shadowcam.x`` and ``from shadowcam.x import y`` (also inside functions) to modules,
and prints:

* the import circles between modules (strongly connected components of more than one module);
* library modules (outside ``shadowcam/cli``) that import ``shadowcam.cli``;
* product wings (``io``, ``lab``, ``cameras``, ``outdoor``, ``report``) importing the
  development wings (``synthetic``, ``evaluate``), which sit above the product;
* with ``--edges``, the wing-to-wing edges with their counts.

Exits with status 1 if any circle or forbidden import exists.
"""

import argparse
import ast
import sys
from collections import Counter
from pathlib import Path

PACKAGE = "shadowcam"
PRODUCT_WINGS = {"io", "lab", "cameras", "outdoor", "report", "lightfield", "_shared"}
DEVELOPMENT_WINGS = {"synthetic", "evaluate"}


def module_name(path, root):
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def imported_modules(tree, modules):
    """Modules of the package that a module's syntax tree imports."""
    found = set()
    for node in ast.walk(tree):
        names = []
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module] + [f"{node.module}.{alias.name}" for alias in node.names]
        for name in names:
            if not name.startswith(PACKAGE):
                continue
            while name and name not in modules:
                name = name.rpartition(".")[0]
            if name and name != PACKAGE:
                found.add(name)
    return found


def strongly_connected(graph):
    """Tarjan's algorithm: the strongly connected components of a {node: set(nodes)} graph."""
    index, low, stack, on_stack, components = {}, {}, [], set(), []

    def visit(node):
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for succ in graph.get(node, ()):
            if succ not in index:
                visit(succ)
                low[node] = min(low[node], low[succ])
            elif succ in on_stack:
                low[node] = min(low[node], index[succ])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            components.append(sorted(component))

    sys.setrecursionlimit(10000)
    for node in graph:
        if node not in index:
            visit(node)
    return components


def wing(module):
    parts = module.split(".")
    return parts[1] if len(parts) > 2 or (len(parts) == 2 and parts[1] != "__init__") else ""


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--edges", action="store_true", help="also print wing-to-wing edge counts")
    parser.add_argument("--root", default=Path(__file__).resolve().parents[1], type=Path,
                        help="repository root (default: this script's repository)")
    args = parser.parse_args(argv)
    paths = sorted((args.root / PACKAGE).rglob("*.py"))
    modules = {module_name(p, args.root): p for p in paths}
    graph = {name: imported_modules(ast.parse(p.read_text()), modules) - {name} for name, p in modules.items()}

    circles = [c for c in strongly_connected(graph) if len(c) > 1]
    cli_imports = sorted((a, b) for a, deps in graph.items() for b in deps
                         if not a.startswith(f"{PACKAGE}.cli") and b.startswith(f"{PACKAGE}.cli"))
    upward = sorted((a, b) for a, deps in graph.items() for b in deps
                    if wing(a) in PRODUCT_WINGS and wing(b) in DEVELOPMENT_WINGS)
    print(f"{len(modules)} modules, {sum(map(len, graph.values()))} imports")
    print(f"import circles: {len(circles)}")
    for circle in circles:
        print("  " + " <-> ".join(circle))
    print(f"library modules importing cli: {len(cli_imports)}")
    for a, b in cli_imports:
        print(f"  {a} -> {b}")
    print(f"product wings importing development wings: {len(upward)}")
    for a, b in upward:
        print(f"  {a} -> {b}")
    if args.edges:
        edges = Counter((wing(a) or "(top)", wing(b) or "(top)") for a, deps in graph.items() for b in deps)
        for (a, b), n in sorted(edges.items()):
            if a != b:
                print(f"  {a:10s} -> {b:10s} {n}")
    return 1 if circles or cli_imports or upward else 0


if __name__ == "__main__":
    sys.exit(main())
