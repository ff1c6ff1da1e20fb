"""The generator: reproducible, within the paper's limits, structurally sound."""

from __future__ import annotations

from collections import deque
from pathlib import Path

import pytest

from fsmbt.cli import main
from fsmbt.generate import random_bt, random_fsm
from fsmbt.generate.generator import DECORATORS, EXTENDED_CONTROLS
from fsmbt.model.bt import BTNode
from fsmbt.model.serialize import model_to_dict


def _depth(root: BTNode) -> int:
    stack, deepest = [(root, 1)], 0
    while stack:
        node, level = stack.pop()
        deepest = max(deepest, level)
        stack.extend((child, level + 1) for child in node.children)
    return deepest


def _reachable(fsm) -> set[str]:
    seen, queue = {fsm.initial}, deque([fsm.initial])
    while queue:
        for nxt in fsm.successors(queue.popleft()):
            if nxt not in seen:
                seen.add(nxt)
                queue.append(nxt)
    return seen


@pytest.mark.parametrize("scenario", ["basic", "robot", "game"])
def test_fsm_is_reproducible_and_sound(scenario: str) -> None:
    sizes, self_loops, shared = set(), 0, 0
    for seed in range(150):
        fsm = random_fsm(seed, scenario=scenario)
        assert model_to_dict(fsm) == model_to_dict(random_fsm(seed, scenario=scenario))
        assert 2 <= len(fsm.states) <= 30
        sizes.add(len(fsm.states))
        assert _reachable(fsm) == set(fsm.states)
        keys = [(t.source, t.event) for t in fsm.transitions]
        assert len(keys) == len(set(keys)), "deterministic: one target per (source, event)"
        for state in fsm.states.values():
            assert state.final == (not fsm.outgoing(state.name))
        self_loops += sum(t.source == t.target for t in fsm.transitions)
        shared += sum(len(fsm.predecessors(s)) >= 2 for s in fsm.states)
    assert len(sizes) > 10 and self_loops > 0 and shared > 0


def test_fsm_vocabularies_and_sizes() -> None:
    robot = random_fsm(3, 12, "robot")
    game = random_fsm(3, 12, "game")
    basic = random_fsm(3, 28, "basic")
    assert "Idle" in robot.states and "Navigate" in robot.states
    assert "Patrol" in game.states and "Chase" in game.states
    assert list(basic.states)[:3] == ["A", "B", "C"] and "AB" in basic.states
    for t in basic.transitions:
        assert t.event == f"event{t.source}{t.target}"
    chain = random_fsm(1, 10, shape="chain", extra_edges=0, start_event=True)
    assert [(t.source, t.target) for t in chain.transitions] == [
        (a, b) for a, b in zip("ABCDEFGHI", "BCDEFGHIJ")
    ]
    assert chain.start_name == "Start" and chain.initial_event == "eventSA"


@pytest.mark.parametrize("extended", [False, True])
def test_bt_limits(extended: bool) -> None:
    allowed_controls = set(EXTENDED_CONTROLS) if extended else {"Sequence", "Fallback"}
    allowed_decorators = set(DECORATORS) if extended else set()
    for depth in range(2, 11):
        for breadth in range(2, 11):
            doc = random_bt(depth * 100 + breadth, depth, breadth, "game", extended=extended)
            root = doc.main.root
            assert _depth(root) == depth
            assert max(len(n.children) for n in root.walk()) == breadth
            labels = [n.label for n in root.walk() if n.is_leaf]
            assert len(labels) == len(set(labels)), "every leaf has its own label"
            for node in root.walk():
                if node.is_leaf:
                    assert node.type in doc.node_models
                elif node.kind.value == "Control":
                    assert node.type in allowed_controls
                else:
                    assert node.type in allowed_decorators
    seen_types = {
        n.type
        for s in range(60)
        for n in random_bt(s, scenario="robot", extended=True).main.root.walk()
    }
    if extended:
        assert allowed_controls | allowed_decorators <= seen_types


def test_bt_reproducible_and_large_without_recursion() -> None:
    assert model_to_dict(random_bt(5, extended=True)) == model_to_dict(random_bt(5, extended=True))
    assert model_to_dict(random_bt(5)) != model_to_dict(random_bt(6))
    big = random_bt(1, 40, 10, max_nodes=20_000)
    assert sum(1 for _ in big.main.root.walk()) >= 20_000


def test_generate_cli_is_reproducible(tmp_path: Path) -> None:
    first, second = tmp_path / "a", tmp_path / "b"
    for out in (first, second):
        assert (
            main(
                [
                    "generate",
                    "--kind",
                    "fsm",
                    "--scenario",
                    "robot",
                    "--n",
                    "3",
                    "--seed",
                    "9",
                    "-o",
                    str(out),
                ]
            )
            == 0
        )
    names = sorted(p.name for p in first.iterdir())
    assert names == ["fsm_robot_9_0000.json", "fsm_robot_9_0001.json", "fsm_robot_9_0002.json"]
    for name in names:
        assert (first / name).read_text() == (second / name).read_text()
    assert (
        main(
            [
                "generate",
                "--kind",
                "fsm",
                "--n",
                "1",
                "--seed",
                "9",
                "--scenario",
                "robot",
                "-o",
                str(first),
            ]
        )
        == 2
    ), "never overwrites without --force"
    assert (
        main(["generate", "--kind", "bt", "--n", "2", "--extended", "-o", str(tmp_path / "bt")])
        == 0
    )
    assert main(["generate", "--kind", "tree", "-o", str(tmp_path / "x")]) == 2
