"""Flat against hierarchical dispatch form (prints tables; not a test): docs/semantics.md §12a,
"Size", holds its output.

For the corpus' hierarchical SCXML files that the hierarchical form keeps, seeded generated
hierarchical machines (``fsmbt.generate.hierarchical.random_hfsm``: 20, 60 and 200 states, 10
seeds each, summed) and two families that show how each form grows - one composite state of n
children with k transitions of its own (``wide``), and composites nested d deep (``deep``) -:
the XML nodes and depth of the flat dispatch form (the machine flattened first, what fsmbt
wrote before issue 23's hierarchical form) and of the hierarchical one (depth: the deepest
``BehaviorTree``; the SubTree chain is the machine's nesting), the nodes BehaviorTree.CPP
4.8.2 instantiates loading each (``check_loads``: SubTrees expanded), the CPU nanoseconds
per macro step of each in BehaviorTree.CPP (the C++ driver's ``--dispatch --bench``: 4 seeded
walks of 200 events, 20 repeats, mean over the machines of a row; one run on a shared machine,
so the figures carry its load), and whether the native checker proves every hierarchical tree
equivalent to its source.

Run: .venv/bin/python benchmarks/bench_dispatch_hier.py   (FSMBT_CORPUS: the corpus folder)
"""

from __future__ import annotations

import os
import random
import tempfile
from pathlib import Path

from fsmbt import api
from fsmbt.convert import convert
from fsmbt.formats import dumps
from fsmbt.generate.hierarchical import random_hfsm
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM, State
from fsmbt.runtime.cpp import DriverSession, require_driver
from fsmbt.semantics.engines.btcpp_load import check_loads
from fsmbt.semantics.machine import FSMMachine
from fsmbt.verify import verify

CORPUS = Path(
    os.environ.get("FSMBT_CORPUS", Path(__file__).resolve().parents[1] / ".." / "shared" / "corpus")
)
KEPT = (
    "fsm/commons_scxml/state-01.scxml",
    "fsm/scion_tests/hierarchy__hier0.scxml",
    "fsm/scion_tests/hierarchy__hier1.scxml",
    "fsm/scion_tests/hierarchy_documentOrder__test0.scxml",
)


def _wide(children: int, own: int) -> FSM:
    inner = FSM("C")
    for i in range(children):
        inner.add_state(f"c{i}")
    inner.initial = "c0"
    for i in range(children - 1):
        inner.add_transition(f"c{i}", "next", f"c{i + 1}")
    fsm = FSM(f"wide_{children}x{own}")
    fsm.add_state(State("C", action=None, regions=[inner]))
    for k in range(own):
        fsm.add_state(f"t{k}")
        fsm.add_transition("C", f"go{k}", f"t{k}")
        fsm.add_transition(f"t{k}", "back", "C")
    fsm.initial = "C"
    return fsm


def _deep(depth: int) -> FSM:
    fsm = FSM(f"deep_{depth}")
    machine = fsm
    for level in range(depth):
        inner = FSM(f"L{level}")
        machine.add_state(State(f"L{level}", action=None, regions=[inner]))
        machine.add_state(f"x{level}")
        machine.initial = f"L{level}"
        machine.add_transition(f"L{level}", f"out{level}", f"x{level}")
        machine.add_transition(f"x{level}", f"in{level}", f"L{level}")
        machine = inner
    machine.add_state("leaf")
    machine.initial = "leaf"
    return fsm


def _walks(fsm: FSM, seed: int) -> list[list[str]]:
    """4 seeded walks of 200 events, mostly events the state reacts to."""
    machine = FSMMachine(fsm)
    rng = random.Random(seed)
    walks = []
    for _ in range(4):
        events, state = [], machine.start()[0]
        for _ in range(200):
            active = list(machine.active_inputs(state)) or list(machine.alphabet) or ["none"]
            events.append(rng.choice(active))
            state = machine.step(state, events[-1])[0]
        walks.append(events)
    return walks


def _ns_per_step(text: str, walks: list[list[str]], folder: Path) -> float:
    tree = folder / "tree.xml"
    tree.write_text(text, encoding="utf-8")
    session = DriverSession(tree, driver=require_driver(), dispatch=True, timeout=1200)
    return float(session.bench(walks, 20)["cpu_ns_per_step"])


def _measure(fsms: list[FSM], folder: Path) -> list[object]:
    """Summed over ``fsms``: flat states, flat nodes, max flat depth, hierarchical nodes, max
    depth, SubTrees, BT.CPP instantiated nodes flat / hierarchical, mean ns per step flat /
    hierarchical, all proven."""
    row: list[object] = [0, 0, 0, 0, 0, 0, 0, 0, 0.0, 0.0, True]
    for k, fsm in enumerate(fsms):
        flat_fsm = flatten(fsm)
        flat = convert(flat_fsm, style="dispatch")
        hier = convert(fsm, style="dispatch")
        assert hier.stats.get("form") == "hierarchical", (fsm.name, hier.warnings)
        flat_text, hier_text = dumps(flat.model, "btcpp"), dumps(hier.model, "btcpp")
        loads_flat, loads_hier = check_loads(flat_text), check_loads(hier_text)
        assert loads_flat.loaded and loads_hier.loaded, (loads_flat.error, loads_hier.error)
        walks = _walks(fsm, k)
        sums = [
            len(flat_fsm.states),
            int(flat.stats["nodes"]),
            0,
            int(hier.stats["nodes"]),
            0,
            int(hier.stats["subtrees"]),
            loads_flat.nodes or 0,
            loads_hier.nodes or 0,
            _ns_per_step(flat_text, walks, folder) / len(fsms),
            _ns_per_step(hier_text, walks, folder) / len(fsms),
        ]
        for i, value in enumerate(sums):
            row[i] = row[i] + value  # type: ignore[operator]
        row[2] = max(int(row[2]), int(flat.stats["depth"]))  # type: ignore[call-overload]
        row[4] = max(int(row[4]), int(hier.stats["depth"]))  # type: ignore[call-overload]
        row[10] = bool(row[10]) and verify(fsm, hier.model).equivalent
    return row


def main() -> None:
    cases: list[tuple[str, list[FSM]]] = []
    for name in KEPT:
        path = CORPUS / name
        if path.exists():
            model = api.load(path).model
            assert isinstance(model, FSM)
            cases.append((f"corpus {path.name}", [model]))
    for size in (20, 60, 200):
        cases.append(
            (f"random_hfsm {size} states, seeds 0-9", [random_hfsm(s, size) for s in range(10)])
        )
    for n, k in ((10, 10), (20, 20), (40, 40)):
        cases.append((f"wide: {n} children x {k} own transitions", [_wide(n, k)]))
    for depth in (5, 15, 30):
        cases.append((f"deep: {depth} nested composites", [_deep(depth)]))
    print(
        "| machine(s) | flat states | flat dispatch nodes / depth "
        "| hierarchical nodes / depth / SubTrees | BT.CPP instantiated nodes flat / hier "
        "| BT.CPP ns/step flat / hier | proven |"
    )
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for label, fsms in cases:
            r = _measure(fsms, Path(tmp))
            print(
                f"| {label} | {r[0]} | {r[1]} / {r[2]} | {r[3]} / {r[4]} / {r[5]} "
                f"| {r[6]} / {r[7]} | {r[8]:,.0f} / {r[9]:,.0f} | {r[10]} |"
            )


if __name__ == "__main__":
    main()
