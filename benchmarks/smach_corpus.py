"""The SMACH / FlexBE corpus table: for each file, does it read, convert (FSM -> BT with the
rules engine) and verify equivalent, and round-trip through the SMACH writer? Prints a
Markdown table with the model's size and the measured times, or the exact blocker.

    .venv/bin/python benchmarks/smach_corpus.py [CORPUS]   (default: $FSMBT_CORPUS or
                                                            ../shared/corpus)
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

from fsmbt import api
from fsmbt.convert import convert
from fsmbt.formats import loads
from fsmbt.formats.pysm.smach_write import write_smach
from fsmbt.model.errors import FsmbtError
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM
from fsmbt.verify import verify


def main() -> int:
    default = os.environ.get(
        "FSMBT_CORPUS", str(Path(__file__).resolve().parents[1] / ".." / "shared" / "corpus")
    )
    corpus = Path(sys.argv[1] if len(sys.argv) > 1 else default) / "fsm"
    files = sorted(
        [
            *corpus.glob("smach_tutorials/*.py"),
            *corpus.glob("smach_tests/*.py"),
            *corpus.glob("flexbe_turtlesim_demo/*_sm.py"),
        ]
    )
    if not files:
        print(f"no SMACH/FlexBE files under {corpus}", file=sys.stderr)
        return 2
    print(
        "| file | reads | states (all levels / flat) | warnings | converts + verifies | "
        "SMACH round trip | read ms | convert+verify ms |"
    )
    print("|---|---|---|---|---|---|---|---|")
    totals = {"read": 0, "verified": 0, "round": 0}
    for path in files:
        name = f"{path.parent.name}/{path.name}"
        warnings: list[str] = []
        start = time.perf_counter()
        try:
            model = api.load(path, warnings=warnings).model
        except FsmbtError as exc:
            print(f"| {name} | no: {exc} | | | | | | |")
            continue
        read_ms = (time.perf_counter() - start) * 1000
        assert isinstance(model, FSM)
        totals["read"] += 1
        size = f"{sum(1 for _ in model.walk())} / {len(flatten(model).states)}"
        start = time.perf_counter()
        try:
            result = convert(model)
            verdict = "yes" if verify(model, result.model).equivalent else "NOT EQUIVALENT"
        except FsmbtError as exc:
            verdict = f"no: {exc}"
        convert_ms = (time.perf_counter() - start) * 1000
        totals["verified"] += verdict == "yes"
        try:
            again = loads(write_smach(model), "smach")
            round_trip = "equivalent" if verify(model, again).equivalent else "NOT EQUIVALENT"
        except FsmbtError as exc:
            round_trip = f"no: {exc}"
        totals["round"] += round_trip == "equivalent"
        print(
            f"| {name} | yes | {size} | {len(warnings)} | {verdict} | {round_trip} | "
            f"{read_ms:.1f} | {convert_ms:.1f} |"
        )
    print(
        f"\n{len(files)} files: {totals['read']} read, {totals['verified']} convert and verify, "
        f"{totals['round']} round-trip through the SMACH writer"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
