"""BT files fsmbt writes against the XSD BehaviorTree.CPP 4.8.2 generates (prints figures).

For each file, ``fsmbt.runtime.btcpp_xsd.xsd_errors`` (``BT::writeTreeXSD`` for the built-ins
plus the written file's own ``<TreeNodesModel>``, lxml validation). Two groups:

- **generated**: FSM -> BT of every example FSM and of every corpus FSM file (SCXML, SMACH,
  FlexBE) that converts with no option - files fsmbt makes from nothing of the user's;
- **rewritten**: every corpus BT file read (no option: profiles found by themselves) and
  written back - it keeps the user's attributes and declarations, so the XSD's gaps show here;
  each failing file is tallied by the first gap it hits.

Run: FSMBT_CORPUS=../shared/corpus PYTHONPATH=src python benchmarks/btcpp_xsd_check.py
"""

from __future__ import annotations

import re
import sys
import tempfile
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from corpus_coverage import corpus_files, corpus_root  # noqa: E402

from fsmbt import api  # noqa: E402
from fsmbt.formats.btcpp.xml_format import write_btcpp  # noqa: E402
from fsmbt.model.errors import FsmbtError  # noqa: E402
from fsmbt.runtime.btcpp_xsd import find_program, xsd_errors  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def gap_of(error: str) -> str:
    """The XSD limit an error shows (docs/formats/btcpp.md), by its message."""
    text = re.sub(r"^\d+: ", "", error)
    for pattern, gap in (
        (r"is required but missing", "a declared port the tree leaves out (required in the XSD)"),
        (r"'inout_port'", "<inout_port> in <TreeNodesModel>"),
        (r"Element 'SubTree'.*not expected", "<SubTree> declared in <TreeNodesModel>"),
        (r"Element 'BehaviorTree', attribute", "a user's attribute on <BehaviorTree>"),
        (r"attribute '[^']*' is not allowed", "an attribute the node's model does not declare"),
    ):
        if re.search(pattern, text):
            return gap
    return text[:100]


def main() -> int:
    if find_program() is None:
        print("BehaviorTree.CPP 4.8.2 not built: fsmbt doctor --install btcpp", file=sys.stderr)
        return 2
    root = corpus_root()
    sources = [p for p in sorted(EXAMPLES.iterdir()) if p.suffix in (".scxml", ".csv", ".mmd")]
    sources += [EXAMPLES / "paper_fsm.json", EXAMPLES / "paper_fsm.xml"]
    sources += [p for p, _s, kind in corpus_files(root) if kind in ("scxml", "smach", "flexbe")]
    generated = valid = 0
    failures: list[str] = []  # the gap each failing file hits first
    with tempfile.TemporaryDirectory() as tmp:
        for index, source in enumerate(sources):
            out = Path(tmp) / f"{index}.xml"
            try:
                outcome = api.convert_file(source, out)
            except FsmbtError:
                continue
            if outcome.equivalent is not True or not out.is_file():
                continue
            generated += 1
            errors = xsd_errors(out.read_text(encoding="utf-8"))
            valid += not errors
            if errors:
                failures.append(gap_of(errors[0]))
    print(f"generated (FSM -> BT): {valid}/{generated} written BT files validate")
    for gap, count in Counter(failures).most_common():
        print(f"  {count} file(s): {gap}")
    rewritten = ok = 0
    gaps: Counter[str] = Counter()
    for path, _source, kind in corpus_files(root):
        if kind != "bt" or "_malformed" in path.parts:
            continue
        try:
            text = write_btcpp(api.load(path).model)
        except FsmbtError:
            continue
        rewritten += 1
        errors = xsd_errors(text)
        ok += not errors
        if errors:
            gaps[gap_of(errors[0])] += 1
    print(f"rewritten (corpus BT read and written back): {ok}/{rewritten} validate")
    for gap, count in gaps.most_common():
        print(f"  {count} file(s): {gap}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
