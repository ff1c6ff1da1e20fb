"""BT Parallel / ParallelAll as an SCXML ``<parallel>`` (issue 24; docs/semantics.md §6a,
"Parallel as `<parallel>`"): corpus and generated trees convert with one region per child,
are proven equivalent through the W3C reading of their data, read back byte for byte and stay
within 4 * nodes + 10 state elements; a wrong threshold or a wrong region order is caught; a
Parallel that cannot be expressed keeps the product form and the warning says why."""

from __future__ import annotations

import pytest
from lxml import etree

from fsmbt import api
from fsmbt.convert.bt_to_hfsm import bt_to_hfsm
from fsmbt.formats import dumps, loads
from fsmbt.model.bt import BTDocument
from fsmbt.model.fsm import FSM
from fsmbt.model.fsm_data import COND, has_data
from support.corpus import CORPUS, profile_options
from support.parallel_trees import parallel_tree_xml

SCXML = "{http://www.w3.org/2005/07/scxml}"
#: Corpus trees whose Parallel heads its region (plain children; a RepeatUnlessFailureEachTick
#: in the last one's second child).
CORPUS_PARALLEL = (
    "bt/moveit_pro/kitchen_sim__write_text.xml",
    "bt/moveit_pro/dual_arm_sim__draw.xml",
    "bt/moveit_pro/hangar_sim__cartesian_draw_geometry_from_file.xml",
)


def counts(fsm: FSM) -> tuple[int, int]:
    """(``<state>`` + ``<parallel>`` + ``<final>`` elements, ``<parallel>`` elements)."""
    root = etree.fromstring(dumps(fsm, "scxml").encode())
    tags = [e.tag for e in root.iter() if isinstance(e.tag, str)]
    states = sum(1 for t in tags if t in {f"{SCXML}{k}" for k in ("state", "parallel", "final")})
    return states, tags.count(f"{SCXML}parallel")


def nodes(doc: BTDocument) -> int:
    count, stack = 0, [doc.main.root]
    while stack:
        node = stack.pop()
        count += 1
        stack.extend(node.children)
        if node.type == "SubTree" and node.attrs.get("ID") in doc.trees:
            stack.append(doc.trees[node.attrs["ID"]].root)
    return count


def proven_parallel(doc: BTDocument, label: str) -> FSM:
    """Convert; one ``<parallel>``; proven; read back to the same text; within the bound."""
    result = bt_to_hfsm(doc)
    hfsm = result.model
    states, parallels = counts(hfsm)
    assert parallels == 1 and result.stats["parallel_states"] == 1, (label, result.warnings)
    assert states <= 4 * nodes(doc) + 10, (label, states)
    report = api.verify_models(doc, hfsm)
    assert report.equivalent, (label, report.to_dict())
    text = dumps(hfsm, "scxml")
    back = loads(text, "scxml")
    assert has_data(back) and dumps(back, "scxml") == text, label
    assert api.verify_models(doc, back).equivalent, label
    return hfsm


@pytest.mark.parametrize("relative", CORPUS_PARALLEL)
def test_corpus_parallel_becomes_parallel_regions(relative: str) -> None:
    path = CORPUS / relative
    if not path.exists():
        pytest.skip(f"corpus not found at {CORPUS} (set FSMBT_CORPUS)")
    doc = api.load(path, options=profile_options(path)).model
    assert isinstance(doc, BTDocument)
    proven_parallel(doc, relative)


@pytest.mark.parametrize("memory", [False, True], ids=["plain", "memory"])
def test_generated_parallels_are_proven(memory: bool) -> None:
    """40 seeded trees each: Parallel (every success/failure threshold but 0) and ParallelAll,
    children up to three levels - plain, or with Retry/Repeat, SequenceWithMemory and reactive
    controls (their compact regions, tick ends marked) -, at the root or inside a plain
    Sequence/Fallback."""
    kinds = set()
    for seed in range(40):
        text = parallel_tree_xml(seed, memory=memory)
        doc = loads(text, "btcpp")
        proven_parallel(doc, text)
        kinds.add("ParallelAll" if "ParallelAll" in text else "Parallel")
    assert kinds == {"Parallel", "ParallelAll"}


def _one_parallel(text: str) -> tuple[BTDocument, FSM]:
    doc = loads(text, "btcpp")
    return doc, bt_to_hfsm(doc).model


TWO_OF_THREE = (
    '<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M">'
    '<Parallel name="P" success_count="2" failure_count="2">'
    '<Action ID="A"/><Sequence><Action ID="B"/><Condition ID="C"/></Sequence><Action ID="D"/>'
    "</Parallel></BehaviorTree></root>"
)


def test_a_wrong_threshold_is_caught() -> None:
    doc, hfsm = _one_parallel(TWO_OF_THREE)
    assert api.verify_models(doc, hfsm).equivalent
    guarded = [
        t for m in hfsm.machines() for t in m.transitions if t.attrs.get(COND) == "P_successes >= 2"
    ]
    assert guarded  # the result's success rule
    guarded[0].attrs[COND] = "P_successes >= 1"
    assert not api.verify_models(doc, hfsm).equivalent


def test_a_wrong_turn_order_is_caught() -> None:
    """The regions take turns in document order, as BehaviorTree.CPP ticks the children: a
    region that passes the turn to the wrong one is not the tree."""
    doc, hfsm = _one_parallel(TWO_OF_THREE)
    changed = 0
    for machine in hfsm.machines():
        for t in machine.transitions:
            assign = t.attrs.get("fsmbt:assign", "")
            if t.source == "A" and t.event == "running" and "P_turn=1" in assign:
                t.attrs["fsmbt:assign"] = assign.replace("P_turn=1", "P_turn=2")
                changed += 1
    assert changed == 1
    assert not api.verify_models(doc, hfsm).equivalent


