"""List every use of another module's private name in a package (default: src/fsmbt). Prints them.

    python scripts/private_access.py [--root src] [--package fsmbt]

A name starting with one underscore (not a dunder) is private to the module that defines it:
the module is free to rename or remove it. Reads every ``.py`` file with the stdlib ``ast``
(nothing is imported or run) and reports, with ``file:line``:

- ``import``: ``from m import _x`` of a module of the package, or a private module in the
  imported path (``fsmbt.formats._pysm_build``), at any depth (in functions and under
  ``if TYPE_CHECKING:`` too);
- ``module``: ``m._x`` where ``m`` names a module of the package (``from fsmbt.verify import
  native`` then ``native._product``);
- ``member``: ``obj._x`` on any object other than ``self``/``cls``/``super()``, outside the
  body of a class that defines ``_x`` (a method, class attribute or ``self._x = ...``): a private
  member is the class's own, so ``checker._check(...)`` from another module, or a module-level
  function calling ``builder._leaf(...)``, is reported; a class's methods may reach its members on
  another instance (``other._key`` in ``__eq__``).

The private members of the standard library's public API (``namedtuple._replace``,
``sys._getframe``, ``os._exit``, ``Enum._missing_``...) are allowed by name (``ALLOWED``).
Exit status 1 when anything is found. Cost: O(source size).
"""

from __future__ import annotations

import argparse
import ast
import sys
from dataclasses import dataclass
from pathlib import Path

#: Private-looking names that are the documented API of the standard library or a dependency.
ALLOWED = frozenset(
    {
        "_replace",
        "_asdict",
        "_fields",
        "_field_defaults",
        "_make",
        "_value_",
        "_name_",
        "_missing_",
        "_generate_next_value_",
        "_ignore_",
        "_getframe",
        "_exit",
        "_current_frames",
        # lxml's documented element and tree types (lxml.etree._Element in its API reference)
        "_Element",
        "_ElementTree",
        "_Attrib",
        "_Comment",
        "_ProcessingInstruction",
    }
)


@dataclass(frozen=True)
class Use:
    path: Path
    line: int
    kind: str  # import | module | member
    text: str


def is_private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def module_names(root: Path, package: str) -> dict[str, Path]:
    """Every module of ``package`` under ``root`` by dotted name (packages by their own name)."""
    out: dict[str, Path] = {}
    for path in sorted((root / package).rglob("*.py")):
        parts = list(path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def class_members(cls: ast.ClassDef) -> set[str]:
    """The names a class defines: its methods and nested classes, class-level assignments and
    annotations, and the attributes its methods assign (``self._x = ...``)."""
    names: set[str] = set()
    for node in ast.walk(cls):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, (ast.Store, ast.Del)):
            names.add(node.attr)
    return names


def enclosing_members(tree: ast.AST) -> dict[int, set[str]]:
    """For each ``ast.Attribute`` node (by ``id``), the members of the classes around it."""
    out: dict[int, set[str]] = {}
    stack: list[tuple[ast.AST, frozenset[str]]] = [(tree, frozenset())]
    while stack:
        node, members = stack.pop()
        if isinstance(node, ast.ClassDef):
            members = members | class_members(node)
        if isinstance(node, ast.Attribute):
            out[id(node)] = set(members)
        stack.extend((child, members) for child in ast.iter_child_nodes(node))
    return out


def uses_in(name: str, path: Path, modules: dict[str, Path], package: str) -> list[Use]:
    """The private names of other modules that module ``name`` (file ``path``) uses."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    is_package = path.name == "__init__.py"
    inside = enclosing_members(tree)
    module_alias: dict[str, str] = {}  # local name -> module of the package it is bound to
    found: list[Use] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] != package:
                    continue
                if any(is_private(part) for part in alias.name.split(".")):
                    found.append(Use(path, node.lineno, "import", f"import {alias.name}"))
                if alias.asname and alias.name in modules:
                    module_alias[alias.asname] = alias.name
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = name.split(".") if is_package else name.split(".")[:-1]
                anchor = anchor[: len(anchor) - (node.level - 1)]
                base = ".".join(anchor + ([base] if base else []))
            if base.split(".")[0] != package:
                continue
            for alias in node.names:
                target = f"{base}.{alias.name}"
                if any(is_private(part) for part in target.split(".")):
                    found.append(
                        Use(path, node.lineno, "import", f"from {base} import {alias.name}")
                    )
                if target in modules:
                    module_alias[alias.asname or alias.name] = target
    for node in ast.walk(tree):
        if not isinstance(node, ast.Attribute) or not is_private(node.attr):
            continue
        if node.attr in ALLOWED:
            continue
        owner = node.value
        if isinstance(owner, ast.Name) and owner.id in module_alias:
            if module_alias[owner.id] != name:
                found.append(
                    Use(
                        path,
                        node.lineno,
                        "module",
                        f"{owner.id}.{node.attr} ({module_alias[owner.id]})",
                    )
                )
            continue
        if isinstance(owner, ast.Name) and owner.id in ("self", "cls"):
            continue
        if (
            isinstance(owner, ast.Call)
            and isinstance(owner.func, ast.Name)
            and owner.func.id == "super"
        ):
            continue
        if node.attr in inside.get(id(node), ()):
            continue  # a class's own code reaching its members on another instance
        found.append(Use(path, node.lineno, "member", f"{ast.unparse(owner)}.{node.attr}"))
    return found


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", default="src", type=Path)
    parser.add_argument("--package", default="fsmbt")
    args = parser.parse_args(argv)
    modules = module_names(args.root, args.package)
    found = sorted(
        (u for name, path in modules.items() for u in uses_in(name, path, modules, args.package)),
        key=lambda u: (u.path.as_posix(), u.line, u.text),
    )
    print(f"{len(modules)} modules, {len(found)} use(s) of another module's private name")
    for use in found:
        print(f"  {use.path.as_posix()}:{use.line}: {use.kind}: {use.text}")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
