"""BT -> FSM, compact (memory as data) against unrolled (memory as states), per tree.

For every behavior tree of the corpus (``FSMBT_CORPUS``, the BT files, read with the profile
options of ``corpus_coverage.py``: ``--nodes nav2,moveit_pro``, Nav2's node models, ...) and of
``examples/``, that converts today: the tree's nodes (SubTrees inlined), the SCXML element
counts (``<state>``, ``<parallel>``, ``<final>``) and transitions of the unrolled conversion
(``--unroll``) and of the compact one (the default), the data variables, the paper's formula
4M+2k+1 (M leaves, k sub-machines of the compact result), the bound of issue 24 (4·nodes+10),
and the CPU time of the compact conversion, of its proof (native checker, through the W3C
expansion of the data model; docs/conversion.md "Compact conversion") and of both together
(``--repeat N``: the least of N runs each, which a shared machine's load disturbs least).
The last line counts the trees whose conversion and proof together take under one second.
``--parallel``: only the trees with a ``Parallel`` or ``ParallelAll`` node (SubTrees inlined);
the column "par" counts the ``<parallel>`` elements of the compact SCXML (docs/semantics.md
§6a, "Parallel as `<parallel>`").

Run: PYTHONPATH=src python benchmarks/bench_compact.py [--only nav2] [--parallel] [--markdown]
[--repeat 3]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

from lxml import etree

sys.path.insert(0, str(Path(__file__).resolve().parent))
import corpus_coverage  # noqa: E402 - the sibling script: corpus files and profile options

from fsmbt import api  # noqa: E402
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm  # noqa: E402
from fsmbt.formats.scxml.structural import write_scxml  # noqa: E402
from fsmbt.model.bt import BTDocument  # noqa: E402
from fsmbt.model.errors import InputError  # noqa: E402
from fsmbt.model.fsm import FSM  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SCXML_NS = "http://www.w3.org/2005/07/scxml"


def elements(fsm: FSM) -> tuple[int, int]:
    """(``<state>`` + ``<parallel>`` + ``<final>`` elements, ``<transition>`` elements) of the
    SCXML the machine is written as."""
    return _elements(etree.fromstring(write_scxml(fsm).encode()))


def parallels(fsm: FSM) -> int:
    """``<parallel>`` elements of the SCXML the machine is written as."""
    root = etree.fromstring(write_scxml(fsm).encode())
    return sum(1 for _ in root.iter(f"{{{SCXML_NS}}}parallel"))


def has_parallel(doc: BTDocument) -> bool:
    """Whether the main tree, SubTrees inlined, holds a Parallel or ParallelAll node."""
    from fsmbt.convert.compress import inline_and_compress

    stack = [inline_and_compress(doc).compression.root]
    while stack:
        node = stack.pop()
        if node.type in ("Parallel", "ParallelAll"):
            return True
        stack.extend(node.children)
    return False


def _elements(root: etree._Element) -> tuple[int, int]:
    states = sum(
        1
        for e in root.iter()
        if e.tag in {f"{{{SCXML_NS}}}{t}" for t in ("state", "parallel", "final")}
    )
    transitions = sum(1 for _ in root.iter(f"{{{SCXML_NS}}}transition"))
    return states, transitions


def tree_nodes(doc: BTDocument) -> int:
    """Nodes of the main tree with its SubTrees inlined (the SubTree nodes themselves not
    counted)."""
    from fsmbt.convert.compress import inline_and_compress

    prepared = inline_and_compress(doc)
    count, stack = 0, [prepared.compression.root]
    while stack:
        node = stack.pop()
        count += 1
        stack.extend(node.children)
    return count + prepared.compression.merged


def inputs(only: str | None) -> list[tuple[str, Path, dict[str, object]]]:
    root = corpus_coverage.corpus_root()
    found = []
    for path, source, kind in corpus_coverage.corpus_files(root):
        negative = any(p in corpus_coverage.NEGATIVE_DIRS for p in path.parts)
        if kind != "bt" or negative or (only and only not in source):
            continue
        options = corpus_coverage.options_for("profiles", source, root, path)
        found.append((f"{source}/{path.name}", path, options))
    if not only:
        for path in sorted(EXAMPLES.glob("*_bt.xml")):
            found.append((f"examples/{path.name}", path, {}))
    return found


def measure(
    label: str, path: Path, options: dict[str, object], repeat: int = 1, only_parallel: bool = False
) -> list[object] | None:
    try:
        doc = api.load(path, options=options).model
        assert isinstance(doc, BTDocument)
        if only_parallel and not has_parallel(doc):
            return None
        unrolled = bt_to_hfsm(doc, unroll=True)
    except InputError:
        return None  # does not convert today: not part of the table
    convert_s = prove_s = total_s = math.inf
    for _ in range(max(1, repeat)):
        started = time.process_time()
        compact = bt_to_hfsm(doc)
        converted = time.process_time()
        report = api.verify_models(doc, compact.model)
        proved = time.process_time()
        convert_s = min(convert_s, converted - started)
        prove_s = min(prove_s, proved - converted)
        total_s = min(total_s, proved - started)
    nodes = tree_nodes(doc)
    u_states, u_trans = elements(unrolled.model)
    c_states, c_trans = elements(compact.model)
    formula = 4 * int(compact.stats["leaves"]) + 2 * int(compact.stats["k"]) + 1
    return [
        label,
        nodes,
        u_states,
        u_trans,
        c_states,
        c_trans,
        compact.stats["data_variables"],
        parallels(compact.model),
        formula,
        4 * nodes + 10,
        "yes" if c_states <= 4 * nodes + 10 else "NO",
        f"{convert_s:.3f}",
        f"{prove_s:.3f}",
        f"{total_s:.3f}",
        "EQUIVALENT" if report.equivalent else "NOT EQUIVALENT",
    ]


HEADER = [
    "tree",
    "nodes",
    "unrolled st",
    "unrolled tr",
    "compact st",
    "compact tr",
    "vars",
    "par",
    "4M+2k+1",
    "4n+10",
    "within",
    "convert s",
    "proof s",
    "total s",
    "verdict",
]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", help="only sources whose folder contains this text (nav2)")
    parser.add_argument("--markdown", action="store_true")
    parser.add_argument("--repeat", type=int, default=1, help="times: the least is shown")
    parser.add_argument(
        "--parallel", action="store_true", help="only trees with a Parallel or ParallelAll node"
    )
    args = parser.parse_args()
    rows = []
    for label, path, options in inputs(args.only):
        row = measure(label, path, options, args.repeat, args.parallel)
        if row is not None:
            rows.append(row)
            if not args.markdown:
                print("  ".join(str(c) for c in row), flush=True)
    if args.markdown:
        print("| " + " | ".join(HEADER) + " |")
        print("|" + "---|" * len(HEADER))
        for row in rows:
            print("| " + " | ".join(str(c) for c in row) + " |")
    within = sum(1 for r in rows if r[10] == "yes")
    proved = sum(1 for r in rows if r[14] == "EQUIVALENT")
    fast = [r for r in rows if float(str(r[13])) < 1.0]
    slowest = max(rows, key=lambda r: float(str(r[13])), default=None)
    print(
        f"\n{len(rows)} trees: {within} within 4*nodes+10 states, {proved} proven equivalent; "
        f"elements before/after: {sum(int(r[2]) for r in rows)} / {sum(int(r[4]) for r in rows)}"
    )
    if slowest is not None:
        print(
            f"conversion + proof under 1 s CPU: {len(fast)} of {len(rows)} trees; slowest "
            f"{slowest[0]} {slowest[13]} s (least of {max(1, args.repeat)} run(s))"
        )
    return 0 if within == proved == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main())
