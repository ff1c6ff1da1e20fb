"""Presentation only in ``cli/`` and ``web/`` (docs/architecture.md, issue 25): no other module of
fsmbt imports rich or calls ``print``; the library returns data and takes callbacks (progress
hooks), the interfaces draw. Read with ``ast`` (a ``print`` inside a string the runtime writes
out as a user's example is not a call)."""

from __future__ import annotations

import ast
from pathlib import Path

import fsmbt

PACKAGE = Path(fsmbt.__file__).parent
PRESENTATION = ("cli", "web")


def test_no_library_module_draws_or_prints() -> None:
    offenders: list[str] = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        if rel.split("/")[0] in PRESENTATION:
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=rel)
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                names = [node.module or ""]
            else:
                names = []
            if any(name == "rich" or name.startswith("rich.") for name in names):
                offenders.append(f"{rel}:{node.lineno}: imports rich")
            if (
                isinstance(node, ast.Call)
                and isinstance(node.func, ast.Name)
                and node.func.id == "print"
            ):
                offenders.append(f"{rel}:{node.lineno}: print(...)")
    assert offenders == []
