"""Located findings (``Issue``) printed for people, editors and CI: the compiler form, JSON,
SARIF 2.1.0 and a rich table (docs/cli.md, "Diagnostics").

Rules:
- The default is the compiler form, one finding per line, which editors and CI annotate:
  ``file:line:col: severity: element: message [code]`` (``:col`` and ``:line`` only when known;
  ``element: `` only when the finding names one). Newlines in a message become spaces, so a
  finding is always one line.
- ``code`` is the stable name of the check (``Issue.code``); the list with its meaning is
  ``CODES`` here and the table in docs/cli.md (a test keeps the two equal).
- SARIF is the Static Analysis Results Interchange Format 2.1.0 (OASIS), what GitHub code
  scanning reads: one run, the tool ``fsmbt`` with one rule per code used, one result per
  finding with a physical location when the finding has a file.
- The table (``--format table``) is for a wide terminal; it wraps messages.

Cost: O(findings).
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.markup import escape
from rich.table import Table

from fsmbt import __version__
from fsmbt.model.errors import SourceLocation
from fsmbt.model.validate import Issue

#: Every code a finding of ``fsmbt validate`` may carry, with what it means (docs/cli.md).
CODES: dict[str, str] = {
    # reading
    "reader": "the reader changed or ignored part of the file (a documented deviation)",
    # FSMs
    "fsm-no-states": "the state machine has no states",
    "state-name-reused": "a state name is used at two places of a hierarchy",
    "empty-submachine": "a composite state has an empty sub-machine",
    "no-initial": "a machine has no initial state",
    "bad-initial": "the initial state is not a state of its machine",
    "unknown-state": "a transition starts or ends at a name that is not a state",
    "nondeterministic": "one state and event lead to two targets",
    "duplicate-transition": "the same transition is written twice",
    "final-has-transition": "a final state has an outgoing transition",
    "composite-action": "a composite state has an action of its own",
    "dead-end": "a state with no way out is not marked final",
    "transient-state": "a state left by an eventless transition: its action is not observable",
    "unreachable": "a state cannot be reached from the initial state",
    # behavior trees
    "no-tree": "the document holds no behavior tree",
    "unknown-main-tree": "the main tree named is not defined",
    "no-main-tree": "several trees and no main tree named",
    "empty-tree": "a tree has no root",
    "unknown-node": "a node type that is neither built in nor declared",
    "undeclared-leaf": "leaf types that are not declared (assumed Actions that may run)",
    "unknown-semantics": "a custom control or decorator whose behaviour fsmbt does not know",
    "childless-node": "a node without children that its own rule gives a result",
    "no-children": "a control node without children",
    "child-count": "a node with a number of children its kind does not take",
    "subtree-children": "a SubTree node with children",
    "subtree-no-id": "a SubTree node without an ID",
    "subtree-builtin-id": "a SubTree ID that is the name of a built-in node",
    "missing-subtree": "a SubTree names a tree that is not defined",
    "leaf-children": "a leaf with children",
    "time-based": "a time-based node: fsmbt does not model time",
    "recursive-subtree": "SubTrees that reach themselves",
    "lebt-port": "an LEBT leaf whose ports contradict the tree's structure",
    # conversion
    "invalid-tree": "a node the BehaviorTree.CPP v4 rules refuse (conversion refuses it too)",
    "cannot-convert": "a valid model fsmbt cannot convert exactly yet (an error with --strict)",
}

SARIF_SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"

_LOCATED = re.compile(r"^(?P<file>[^\n]*?):(?P<line>\d+)(?::(?P<column>\d+))?: (?P<rest>.*)$", re.S)


def reader_warning(text: str, model: Path) -> Issue:
    """A reader's warning (``file:line: element: message``) as a located ``Issue``."""
    match = _LOCATED.match(text)
    if match is not None:
        column = match.group("column")
        location = SourceLocation(
            match.group("file"), int(match.group("line")), int(column) if column else None
        )
        return Issue("warning", match.group("rest"), location, None, "reader")
    prefix = f"{model}: "
    message = text[len(prefix) :] if text.startswith(prefix) else text
    return Issue("warning", message, SourceLocation(str(model), None, None), None, "reader")


