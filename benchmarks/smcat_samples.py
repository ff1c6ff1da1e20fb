"""state-machine-cat's own sample files through fsmbt's smcat reader (prints tables).

Give it a folder of ``.smcat`` files (e.g. every ``*.smcat`` of a checkout of
sverweij/state-machine-cat: its docs pictures, samples and parser fixtures). For each file it
asks state-machine-cat itself (``tools/smcat``, ``smcat -T json``) whether the text parses, then
reads it with fsmbt and, when that works, converts it (rules engine) and verifies the result.
It prints: how many files each side accepts, the disagreements (a file state-machine-cat parses
that fsmbt calls a syntax error, or the reverse), and fsmbt's refusals by reason.

Run: PYTHONPATH=src python benchmarks/smcat_samples.py FOLDER [--markdown]
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from collections import Counter
from pathlib import Path

from fsmbt import api
from fsmbt.model.errors import InputError, UnsupportedError

SMCAT = Path(__file__).resolve().parents[1] / "tools" / "smcat" / "node_modules" / ".bin" / "smcat"


def their_verdict(path: Path) -> bool:
    run = subprocess.run(
        [str(SMCAT), "-T", "json", str(path), "-o", "-"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    return run.returncode == 0


def reason_of(exc: Exception) -> str:
    text = str(exc).split("unsupported: ", 1)[-1]
    text = re.sub(r"'[^']*'", "'…'", text)
    text = re.sub(r"transition .*? (crosses|has)", r"transition … \1", text)
    text = re.sub(r"\[[^\]]*\]", "[…]", text)
    return text[:100]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path)
    parser.add_argument("--markdown", action="store_true")
    args = parser.parse_args()
    if not SMCAT.exists():
        print("state-machine-cat is not installed: run scripts/install_smcat.sh", file=sys.stderr)
        return 2
    files = sorted(args.folder.rglob("*.smcat"))
    parsed = read = converted = 0
    disagreements: list[str] = []
    refusals: Counter[str] = Counter()
    for path in files:
        theirs = their_verdict(path)
        parsed += theirs
        try:
            model = api.load(path).model
        except UnsupportedError as exc:
            refusals[reason_of(exc)] += 1
            continue
        except InputError as exc:
            if theirs:
                disagreements.append(f"{path.name}: fsmbt: {exc}")
            continue
        read += 1
        if not theirs:
            disagreements.append(f"{path.name}: fsmbt reads what state-machine-cat refuses")
        try:
            outcome = api.convert_file(path)
        except (InputError, UnsupportedError) as exc:
            refusals[f"convert: {reason_of(exc)}"] += 1
            continue
        converted += api.verdict_word(outcome.report) == "EQUIVALENT"
        del model
    bar = "|" if args.markdown else ""
    print(f"{len(files)} files; state-machine-cat parses {parsed}")
    print(f"fsmbt reads {read}; converts and verifies {converted}")
    print(f"syntax disagreements: {len(disagreements)}")
    for line in disagreements:
        print(f"  {line}")
    print("fsmbt's refusals (unsupported constructs), by reason:")
    for reason, count in refusals.most_common():
        print(f"{bar} {count} {bar} {reason} {bar}" if bar else f"  {count:3d}  {reason}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
