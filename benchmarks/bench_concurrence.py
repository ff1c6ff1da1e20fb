"""How many Concurrences of the corpus become a Parallel in the structured style, and why the
others keep their product form (prints a table; not a test). docs/semantics.md §11,
"Concurrences: Parallel or product", "Container children", "YASMIN concurrences",
"Concurrence callbacks".

Inputs: every SMACH / FlexBE / YASMIN file of the shared corpus (``$FSMBT_CORPUS``, else
``../shared/corpus``) that mentions ``Concurrence``, ``ConcurrencyContainer`` or
``OrthogonalState``, the examples/ folder's, and the small sources of
``tests/data/concurrence`` (container children, loops, callbacks, YASMIN). Each is read as its
format says, converted with ``--style structured``, verified (the outcome pairing) and
load-checked in BehaviorTree.CPP 4.8.2, as ``fsmbt convert`` does; a file the reader refuses is
counted with its one-line reason. For each concurrence: its children (leaves / containers), the
form it became, or the cause named in the warning.

Run: .venv/bin/python benchmarks/bench_concurrence.py
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from fsmbt import api
from fsmbt.convert.structured.schedule import read_structured_view
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM

REPO = Path(__file__).resolve().parents[1]
CORPUS = Path(os.environ.get("FSMBT_CORPUS", REPO / ".." / "shared" / "corpus")) / "fsm"
TESTS = REPO / "tests" / "data" / "concurrence"
_MENTION = re.compile(r"Concurrence|ConcurrencyContainer|OrthogonalState")
_KIND = r"(Concurrence|ConcurrencyContainer|OrthogonalState)"
_FORM = re.compile(rf"^{_KIND} '([^']*)': a (.*) over its children(, then [^,]*)?")
_KEPT = re.compile(rf"^{_KIND} '([^']*)': kept as .*not a Parallel: (.*)")


def files() -> list[Path]:
    found: list[Path] = []
    for folder in (CORPUS, REPO / "examples", TESTS):
        for pattern in ("*.py", "*.xml"):
            found += [p for p in sorted(folder.rglob(pattern)) if _MENTION.search(p.read_text())]
    return found


def _children(outcome: api.Outcome) -> dict[str, str]:
    """Each concurrence's path (or machine name) -> its children, in words."""
    model = outcome.source.model
    if not isinstance(model, FSM):
        return {}
    view = read_structured_view(model)
    out: dict[str, str] = {}
    for path, region in view.regions.items():
        c = region.concurrence
        if c is not None:
            boxes = len(c.machines)
            out[path or model.name] = f"{len(c.labels) - boxes} leaves, {boxes} containers"
    return out


def _name(path: Path) -> str:
    for folder in (CORPUS, REPO):
        if path.is_relative_to(folder):
            return str(path.relative_to(folder))
    return path.name


def main() -> None:
    parallels = kept = refused = 0
    print("| file | concurrence | children | result | verdict | loads |")
    print("|---|---|---|---|---|---|")
    for path in files():
        name = _name(path)
        try:
            outcome = api.convert_file(path, style="structured")
        except InputError as exc:
            refused += 1
            print(f"| {name} | - | - | refused: {str(exc).splitlines()[0][:90]} | - | - |")
            continue
        verdict = api.verdict_word(outcome.report)
        loads = "yes" if outcome.load is not None and outcome.load.loaded else "no"
        children = _children(outcome)
        for warning in outcome.conversion.warnings:
            form, rest = _FORM.match(warning), _KEPT.match(warning)
            if form:
                parallels += 1
                where = form.group(2)
                result = form.group(3) + (form.group(4) or "")
                print(f"| {name} | {where} | {children.get(where, '?')} | {result} | "
                      f"{verdict} | {loads} |")  # fmt: skip
            elif rest:
                kept += 1
                where = rest.group(2)
                print(f"| {name} | {where} | {children.get(where, '?')} | product: "
                      f"{rest.group(3)} | {verdict} | {loads} |")  # fmt: skip
    total = parallels + kept
    print(
        f"\nconcurrences: {total}; Parallel/ParallelAll: {parallels}; "
        f"product (named fallback): {kept}; files refused by the reader: {refused}"
    )


if __name__ == "__main__":
    main()
