"""Which of two models is the source, so that a verdict never depends on the argument order.

Why: a user checks a conversion as ``verify A B`` or ``verify B A``; equivalence is symmetric,
but the machines the checker builds are not — an FSM is compared with its loop-execution BT by
macro steps (the FSM is the source), and a BT with its hierarchical FSM by leaf execution (the
BT is the source). So the pair is put in the one order a pairing rule exists for
(docs/verification.md, "Pairing rules"):

=========================================  ====================================================
rule                                        when
=========================================  ====================================================
FSM ~ loop-execution BT (macro steps)       one side is an FSM, the other a BT whose leaves are
                                            LebtGuard / LebtState
FSM ~ state-variable BT (macro steps)       the BT's leaves are the baselines' Sv* leaves
FSM ~ dispatch BT (macro steps)             the BT's leaves are DispatchEntry (docs/semantics.md
                                            section 12)
FSM ~ structured BT (outcome execution)     an outcome-driven FSM (its format's events are
                                            outcomes, or a state declares them) and any other
                                            BT (docs/semantics.md §11)
BT ~ FSM (leaf execution)                   any other BT against an FSM: the FSM is read as the
                                            BT's leaf-execution machine
FSM ~ FSM (macro steps)                     two FSMs, in the given order
BT ~ BT (leaf execution)                    two BTs, in the given order
=========================================  ====================================================

When the order is changed, the report says so: what the five properties call "source" is then
the second model. Cost: one pass over the BT's nodes.
"""

from __future__ import annotations

from dataclasses import dataclass

from fsmbt.model.bt import BTDocument
from fsmbt.model.fsm import FSM
from fsmbt.semantics.execution import Flavour, flavour_of
from fsmbt.verify.outcome_pairing import is_outcome_pair

Model = FSM | BTDocument

LEBT_RULE = "FSM ~ loop-execution BT (macro steps)"
STATE_VARIABLE_RULE = "FSM ~ state-variable BT (macro steps)"
DISPATCH_RULE = "FSM ~ dispatch BT (macro steps)"
OUTCOME_RULE = "FSM ~ structured BT (outcome execution)"
LEAF_EXECUTION_RULE = "BT ~ FSM (leaf execution)"
FSM_FSM_RULE = "FSM ~ FSM (macro steps)"
BT_BT_RULE = "BT ~ BT (leaf execution)"
#: Every pairing rule, in the order they are tried (named in errors).
PAIRING_RULES = (
    LEBT_RULE,
    STATE_VARIABLE_RULE,
    DISPATCH_RULE,
    OUTCOME_RULE,
    LEAF_EXECUTION_RULE,
    FSM_FSM_RULE,
    BT_BT_RULE,
)


@dataclass(frozen=True)
class Orientation:
    """A pair in the order its pairing rule needs.

    Attributes:
        source: the model the five properties call the source.
        result: the other model.
        swapped: ``True`` when the given order was reversed.
        rule: the pairing rule that applies (one of ``PAIRING_RULES``).
    """

    source: Model
    result: Model
    swapped: bool
    rule: str


#: The macro-step rule by which an FSM is compared with a BT of each flavour (the rest: leaf
#: execution). ``fsmbt.semantics.execution.flavour_of`` says what a BT is.
_MACRO_STEP_RULES = {
    Flavour.LEBT: LEBT_RULE,
    Flavour.STATE_VARIABLE: STATE_VARIABLE_RULE,
    Flavour.DISPATCH: DISPATCH_RULE,
}


def fsm_side_rule(doc: BTDocument) -> str | None:
    """The macro-step rule a BT is compared with an FSM by, or ``None`` (leaf execution)."""
    return _MACRO_STEP_RULES.get(flavour_of(doc))


def orient(first: Model, second: Model, *, outcome_driven: bool = False) -> Orientation:
    """Put two models in the order a pairing rule exists for.

    Args:
        first: the model given first.
        second: the model given second.
        outcome_driven: the FSM's events are outcomes (read from SMACH, FlexBE or YASMIN).

    Returns:
        The ``Orientation``: source, result, whether they were swapped, and the rule.
    """
    if isinstance(first, FSM) and isinstance(second, FSM):
        return Orientation(first, second, False, FSM_FSM_RULE)
    if isinstance(first, BTDocument) and isinstance(second, BTDocument):
        return Orientation(first, second, False, BT_BT_RULE)
    if isinstance(first, FSM) and isinstance(second, BTDocument):
        rule = fsm_side_rule(second)
        if rule is not None:
            return Orientation(first, second, False, rule)
        if is_outcome_pair(first, second, outcome_driven=outcome_driven):
            return Orientation(first, second, False, OUTCOME_RULE)
        return Orientation(second, first, True, LEAF_EXECUTION_RULE)
    assert isinstance(first, BTDocument) and isinstance(second, FSM)
    rule = fsm_side_rule(first)
    if rule is not None:
        return Orientation(second, first, True, rule)
    if is_outcome_pair(second, first, outcome_driven=outcome_driven):
        return Orientation(second, first, True, OUTCOME_RULE)
    return Orientation(first, second, False, LEAF_EXECUTION_RULE)


def rules_text() -> str:
    """The pairing rules as one line, for error messages."""
    return "; ".join(PAIRING_RULES)
