"""What a verdict says it proved: the method, the engines and their versions, the abstractions.

Why: "equivalent" means different things by method - the whole product of two machines on
fsmbt's faithful interpreter states, the same product with a BT side on its static leaf table or
on canonical states, or NuSMV's symbolic check - and a reader (a reviewer, a CI) must know which
before trusting it (docs/verification.md, "What a verdict says"). The method is read off the
machines the pairing built (``fsmbt.verify.pairing.machines_for``), never guessed from the models.
"""

from __future__ import annotations

from fsmbt.verify.report import CANONICAL, TABLE, WHOLE_PRODUCT

#: The sentence each machine representation adds to a verdict's abstractions.
TABLE_SENTENCE = (
    "a BT side runs on its static leaf table (semantics/leaf_fast.py; checked in lockstep "
    "against the interpreter by tests/semantics/test_sem_leaf_fast.py)"
)
CANONICAL_SENTENCE = (
    "a BT side's states are canonical: statuses and frame locals reset before they are read "
    "are erased (docs/semantics.md §4a); the verdict is that of the faithful machine"
)
LEBT_FAST_SENTENCE = (
    "an LEBT side of the strict grammar runs on its fast macro-step runtime "
    "(semantics/lebt/fast.py, the same MacroStepDriver rules as the LEBT interpreter)"
)
PER_NODE_SENTENCE = (
    "compositional (per node): each node of a region written per node is checked alone "
    "against fsmbt's interpreter (tick and halt) running it over abstract children, equal "
    "local problems once; the results compose (docs/semantics.md §4d: equivalence is a "
    "congruence for the per-node wiring under the side conditions checked)"
)
SYMBOLIC_PER_NODE_SENTENCE = (
    "symbolic (per node): NuSMV decides each distinct local check again, its tree side from "
    "its own encoding of the node's tick rules over abstract children (encode_bt, families), "
    "the fragment as an explicit table; the native walk only chooses which checks exist and "
    "σ, the pairing of each node's statuses with its exits (docs/nusmv.md, 'Trees node by "
    "node')"
)
ACTIVE_SENTENCE = (
    "inputs a machine declares silent in a state (active_inputs) are not stepped there: "
    "they are self-loops without output by the machine's own rules"
)


def describe_method(*machines: object) -> tuple[str, list[str]]:
    """The method of a native check on ``machines`` and the abstractions it used.

    ``table`` when a BT side ran on its static leaf table, else ``canonical`` when one ran on
    canonical states, else ``whole product``. Cost: O(1) per machine.
    """
    sentences: dict[str, None] = {}
    method = WHOLE_PRODUCT
    for machine in machines:
        inner = getattr(machine, "machine", machine)  # LEBTWithActiveInputs wraps its machine
        if getattr(inner, "runtime", None) is not None:  # an LEBT macro-step machine
            if getattr(inner, "fast", False):
                sentences.setdefault(LEBT_FAST_SENTENCE, None)
        elif getattr(inner, "fast", False):
            method = TABLE
            sentences.setdefault(TABLE_SENTENCE, None)
        elif getattr(inner, "canonical", False):
            if method != TABLE:
                method = CANONICAL
            sentences.setdefault(CANONICAL_SENTENCE, None)
        if getattr(machine, "active_inputs", None) is not None:
            sentences.setdefault(ACTIVE_SENTENCE, None)
    return method, list(sentences)


def nusmv_engine() -> dict[str, str]:
    """NuSMV's name and version as the verdict names it (``unknown`` when it cannot say)."""
    from fsmbt.verify.nusmv.binary import find_nusmv, nusmv_version

    path = find_nusmv()
    return {"NuSMV": nusmv_version(str(path)) if path is not None else "not found"}
