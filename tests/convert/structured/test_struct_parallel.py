"""A Concurrence becomes a Parallel where the semantics allow, else keeps its named product form
(docs/semantics.md §11, "Concurrences: Parallel or product"): the tree is written, proven
EQUIVALENT and loads in BehaviorTree.CPP; a wrong threshold or a halting Parallel in place of a
ParallelAll is found NOT EQUIVALENT; a map no parallel node expresses is named."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest

from fsmbt import api
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.semantics.outcome_parallel import FLEXBE, SMACH, Concurrence, choose_form
from fsmbt.semantics.outcome_rules import FAILURE, SUCCESS
from fsmbt.verify import verify
from support.corpus import CORPUS

HEADER = """import smach


class Two(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=["done", "failed"])


class Last(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=["succeeded", "aborted"])


def build():
    sm = smach.StateMachine(outcomes=["finished", "gave_up"])
    with sm:
        cc = smach.Concurrence(
            outcomes=["ok", "bad"],
            default_outcome="bad",
            outcome_map=MAP,
        )
        with cc:
            smach.Concurrence.add("A", Two())
            smach.Concurrence.add("B", Two())
            smach.Concurrence.add("C", Two())
        smach.StateMachine.add("CC", cc, transitions={"ok": "LAST", "bad": "gave_up"})
        smach.StateMachine.add("LAST", Last(), transitions={"succeeded": "finished",
                                                           "aborted": "gave_up"})
    return sm
