"""List the import cycles between the modules of a package (default: src/fsmbt). Prints them.

    python scripts/import_cycles.py [--root src] [--package fsmbt] [--module-level-only]

Reads every ``.py`` file with the stdlib ``ast`` (nothing is imported or run) and draws an edge
``a -> b`` for each ``import b`` / ``from b import x`` in module ``a`` (``from p import m`` with
``m`` a module of the package is an edge to ``p.m``). Imports inside functions *are* counted, and
marked ``(local)``: an import hidden in a function still ties the two modules together, it only
postpones the cycle to run time. Imports under ``if TYPE_CHECKING:`` are counted too, marked
``(typing)``: a module that names another's types depends on it as much as one that calls it, and
a cycle kept only for annotations is a cycle of design (issue 25). ``--module-level-only`` leaves
both out and shows what Python's import machinery itself would trip over.
Importing ``p.m`` also runs ``p/__init__.py``; like grimp, that implicit edge is not drawn.

A cycle is a strongly connected component of more than one module (Tarjan's algorithm, written
with an explicit stack, no recursion); each is printed with the edges inside it and where they
are written. Exit status 1 when there is a cycle, so CI can run it. Cost: O(files + imports).
"""

from __future__ import annotations

import argparse
import ast
import sys
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Edge:
    source: str
    target: str
    line: int
    local: bool  # written inside a function
    typing: bool = False  # under ``if TYPE_CHECKING:``


def module_names(root: Path, package: str) -> dict[str, Path]:
    """Every module of ``package`` under ``root`` by dotted name (packages by their own name)."""
    out: dict[str, Path] = {}
    for path in sorted((root / package).rglob("*.py")):
        parts = list(path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def imports_of(name: str, path: Path, modules: dict[str, Path]) -> list[Edge]:
    """The edges from module ``name`` (file ``path``) to other modules of the package."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    is_package = path.name == "__init__.py"
    edges: list[Edge] = []
    # (node, inside a function, under TYPE_CHECKING) triples, walked with an explicit stack
    stack: list[tuple[ast.AST, bool, bool]] = [(tree, False, False)]
    while stack:
        node, local, typing = stack.pop()
        if isinstance(node, ast.If) and _is_type_checking(node.test):
            stack.extend((child, local, True) for child in node.body)
            stack.extend((child, local, typing) for child in node.orelse)
            continue
        targets: list[str] = []
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = name.split(".") if is_package else name.split(".")[:-1]
                anchor = anchor[: len(anchor) - (node.level - 1)]
                base = ".".join(anchor + ([base] if base else []))
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                targets.append(sub if sub in modules else base)
        for target in targets:
            while target and target not in modules:  # ``import a.b.c`` of a non-module c
                target = target.rpartition(".")[0]
            if target and target != name:
                edges.append(Edge(name, target, getattr(node, "lineno", 0), local, typing))
        inner = local or isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
        stack.extend((child, inner, typing) for child in ast.iter_child_nodes(node))
    return edges


def strongly_connected(graph: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's strongly connected components, iteratively; only those of 2+ nodes."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    order: list[str] = []
    components: list[list[str]] = []
    counter = 0
    for root in sorted(graph):
        if root in index:
            continue
        work: list[tuple[str, list[str]]] = [(root, sorted(graph[root]))]
        index[root] = low[root] = counter
        counter += 1
        order.append(root)
        on_stack.add(root)
        while work:
            node, pending = work[-1]
            if pending:
                nxt = pending.pop()
                if nxt not in index:
                    index[nxt] = low[nxt] = counter
                    counter += 1
                    order.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, sorted(graph.get(nxt, ()))))
                elif nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component: list[str] = []
                while True:
                    member = order.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    components.append(sorted(component))
    return sorted(components)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", default="src", type=Path)
    parser.add_argument("--package", default="fsmbt")
    parser.add_argument("--module-level-only", action="store_true",
                        help="leave out imports inside functions and under TYPE_CHECKING")
    args = parser.parse_args(argv)
    modules = module_names(args.root, args.package)
    edges = [e for name, path in modules.items() for e in imports_of(name, path, modules)
             if not (args.module_level_only and (e.local or e.typing))]
    graph: dict[str, set[str]] = {name: set() for name in modules}
    for edge in edges:
        graph[edge.source].add(edge.target)
    cycles = strongly_connected(graph)
    print(f"{len(modules)} modules, {len(edges)} imports inside {args.package}, "
          f"{len(cycles)} import cycle(s)"
          + (" (module-level imports only)" if args.module_level_only else ""))
    for number, component in enumerate(cycles, 1):
        members = set(component)
        print(f"\ncycle {number}: {len(component)} modules")
        for edge in sorted({e for e in edges if e.source in members and e.target in members},
                           key=lambda e: (e.source, e.target, e.line)):
            where = f"{modules[edge.source].as_posix()}:{edge.line}"
            print(f"  {edge.source} -> {edge.target}  {where}"
                  + ("  (local)" if edge.local else "") + ("  (typing)" if edge.typing else ""))
    return 1 if cycles else 0


if __name__ == "__main__":
    sys.exit(main())
