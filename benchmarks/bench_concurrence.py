"""How many Concurrences of the corpus become a Parallel in the structured style, and why the
others keep their product form (prints a table; not a test). docs/semantics.md §11,
"Concurrences: Parallel or product".

Inputs: every SMACH / FlexBE file of the shared corpus (``$FSMBT_CORPUS``, else
``../shared/corpus``) that mentions ``Concurrence`` or ``ConcurrencyContainer``, and the
examples/ folder's. Each is read as its format says, converted with ``--style structured``,
verified (the outcome pairing) and load-checked in BehaviorTree.CPP 4.8.2, as
``fsmbt convert`` does; a file the reader refuses is counted with its one-line reason. For each
concurrence of leaf children: the form it became, or the cause named in the warning.

Run: .venv/bin/python benchmarks/bench_concurrence.py
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from fsmbt import api
from fsmbt.model.errors import InputError

REPO = Path(__file__).resolve().parents[1]
CORPUS = Path(os.environ.get("FSMBT_CORPUS", REPO / ".." / "shared" / "corpus")) / "fsm"
_MENTION = re.compile(r"Concurrence|ConcurrencyContainer")
_FORM = re.compile(r"^(Concurrence|ConcurrencyContainer) '([^']*)': a (.*) over its children")
_KEPT = re.compile(r"^(Concurrence|ConcurrencyContainer) '([^']*)': kept as .*not a Parallel: (.*)")


def files() -> list[Path]:
    found = [p for p in sorted(CORPUS.rglob("*.py")) if _MENTION.search(p.read_text())]
    return found + [p for p in sorted((REPO / "examples").glob("*.py"))
                    if _MENTION.search(p.read_text())]  # fmt: skip


def main() -> None:
    parallels = kept = refused = 0
    print("| file | concurrence | result | verdict | loads |")
    print("|---|---|---|---|---|")
    for path in files():
        name = str(path.relative_to(CORPUS)) if path.is_relative_to(CORPUS) else path.name
        try:
            outcome = api.convert_file(path, style="structured")
        except InputError as exc:
            refused += 1
            print(f"| {name} | - | refused: {str(exc).splitlines()[0][:90]} | - | - |")
            continue
        verdict = api.verdict_word(outcome.report)
        loads = "yes" if outcome.load is not None and outcome.load.loaded else "no"
        for warning in outcome.conversion.warnings:
            form, rest = _FORM.match(warning), _KEPT.match(warning)
            if form:
                parallels += 1
                print(f"| {name} | {form.group(2)} | {form.group(3)} | {verdict} | {loads} |")
            elif rest:
                kept += 1
                print(f"| {name} | {rest.group(2)} | product: {rest.group(3)} | {verdict} | "
                      f"{loads} |")  # fmt: skip
    total = parallels + kept
    print(
        f"\nconcurrences of leaf children: {total}; Parallel/ParallelAll: {parallels}; "
        f"product (named fallback): {kept}; files refused by the reader: {refused}"
    )


if __name__ == "__main__":
    main()