"""
EVERY = '{"ok": {"A": "done", "B": "done", "C": "done"}}'
ONLY_A = '{"ok": {"A": "done"}}'


def _write(tmp_path: Path, mapping: str) -> Path:
    path = tmp_path / "cc_smach.py"
    path.write_text(HEADER.replace("MAP", mapping))
    return path


def _convert(path: Path) -> api.Outcome:
    return api.convert_file(path, style="structured")


def _node(doc: BTDocument, kind: str) -> BTNode:
    return next(n for _t, n in doc.nodes() if n.type == kind)


def test_every_child_succeeding_is_a_parallel_all_proven_and_loaded(tmp_path: Path) -> None:
    outcome = _convert(_write(tmp_path, EVERY))
    doc = outcome.conversion.model
    assert isinstance(doc, BTDocument)
    node = _node(doc, "ParallelAll")
    assert node.attrs == {"max_failures": "1"}
    assert [c.name for c in node.children] == ["A", "B", "C"]
    assert outcome.report is not None and outcome.report.equivalent
    assert outcome.load is not None and outcome.load.loaded
    assert outcome.conversion.stats["parallels"] == 1
    assert "1 parallel," in str(outcome.conversion.stats["summary"])
    assert any("ParallelAll max_failures=1" in w for w in outcome.conversion.warnings)
    abstractions = outcome.report.stats["abstractions"]
    assert any("read in rounds" in a and a.endswith(": CC") for a in abstractions)


def test_a_wrong_threshold_or_a_halting_parallel_is_not_equivalent(tmp_path: Path) -> None:
    path = _write(tmp_path, EVERY)
    source = api.load(path).model
    doc = _convert(path).conversion.model
    assert isinstance(doc, BTDocument)
    wrong = copy.deepcopy(doc)
    _node(wrong, "ParallelAll").attrs["max_failures"] = "2"
    assert verify(source, wrong, outcome_driven=True).equivalent is False
    # Parallel success_count=3 failure_count=1 decides the same status, but halts the others
    # at the first failure, where SMACH lets every child finish: the leaf ticks differ
    halting = copy.deepcopy(doc)
    node = _node(halting, "ParallelAll")
    node.type = "Parallel"
    node.attrs = {"success_count": "3", "failure_count": "1"}
    report = verify(source, halting, outcome_driven=True)
    assert report.equivalent is False


def test_at_least_one_of_three_is_parallel_all_with_three_failures(tmp_path: Path) -> None:
    # "bad" only when every child failed, else the default "ok"
    path = _write(tmp_path, '{"bad": {"A": "failed", "B": "failed", "C": "failed"}}')
    path.write_text(path.read_text().replace('default_outcome="bad"', 'default_outcome="ok"'))
    outcome = _convert(path)
    doc = outcome.conversion.model
    assert isinstance(doc, BTDocument)
    assert _node(doc, "ParallelAll").attrs == {"max_failures": "3"}
    assert outcome.report is not None and outcome.report.equivalent


def test_a_map_no_parallel_expresses_keeps_the_product_and_names_why(tmp_path: Path) -> None:
    outcome = _convert(_write(tmp_path, ONLY_A))
    doc = outcome.conversion.model
    assert isinstance(doc, BTDocument)
    assert not any(n.type.startswith("Parallel") for _t, n in doc.nodes())
    assert outcome.conversion.stats["parallels"] == 0
    named = [w for w in outcome.conversion.warnings if "kept as its product machine" in w]
    assert len(named) == 1
    assert "outcome_map entry 'ok'" in named[0] or "default_outcome 'bad'" in named[0]
    assert "A=" in named[0]
    assert outcome.report is not None and outcome.report.equivalent


FLEXBE_FILE = CORPUS / "fsm" / "flexbe_turtlesim_demo" / "example_3_sm.py"


@pytest.mark.skipif(not FLEXBE_FILE.exists(), reason="corpus not present (FSMBT_CORPUS)")
def test_flexbe_or_and_and_containers_are_halting_parallels() -> None:
    outcome = _convert(FLEXBE_FILE)
    doc = outcome.conversion.model
    assert isinstance(doc, BTDocument)
    forms = sorted(
        (n.attrs["success_count"], n.attrs["failure_count"])
        for _t, n in doc.nodes()
        if n.type == "Parallel"
    )
    assert forms == [("1", "1"), ("2", "1")]
    assert outcome.report is not None and outcome.report.equivalent
    assert outcome.load is not None and outcome.load.loaded
    # FlexBE stops the other child at the first failure: a ParallelAll, which lets it finish,
    # is found NOT EQUIVALENT
    waiting = copy.deepcopy(doc)
    node = next(n for _t, n in waiting.nodes() if n.attrs.get("success_count") == "2")
    node.type, node.attrs = "ParallelAll", {"max_failures": "1"}
    assert verify(outcome.source.model, waiting, outcome_driven=True).equivalent is False


def _two(cls: str, mapping: list[tuple[str, dict[str, str]]], default: str | None) -> Concurrence:
    outs = [["done", "failed"], ["done", "failed"]]
    return Concurrence(cls, ["A", "B"], ["X", "Y"], outs, mapping, default)


STATUS = [{"done": SUCCESS, "failed": FAILURE}] * 2


def test_flexbe_conditions_that_can_all_fail_to_hold_keep_the_product() -> None:
    c = _two(FLEXBE, [("finished", {"A": "done", "B": "done"})], None)
    choose_form(c, STATUS, lambda o: (SUCCESS, ""))
    assert c.form is None
    assert "no condition holds" in c.why and "A=" in c.why


def test_an_outcome_without_a_status_keeps_the_product_and_is_named() -> None:
    c = _two(SMACH, [("ok", {"A": "done", "B": "done"})], "bad")
    choose_form(c, STATUS, lambda o: (None, "halts the tree") if o == "bad" else (SUCCESS, ""))
    assert c.form is None
    assert c.why == "its outcome 'bad' halts the tree"


def test_smach_every_child_is_parallel_all_flexbe_first_failure_is_a_halting_parallel() -> None:
    statuses = {"ok": SUCCESS, "bad": FAILURE}
    smach = _two(SMACH, [("ok", {"A": "done", "B": "done"})], "bad")
    choose_form(smach, STATUS, lambda o: (statuses[o], ""))
    assert smach.form is not None and smach.form.describe() == "ParallelAll max_failures=1"
    flexbe = _two(
        FLEXBE,
        [("ok", {"A": "done", "B": "done"}), ("bad", {"A": "failed"}), ("bad", {"B": "failed"})],
        None,
    )
    choose_form(flexbe, STATUS, lambda o: (statuses[o], ""))
    assert flexbe.form is not None
    assert flexbe.form.describe() == "Parallel success_count=2 failure_count=1"
