"""Run one generated case on a tree in any engine (docs/testgen.md, 'Running a case'): the code
the generated pytest files call, and the mutation score.

The engine's leaves are scripted: every leaf tick asks the case for the next step; the label
ticked must be the step's label, and the step's outcome is returned. A mismatch is recorded
(and a harmless ``failure`` returned, so the engine never sees an exception) and reported after
the tick: a tree that does not behave like the specification gives a failed assertion, never an
error. The tree is ticked until the root returns SUCCESS or FAILURE, the steps are used up with
no result expected, or ``len(steps) + 2`` ticks (a RUNNING leaf costs a tick without a step of
its own only when it is ticked again).

``make_runner(env)`` builds the tree in an engine with ``env(node, path) -> outcome`` as every
leaf: ``fsmbt.semantics.engines.pytrees_engine.PyTreesRunner``, ``...btcpp_engine.BTCppRunner``
or the interpreter's ``BTRunner``. Costs: the engine's ticks, O(1) per leaf tick.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.fsm import FSM
from fsmbt.semantics.bt_interpreter import BTRunner
from fsmbt.testgen.cases import Suite
from fsmbt.verify.mutations import Mutant, mutants

RESULTS = ("SUCCESS", "FAILURE")


class Script:
    """A case's steps as a leaf environment; ``problem`` is the first mismatch."""

    def __init__(self, steps: list[tuple[str, str]] | list[list[str]], then: str | None) -> None:
        self.steps = [tuple(step) for step in steps]
        self.then = then
        self.next = 0
        self.problem: str | None = None
        self.done = False

    def __call__(self, node: BTNode, path: str) -> str:
        label = node.label
        if self.problem is not None or self.done:
            return "failure"
        if self.next >= len(self.steps):
            if self.then is not None and label != self.then:
                self.problem = f"after the last step the tree ticks {label}, expected {self.then}"
            elif self.then is None:
                self.problem = f"the tree ticks {label} after the run should have ended"
            self.done = True
            return "failure"
        expected, outcome = self.steps[self.next]
        if label != expected:
            self.problem = f"step {self.next + 1}: the tree ticks {label}, expected {expected}"
            return "failure"
        if outcome == "running" and node.kind is NodeKind.CONDITION:
            self.problem = f"step {self.next + 1}: {label} is a condition; expected an action"
            return "failure"
        self.next += 1
        return outcome


def run_case(make_runner: Callable[[Any], Any], case: dict[str, Any]) -> str | None:
    """Run one case (``Case.to_dict()``); ``None`` when the tree behaved as expected, else what
    went wrong (one sentence)."""
    steps = case["steps"]
    script = Script(steps, case.get("then"))
    runner = make_runner(script)
    result = None
    for _ in range(len(steps) + 2):
        record = runner.tick_once()
        if script.problem is not None:
            return script.problem
        if record.result in RESULTS:
            result = record.result
            break
        if script.next >= len(steps) and (case["result"] is None and script.done):
            break
    if script.next < len(steps):
        return f"the tree stopped after {script.next} of {len(steps)} steps"
    if result != case["result"]:
        return f"the root returned {result}, expected {case['result']}"
    return None


def kills(tree: BTDocument, suite: Suite) -> bool:
    """Whether some case fails on ``tree`` (run on fsmbt's interpreter, which ticks as
    BehaviorTree.CPP does: tests/semantics' lockstep tests)."""
    for case in suite.cases:
        data = case.to_dict()

        def make(env: Any, doc: BTDocument = tree) -> BTRunner:
            return BTRunner(doc, env, max_leaf_ticks_per_tick=10_000)

        try:
            if run_case(make, data) is not None:
                return True
        except Exception:  # noqa: BLE001 - a mutant the engine refuses (an error) is killed
            return True
    return False


def mutation_score(
    tree: BTDocument | FSM, suite: Suite, *, per_operator: int | None = 4, seed: int = 0
) -> tuple[int, list[Mutant]]:
    """(killed, mutants) over the checker's mutants of ``tree`` (``fsmbt.verify.mutations``)."""
    if not isinstance(tree, BTDocument):
        return 0, []
    found = mutants(tree, seed=seed, per_operator=per_operator)
    killed = sum(1 for m in found if isinstance(m.model, BTDocument) and kills(m.model, suite))
    return killed, found
