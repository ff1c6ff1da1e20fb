"""Node families own their behaviour (issue 25; docs/semantics.md §9a, "Adding a node kind"): no
module of ``fsmbt`` outside the family modules branches on a built-in control, decorator or
SubTree type name, so a new kind's behaviour has one home.

The scan (``ast``, no import of the scanned code): a comparison (``==``, ``!=``, ``in``, ``not
in``) one of whose sides is such a name, or a tuple/list/set of names; and a ``set`` /
``frozenset`` literal holding one (a set a later ``in`` tests). Strings elsewhere (messages,
XML written, dictionary keys of tables such as render's symbols) are not branches and are not
scanned. A module that needs the names for another reason is allowed below, with the reason;
an allowance that no longer matches anything fails, so the list only shrinks.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.nodes import all_nodes

SRC = Path(__file__).resolve().parents[2] / "src" / "fsmbt"

#: Where a kind's declaration and behaviour live: names are expected there.
FAMILY_HOMES = ("model/nodes/", "semantics/families/", "verify/nusmv/families/")

#: Modules (or folders) that compare built-in type names for a reason other than behaviour.
ALLOWED = {
    "formats/btcpp/": "BehaviorTree.CPP XML: element names and the v3/v4 differences are the "
    "format's vocabulary (reading, writing, version detection)",
    "semantics/engines/": "adapters to the real engines: each maps a kind to the other engine's "
    "class or builder call (py_trees, BehaviorTree.CPP)",
    "generate/generator.py": "random trees: the ports drawn per kind (num_cycles or "
    "num_attempts, a Parallel's thresholds)",
    "runtime/skeleton/python.py": "generated py_trees code: the loop decorators it writes",
}


def builtin_names() -> frozenset[str]:
    """Built-in control, decorator and SubTree types with their v3 aliases."""
    names: set[str] = set()
    for n in all_nodes():
        if n.kind in (NodeKind.CONTROL, NodeKind.DECORATOR, NodeKind.SUBTREE):
            names.add(n.name)
            names.update(n.aliases)
    return frozenset(names)


def _strings(node: ast.AST) -> Iterator[str]:
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        yield node.value
    elif isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        for elt in node.elts:
            yield from _strings(elt)
    elif (
        isinstance(node, ast.Call)
        and isinstance(node.func, ast.Name)
        and node.func.id in ("set", "frozenset", "tuple")
        and node.args
    ):
        yield from _strings(node.args[0])


def branches(source: str, names: frozenset[str]) -> list[tuple[int, str]]:
    """``(line, name)`` of every comparison with, and set literal of, a name in ``names``."""
    found: set[tuple[int, str]] = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare):
            parts: list[ast.AST] = [node.left, *node.comparators]
        elif isinstance(node, ast.Set) or (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Name)
            and node.func.id in ("set", "frozenset")
        ):
            parts = [node]
        else:
            continue
        found.update((node.lineno, s) for part in parts for s in _strings(part) if s in names)
    return sorted(found)  # a frozenset({...}) literal is seen as the call and as the set


def _hits() -> dict[str, list[tuple[int, str]]]:
    names = builtin_names()
    out = {}
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        if rel.startswith(FAMILY_HOMES):
            continue
        found = branches(path.read_text(encoding="utf-8"), names)
        if found:
            out[rel] = found
    return out


def test_no_module_outside_the_families_branches_on_builtin_type_names() -> None:
    hits = _hits()
    unexplained = {rel: f for rel, f in hits.items() if not rel.startswith(tuple(ALLOWED))}
    assert unexplained == {}, "move the rule into its family module (docs/semantics.md §9a)"


def test_every_allowance_is_still_needed() -> None:
    hits = _hits()
    stale = [key for key in ALLOWED if not any(rel.startswith(key) for rel in hits)]
    assert stale == []


def test_the_scan_finds_branches_and_ignores_other_strings() -> None:
    names = builtin_names()
    seeded = (
        'if node.type == "Sequence":\n    pass\n'
        'ok = t in ("Fallback", "Foo")\n'
        'KINDS = frozenset({"Inverter"})\n'
        'if ctype != "SubTreePlus":\n    pass\n'
        'message = "Sequence needs children"\n'
        'symbols = {"Parallel": "=>"}\n'
        'if node.type == "MyAction":\n    pass\n'
    )
    assert branches(seeded, names) == [
        (1, "Sequence"),
        (3, "Fallback"),
        (4, "Inverter"),
        (5, "SubTreePlus"),
    ]