@pytest.mark.parametrize(
    ("tree", "reason"),
    [
        (  # inside a reactive region: the ReactiveSequence halts and restarts it
            '<ReactiveSequence><Condition ID="C"/><Parallel success_count="1" '
            'failure_count="1"><Action ID="A"/><Action ID="B"/></Parallel></ReactiveSequence>',
            "inside the region of ReactiveSequence",
        ),
        (  # the retry ends a tick with no leaf ticked, then fails in the next one
            '<Parallel success_count="1" failure_count="1"><Action ID="A"/><Sequence>'
            '<Action ID="B"/><RetryUntilSuccessful num_attempts="2"><AlwaysFailure/>'
            "</RetryUntilSuccessful></Sequence></Parallel>",
            "child 2 can return its result in a tick that ticks none of its leaves",
        ),
        (  # a child that is a constant: it returns in its first tick with no leaf ticked
            '<ParallelAll><Action ID="A"/><AlwaysSuccess/></ParallelAll>',
            "child 2 returns its result in its first tick without ticking a leaf",
        ),
        (
            '<Parallel success_count="1" failure_count="1"><Action ID="A"/>'
            "<KeepRunningUntilFailure><AlwaysSuccess/></KeepRunningUntilFailure></Parallel>",
            "child 2 can end in LIVELOCK",
        ),
        (
            '<Parallel success_count="0" failure_count="1"><Action ID="A"/><Action ID="B"/>'
            "</Parallel>",
            "a threshold of 0",
        ),
        (
            '<Parallel success_count="1" failure_count="1"><Action ID="A"/></Parallel>',
            "a single child",
        ),
    ],
)
def test_inexpressible_parallels_keep_the_product_and_say_why(tree: str, reason: str) -> None:
    doc = loads(
        f'<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M">{tree}'
        "</BehaviorTree></root>",
        "btcpp",
    )
    result = bt_to_hfsm(doc)
    assert counts(result.model)[1] == 0 and result.stats["parallel_states"] == 0
    said = [w for w in result.warnings if "not <parallel>" in w]
    assert len(said) == 1 and reason in said[0] and "tree 'M'" in said[0], result.warnings
    assert api.verify_models(doc, result.model).equivalent


def test_loop_and_unroll_keep_the_product() -> None:
    """With ``loop`` the whole tree is one explored region (the warning says so); ``--unroll``
    keeps every memory as states, Parallels included, as before."""
    doc = loads(TWO_OF_THREE, "btcpp")
    looped = bt_to_hfsm(doc, loop=True)
    assert counts(looped.model)[1] == 0
    assert any("with loop the whole tree is one explored region" in w for w in looped.warnings)
    assert api.verify_models(doc, looped.model, loop=True).equivalent
    unrolled = bt_to_hfsm(doc, unroll=True)
    assert counts(unrolled.model)[1] == 0 and not has_data(unrolled.model)
    assert api.verify_models(doc, unrolled.model).equivalent


def test_render_pages_open_the_regions(tmp_path) -> None:  # noqa: ANN001
    """``fsmbt render --pages``: the ``<parallel>``'s page draws its regions with their leaf
    states (a parallel's level counts from its regions; they were one closed box)."""
    from fsmbt.render import render_pages

    doc, hfsm = _one_parallel(TWO_OF_THREE)
    pages = render_pages(hfsm, tmp_path)
    regions = [p for p in pages if p.name.endswith("P_regions.svg")]
    assert len(regions) == 1, [p.name for p in pages]
    text = regions[0].read_text()
    for leaf in ("wait_A", ">A<", ">B<", ">C<", ">D<", "DONE"):
        assert leaf in text, leaf
    assert "states inside" not in text


@pytest.mark.nusmv
def test_nusmv_agrees_on_the_parallel_regions(nusmv_binary) -> None:  # noqa: ANN001
    """NuSMV checks the same flat meaning (the W3C expansion of the data model) and agrees:
    the conversion is equivalent, the wrong threshold is not."""
    doc, hfsm = _one_parallel(TWO_OF_THREE)
    assert api.verify_models(doc, hfsm, "both").equivalent
    for machine in hfsm.machines():
        for t in machine.transitions:
            if t.attrs.get(COND) == "P_successes >= 2":
                t.attrs[COND] = "P_successes >= 1"
    assert not api.verify_models(doc, hfsm, "nusmv").equivalent


def test_a_parallel_inside_a_child_is_named() -> None:
    """The outer Parallel becomes ``<parallel>``; the inner one, inside a child with memory,
    is part of that child's compact region, and the warning names it."""
    doc = loads(
        '<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M">'
        '<Parallel name="Outer" success_count="1" failure_count="1"><Action ID="A"/>'
        '<RetryUntilSuccessful num_attempts="2"><Parallel name="Inner" success_count="1" '
        'failure_count="1"><Action ID="B"/><Action ID="C"/></Parallel></RetryUntilSuccessful>'
        "</Parallel></BehaviorTree></root>",
        "btcpp",
    )
    result = bt_to_hfsm(doc)
    assert counts(result.model)[1] == 1
    said = [w for w in result.warnings if "not <parallel>" in w]
    assert len(said) == 1 and "'Inner'" in said[0] and "region of Parallel 'Outer'" in said[0]
    assert api.verify_models(doc, result.model).equivalent
