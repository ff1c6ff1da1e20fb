"""Prompt tokens per LLM conversion (tiktoken cl100k_base, counted offline).

Prints, for every example model and for seeded generated models (FSMs of 10, 20 and 30 states
in the paper's three scenarios; BTs of 15-60 nodes), the prompt tokens of the ``llm`` request
(four-part prompt with the SCP), the ``nllm`` baseline (no SCP) and each single-module
ablation. The paper reports 500-1 000 tokens per conversion; the last lines say whether every
30-state FSM stays within 1 000. Tokens are those of the first request; a feedback round adds
the previous answer and the problems found.

    .venv/bin/python benchmarks/bench_llm_tokens.py
"""

from __future__ import annotations

import statistics
import sys
from pathlib import Path

from fsmbt import api
from fsmbt.generate.generator import random_bt, random_fsm
from fsmbt.llm.pipeline import direction_for
from fsmbt.llm.prompts import MODULES, PromptOptions, conversion_messages
from fsmbt.llm.tokens import count_messages
from fsmbt.model.errors import FsmbtError
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM

ROOT = Path(__file__).resolve().parent.parent
BUDGET = 1000


def prompt_tokens(model: FSM | object) -> dict[str, int]:
    shown = flatten(model) if isinstance(model, FSM) else model
    direction = direction_for(shown)  # type: ignore[arg-type]
    variants = {"llm": PromptOptions(direction), "nllm": PromptOptions(direction, scp=False)}
    for module in MODULES[direction]:
        variants[f"-{module}"] = PromptOptions(direction, disabled_modules=frozenset({module}))
    return {
        name: count_messages(conversion_messages(shown, options))  # type: ignore[arg-type]
        for name, options in variants.items()
    }


def size(model: object) -> str:
    if isinstance(model, FSM):
        flat = flatten(model)
        return f"{len(flat.states)} states, {len(flat.transitions)} transitions"
    nodes = sum(1 for _ in model.nodes())  # type: ignore[attr-defined]
    return f"{nodes} nodes"


def row(label: str, model: object) -> dict[str, int]:
    counts = prompt_tokens(model)
    cells = "  ".join(f"{k}={v}" for k, v in counts.items())
    print(f"{label:<38} {size(model):<32} {cells}")
    return counts


def main() -> int:
    print("prompt tokens per conversion (tiktoken cl100k_base, offline)\n")
    print("== examples/")
    for path in sorted((ROOT / "examples").iterdir()):
        if path.suffix == ".md":
            continue
        try:
            model = api.load(path).model
        except FsmbtError as exc:
            print(f"{path.name:<38} (not read: {exc})")
            continue
        row(path.name, model)
    print("\n== generated FSMs (seeds 0-4 per scenario)")
    thirty: list[int] = []
    for n in (10, 20, 30):
        for scenario in ("basic", "robot", "game"):
            counts = [prompt_tokens(random_fsm(seed, n, scenario))["llm"] for seed in range(5)]
            if n == 30:
                thirty.extend(counts)
            print(
                f"{n:>2} states, {scenario:<6} llm prompt tokens: min {min(counts)}, "
                f"mean {statistics.mean(counts):.0f}, max {max(counts)}"
            )
    print("\n== generated BTs (paper node set, seeds 0-4)")
    for depth, breadth in ((3, 3), (4, 4), (5, 5)):
        results = [
            (sum(1 for _ in bt.nodes()), prompt_tokens(bt)["llm"])
            for bt in (random_bt(seed, depth, breadth, "robot", max_nodes=60) for seed in range(5))
        ]
        nodes = [n for n, _ in results]
        counts = [c for _, c in results]
        print(
            f"depth {depth} breadth {breadth} ({min(nodes)}-{max(nodes)} nodes) llm prompt tokens: "
            f"min {min(counts)}, mean {statistics.mean(counts):.0f}, max {max(counts)}"
        )
    within = all(c <= BUDGET for c in thirty)
    print(
        f"\n30-state FSMs: llm prompt tokens min {min(thirty)}, mean {statistics.mean(thirty):.0f}, "
        f"max {max(thirty)}; within the paper's {BUDGET}: {'yes' if within else 'NO'}"
    )
    return 0 if within else 1


if __name__ == "__main__":
    sys.exit(main())