def compiler_line(issue: Issue, model: Path) -> str:
    """``file:line:col: severity: element: message [code]`` on one line."""
    loc = issue.location
    where = str(loc) if loc is not None and loc.file else str(model)
    if loc is not None and not loc.file and loc.line is not None:
        where = str(SourceLocation(str(model), loc.line, loc.column))
    element = f"{issue.element}: " if issue.element else ""
    code = f" [{issue.code}]" if issue.code else ""
    text = f"{where}: {issue.severity}: {element}{issue.message}{code}"
    return " ".join(text.splitlines())


def print_compiler(model: Path, kind: str, issues: list[Issue]) -> None:
    """Every finding in the compiler form, then one summary line."""
    for issue in issues:
        print(compiler_line(issue, model))
    errors = sum(i.severity == "error" for i in issues)
    if not issues:
        print(f"{model}: valid {kind.upper()}, no issues")
    else:
        print(f"{model}: {errors} error(s), {len(issues) - errors} warning(s)")


def as_json(model: Path, kind: str, issues: list[Issue], valid: bool) -> str:
    """The findings as one JSON document (``--format json``)."""
    return json.dumps(
        {
            "file": str(model),
            "kind": kind,
            "valid": valid,
            "errors": sum(i.severity == "error" for i in issues),
            "warnings": sum(i.severity == "warning" for i in issues),
            "issues": [i.to_dict() for i in issues],
        },
        indent=2,
        ensure_ascii=False,
    )


def as_sarif(model: Path, issues: list[Issue], *, strict: bool = False) -> dict[str, Any]:
    """The findings as a SARIF 2.1.0 log (``--format sarif``).

    Args:
        model: The file validated (the location of findings that name no file).
        issues: The findings.
        strict: Warnings count as errors (``--strict``): their level is ``error``.

    Returns:
        The log, ready for ``json.dumps``.
    """
    used = sorted({i.code or "reader" for i in issues})
    rules = [
        {
            "id": code,
            "name": "".join(part.capitalize() for part in code.split("-")),
            "shortDescription": {"text": CODES.get(code, code)},
        }
        for code in used
    ]
    index = {code: n for n, code in enumerate(used)}
    results = []
    for issue in issues:
        code = issue.code or "reader"
        loc = issue.location
        file = loc.file if loc is not None and loc.file else str(model)
        physical: dict[str, Any] = {"artifactLocation": {"uri": Path(file).as_posix()}}
        if loc is not None and loc.line is not None and loc.line >= 1:
            region: dict[str, int] = {"startLine": loc.line}
            if loc.column is not None and loc.column >= 1:
                region["startColumn"] = loc.column
            physical["region"] = region
        element = f"{issue.element}: " if issue.element else ""
        level = "error" if issue.severity == "error" or strict else "warning"
        results.append(
            {
                "ruleId": code,
                "ruleIndex": index[code],
                "level": level,
                "message": {"text": f"{element}{issue.message}"},
                "locations": [{"physicalLocation": physical}],
            }
        )
    return {
        "$schema": SARIF_SCHEMA,
        "version": "2.1.0",
        "runs": [
            {
                "tool": {
                    "driver": {
                        "name": "fsmbt",
                        "version": __version__,
                        "rules": rules,
                    }
                },
                "results": results,
            }
        ],
    }


def print_table(model: Path, kind: str, issues: list[Issue]) -> None:
    """The findings as a rich table (``--format table``)."""
    console = Console()
    if not issues:
        console.print(f"{escape(str(model))}: valid {kind.upper()}, no issues")
        return
    table = Table(title=escape(str(model)), title_justify="left")
    table.add_column("severity", no_wrap=True)
    table.add_column("where")
    table.add_column("element")
    table.add_column("message")
    table.add_column("code", no_wrap=True)
    for issue in issues:
        style = "red" if issue.severity == "error" else "yellow"
        table.add_row(
            f"[{style}]{issue.severity}[/{style}]",
            escape(str(issue.location)) if issue.location else "-",
            escape(issue.element or "-"),
            escape(issue.message),
            escape(issue.code or "-"),
        )
    console.print(table)
    errors = sum(i.severity == "error" for i in issues)
    console.print(f"{errors} error(s), {len(issues) - errors} warning(s)")
