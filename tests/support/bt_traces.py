"""Hand-made BT traces for the node-rule tests: a one-tree document from an XML fragment, an
environment that answers each leaf from its own queue, and the per-tick record of which leaves
ran and what the root returned (``fsmbt.semantics.bt_interpreter.BTRunner``)."""

from __future__ import annotations

from collections.abc import Iterable

from fsmbt import api
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.semantics.bt_interpreter import BTRunner


def doc_of(xml: str, **options: object) -> BTDocument:
    """The document ``<BehaviorTree ID="Main">xml</BehaviorTree>``, read with ``options``."""
    text = f'<root BTCPP_format="4"><BehaviorTree ID="Main">{xml}</BehaviorTree></root>'
    model = api.load_text(text, "btcpp", options=dict(options) or None).model
    assert isinstance(model, BTDocument)
    return model


class Script:
    """The environment: each leaf label answers from its own queue of outcomes."""

    def __init__(self, answers: dict[str, Iterable[str]]) -> None:
        self.answers = {label: list(outs) for label, outs in answers.items()}

    def __call__(self, node: BTNode, path: str) -> str:
        queue = self.answers.get(node.label)
        assert queue, f"unexpected tick of {node.label}"
        return queue.pop(0)


def run(
    doc: BTDocument,
    answers: dict[str, Iterable[str]],
    ticks: int,
    *,
    exactly_once: bool | None = None,
) -> list[tuple[list[str], str]]:
    """``ticks`` ticks of ``doc``: per tick the leaves ticked (labels) and the root's result.
    ``exactly_once``: the runner's tick mode (``None``: its default)."""
    mode = {} if exactly_once is None else {"exactly_once": exactly_once}
    runner = BTRunner(doc, Script(answers), **mode)
    out = []
    for _ in range(ticks):
        record = runner.tick_once()
        out.append(([label for label, _path, _outcome in record.leaves], record.result))
    return out
