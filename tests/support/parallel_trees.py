"""Seeded BehaviorTree.CPP trees with a Parallel or ParallelAll heading its region (issue 24:
the ``<parallel>`` form, docs/semantics.md §6a): plain children (leaves, Sequence, Fallback,
Inverter/ForceSuccess/ForceFailure), thresholds drawn from every value the node accepts except
0, the Parallel at the root or between leaves of a plain Sequence/Fallback."""

from __future__ import annotations

import random

DECORATORS = ("Inverter", "ForceSuccess", "ForceFailure")
#: Nodes with memory, restarts or re-checks a child may hold with ``memory=True``.
MEMORY_DECORATORS = ('RetryUntilSuccessful num_attempts="2"', 'Repeat num_cycles="2"')
MEMORY_CONTROLS = ("SequenceWithMemory", "ReactiveSequence", "ReactiveFallback")


def parallel_tree_xml(seed: int, memory: bool = False) -> str:
    """One tree as BehaviorTree.CPP v4 XML (leaves ``<Action ID>``/``<Condition ID>``);
    ``memory``: the children may also hold Retry/Repeat, SequenceWithMemory and reactive
    controls (each child's tick end is then read from its leaf-execution machine)."""
    rng = random.Random(seed)
    names = iter(range(1, 1000))

    def leaf() -> str:
        if rng.random() < 0.3:
            return f'<Condition ID="C{next(names)}"/>'
        return f'<Action ID="A{next(names)}"/>'

    def child(depth: int) -> str:
        roll = rng.random()
        if depth == 0 or roll < 0.35:
            inner = leaf()
        else:
            kinds = ("Sequence", "Fallback") + (MEMORY_CONTROLS if memory else ())
            kind = rng.choice(kinds)
            kids = "".join(child(depth - 1) for _ in range(rng.randint(2, 3)))
            inner = f"<{kind}>{kids}</{kind}>"
        if rng.random() < 0.2:
            decorator = rng.choice(DECORATORS)
            inner = f"<{decorator}>{inner}</{decorator}>"
        if memory and rng.random() < 0.3:
            decorator = rng.choice(MEMORY_DECORATORS)
            inner = f"<{decorator}>{inner}</{decorator.split()[0]}>"
        return inner

    count = rng.randint(2, 3)
    kids = "".join(child(rng.randint(0, 2)) for _ in range(count))
    choices = ["-1", *(str(k) for k in range(1, count + 1))]
    if rng.random() < 0.25:
        node = f'<ParallelAll max_failures="{rng.choice(choices)}">{kids}</ParallelAll>'
    else:
        node = (
            f'<Parallel success_count="{rng.choice(choices)}" '
            f'failure_count="{rng.choice(choices)}">{kids}</Parallel>'
        )
    if rng.random() < 0.5:
        kind = rng.choice(("Sequence", "Fallback"))
        node = f"<{kind}>{leaf()}{node}{leaf()}</{kind}>"
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Main">'
        f'<BehaviorTree ID="Main">{node}</BehaviorTree></root>'
    )
