"""Property: a valid model written in a format that can hold it reads back equal.

Formats come from the registry (every format that reads and writes the model's kind), so a new
format is covered without a change here. What "equal" means per format is what the format can
hold (docs/formats/): the tables (csv, md) keep no machine name and create states in order of
first appearance, so their first read is compared up to those two; every format must then be
stable: read -> write -> read gives an exactly equal model. A writer may refuse a model it
cannot hold (an ``InputError`` naming why: a parallel state in Mermaid, a name the paper's text
format cannot spell); it may never write something its own reader refuses or reads differently.
DOT reads flat FSMs only (docs/formats/dot.md: BTs and hierarchical FSMs are write-only there).
Counts per format are printed (``pytest -s``).
"""

from __future__ import annotations

import dataclasses
from collections import Counter

from hypothesis import given
from hypothesis import strategies as st

from fsmbt import api
from fsmbt.formats import dumps, formats, loads
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.model.serialize import model_to_dict
from fsmbt.model.validate import errors, validate
from support.prop_strategies import BUDGET, bts, fsms

#: Formats that hold no machine name and order states by first appearance.
TABLES = {"csv", "md"}
#: (format, kind) pairs the format's documentation says are write-only.
WRITE_ONLY = {("dot", "bt")}


def kind_of(model: FSM | BTDocument) -> str:
    return "fsm" if isinstance(model, FSM) else "bt"


def held(model: FSM | BTDocument, fmt: str) -> FSM | BTDocument:
    """The part of ``model`` that ``fmt`` holds. Models compare states as a mapping (their order
    never matters); transitions are compared grouped by source state, keeping their order within
    a source (it is their priority) - writers that list transitions under their state (SCXML)
    change only the order between sources, which means nothing."""
    if not isinstance(model, FSM):
        return model
    copy = copy_fsm(model)
    if fmt in TABLES:
        copy.name = "fsm"
    stack = [copy]
    while stack:
        machine = stack.pop()
        machine.transitions = sorted(machine.transitions, key=lambda t: t.source)
        for state in machine.states.values():
            stack.extend(state.regions)
    return copy


def copy_fsm(model: FSM) -> FSM:
    import copy

    return copy.deepcopy(model)


def without_added_declarations(
    back: FSM | BTDocument, original: FSM | BTDocument
) -> FSM | BTDocument:
    """BehaviorTree.CPP XML declares every custom leaf type in ``<TreeNodesModel>`` (its reader
    needs the kind); drop the declarations the original did not have, after checking each
    declares the kind the original's nodes of that type have."""
    assert isinstance(back, BTDocument) and isinstance(original, BTDocument)
    kinds = {node.type: node.kind for _, node in original.nodes()}
    added = {t: m for t, m in back.node_models.items() if t not in original.node_models}
    for type_name, declared in added.items():
        assert kinds.get(type_name) == declared.kind, f"{type_name} declared as {declared.kind}"
    kept = {t: m for t, m in back.node_models.items() if t in original.node_models}
    return dataclasses.replace(back, node_models=kept)


def round_trip_formats(model: FSM | BTDocument) -> list[str]:
    kind = kind_of(model)
    if kind == "fsm" and model.is_hierarchical:  # type: ignore[union-attr]
        write_only = {"dot"}
    else:
        write_only = {f for f, k in WRITE_ONLY if k == kind}
    return [
        f.name
        for f in formats()
        if f.read and f.write and kind in f.kinds and f.name not in write_only
    ]


#: Writers that may rewrite a model's structure while keeping its behaviour (documented in
#: docs/formats/smach.md: a composite state's event transitions are pushed onto its inner
#: states, outcomes become final states), or whose readers add what the notation declares
#: (YASMIN: each state's class and outcomes; pytransitions: on_enter) or have no place for the
#: machine's name (state-machine-cat, a python-statemachine class name that is not one):
#: read back, such a model must be proven equivalent.
BEHAVIOUR_PRESERVING = {"smach", "yasmin", "smcat", "transitions", "pystatemachine"}


def check_round_trips(model: FSM | BTDocument, tally: Counter[str]) -> None:
    assert not errors(validate(model)), "the strategy drew an invalid model"
    for fmt in round_trip_formats(model):
        try:
            text = dumps(model, fmt)
        except InputError as exc:
            assert str(exc).strip() and "\n" not in str(exc)
            tally[f"{fmt}: refused"] += 1
            continue
        back = loads(text, fmt)
        compared = without_added_declarations(back, model) if fmt == "btcpp" else back
        if fmt in BEHAVIOUR_PRESERVING and held(compared, fmt) != held(model, fmt):
            from fsmbt.verify import verify

            assert verify(model, back).equivalent, f"{fmt} changed the behaviour:\n{text}"
            again = loads(dumps(back, fmt), fmt)
            assert verify(back, again).equivalent, f"{fmt}: read -> write -> read changed it"
            tally[f"{fmt}: equivalent"] += 1
            continue
        assert held(compared, fmt) == held(model, fmt), (
            f"{fmt} changed the model:\n{text}\n{model_to_dict(held(model, fmt))}\n"
            f"{model_to_dict(held(compared, fmt))}"
        )
        again = loads(dumps(back, fmt), fmt)
        assert again == back, f"{fmt}: read -> write -> read is not stable"
        tally[f"{fmt}: equal"] += 1


def test_every_format_reads_back_what_it_wrote_fsm() -> None:
    tally: Counter[str] = Counter()

    @BUDGET
    @given(fsms())
    def run(model: FSM) -> None:
        tally["examples"] += 1
        check_round_trips(model, tally)

    run()
    print("\nFSM round trips:", dict(sorted(tally.items())))
    assert tally["examples"] > 0
    for fmt in round_trip_formats(FSM(name="x")):
        assert tally[f"{fmt}: equal"] + tally[f"{fmt}: equivalent"] > 0, (
            f"{fmt} never round-tripped a drawn FSM"
        )


def test_every_format_reads_back_what_it_wrote_bt() -> None:
    tally: Counter[str] = Counter()

    @BUDGET
    @given(bts())
    def run(model: BTDocument) -> None:
        tally["examples"] += 1
        check_round_trips(model, tally)

    run()
    print("\nBT round trips:", dict(sorted(tally.items())))
    assert tally["examples"] > 0
    for fmt in round_trip_formats(BTDocument()):
        assert tally[f"{fmt}: equal"] > 0, f"{fmt} never round-tripped a drawn BT"


def test_hierarchical_models_from_reading_round_trip() -> None:
    """Hierarchical FSMs: the SCXML example (nested states) through every format holding it."""
    from pathlib import Path

    tally: Counter[str] = Counter()
    example = api.load(Path(__file__).resolve().parents[2] / "examples" / "door_hfsm.scxml").model
    assert isinstance(example, FSM) and example.is_hierarchical

    @BUDGET
    @given(st.just(example))
    def run(model: FSM) -> None:
        check_round_trips(model, tally)

    run()
    assert tally["scxml: equal"] > 0 and tally["json: equal"] > 0
