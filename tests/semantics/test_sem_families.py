"""Node families own their behaviour (docs/semantics.md, "Node families"): the worked example's
one module (tests/support/family_unless.py) is all a new kind needs - the interpreter ticks it,
the native checker proves with it, the NuSMV encoder encodes it - and nothing works without it.
"""

from __future__ import annotations

import random
import re
from pathlib import Path

import pytest

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.bt_interpreter import BTRunner, CompiledTree
from fsmbt.semantics.families import registry
from fsmbt.verify import verify
from fsmbt.verify.nusmv import check as nusmv_check
from fsmbt.verify.nusmv.runner import NuSMVError
from support.family_unless import unless_installed

DOCS = Path(__file__).resolve().parents[2] / "docs" / "semantics.md"
EXAMPLE = Path(__file__).resolve().parents[1] / "support" / "family_unless.py"


def _tree(decorator: str) -> BTDocument:
    """``Fallback(decorator(Sequence(a, b?)), c)``: the decorator's result steers the Fallback."""
    seq = BTNode(
        "Sequence",
        NodeKind.CONTROL,
        children=[
            BTNode("a", NodeKind.ACTION, name="a"),
            BTNode("b", NodeKind.CONDITION, name="b"),
        ],
    )
    top = BTNode(
        "Fallback",
        NodeKind.CONTROL,
        children=[
            BTNode(decorator, NodeKind.DECORATOR, children=[seq]),
            BTNode("c", NodeKind.ACTION, name="c"),
        ],
    )
    return BTDocument.single(top)


def test_sem_family_unknown_before_registration() -> None:
    with pytest.raises(UnsupportedError, match="Unless"):
        CompiledTree(_tree("Unless"))


def test_sem_family_interpreter_ticks_the_registered_rule() -> None:
    rng = random.Random(25)
    differs_from_force_failure = False
    with unless_installed():
        for _ in range(30):
            answers = [rng.choice(["success", "failure", "running"]) for _ in range(60)]

            def runs(decorator: str, answers: list[str] = answers) -> list[object]:
                queue = iter(answers)

                def env(node: BTNode, path: str) -> str:
                    outcome = next(queue)
                    return "failure" if (outcome == "running" and node.name == "b") else outcome

                runner = BTRunner(_tree(decorator), env)
                return [(r.leaves, r.result) for r in (runner.tick_once() for _ in range(8))]

            assert runs("Unless") == runs("Inverter")
            differs_from_force_failure |= runs("Unless") != runs("ForceFailure")
    assert differs_from_force_failure


def test_sem_family_checker_proves_with_the_registered_rule() -> None:
    with unless_installed():
        assert verify(_tree("Inverter"), _tree("Unless")).equivalent
        assert not verify(_tree("ForceFailure"), _tree("Unless")).equivalent
    with pytest.raises(UnsupportedError):
        verify(_tree("Inverter"), _tree("Unless"))


def test_sem_family_nusmv_encodes_the_registered_rule() -> None:
    with unless_installed():
        try:
            same = nusmv_check(_tree("Inverter"), _tree("Unless"))
            other = nusmv_check(_tree("ForceFailure"), _tree("Unless"))
        except NuSMVError as exc:  # no binary on this machine: say so, never pass silently
            pytest.skip(f"NuSMV not available: {exc}")
    assert same.equivalent
    assert not other.equivalent


def test_sem_family_docs_show_the_example_verbatim() -> None:
    text = DOCS.read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    body = EXAMPLE.read_text(encoding="utf-8")
    code = body[body.index("from __future__") :]
    assert any(block.strip() == code.strip() for block in blocks)


def test_sem_family_every_declared_handler_has_one_rule() -> None:
    from fsmbt.semantics.nodes import all_nodes

    for node in all_nodes():
        if node.handler is not None and node.kind is not NodeKind.CONDITION:
            assert registry.rule(node.handler) is not None, node.name
    with pytest.raises(ValueError):
        registry.register_rule("sequence", registry.rule("sequence"))  # type: ignore[arg-type]
