"""The outcome pairing: an outcome-driven FSM and its structured tree (docs/verification.md;
docs/semantics.md §11, "The outcome pairing").

Both sides are leaf-execution machines over the source states' outcomes: the FSM read as "the
state about to run; input: the outcome it returns" (``OutcomeFSMMachine``), the BT through
fsmbt's interpreter with the exact blackboard model of outcome entries, Scripts and Switches
(``OutcomeLeafMachine``); a leaf's outcome becomes its status by the outcome rules
(``outcome_rules``), the same rules the conversion used. Outputs are the next leaf's label and
the root's result, so a wrong child order, a swapped outcome or a lost state is a difference
the checker finds with a shortest trace.

When the pairing applies (``is_outcome_pair``): the tree has no LEBT or state-variable leaves,
and the FSM is outcome-driven - some state declares its outcomes, or the caller says so
(``outcome_driven=True``: the conversion came from a SMACH/FlexBE/YASMIN file, whose events
are outcomes by the format), or the pair has a structured conversion's signature: the FSM has
the outcome-driven shape, its events are not just leaf statuses (a BT -> FSM conversion's
are), and every custom leaf of the tree is named after one of its states.
"""

from __future__ import annotations

from fsmbt.convert.structured.schedule import read_structured_view
from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.dispatch_runtime import is_dispatch_bt
from fsmbt.semantics.lebt.spec import GUARD_TYPE, STATE_TYPE
from fsmbt.semantics.outcome_blackboard import OutcomeLeafMachine
from fsmbt.semantics.outcome_machine import OutcomeFSMMachine
from fsmbt.semantics.outcome_rules import OutcomeRules
from fsmbt.semantics.outcome_view import OutcomeView, declares_outcomes
from fsmbt.semantics.state_variable_runtime import is_state_variable_bt
from fsmbt.semantics.status import LeafOutcome

LEAF_OUTCOMES = tuple(outcome.value for outcome in LeafOutcome)

OUTCOME_EXECUTION = "outcome-execution"


def is_outcome_pair(source: FSM, result: BTDocument, *, outcome_driven: bool = False) -> bool:
    """Whether ``(source, result)`` is compared by the outcome pairing (module docstring)."""
    if any(node.type in (GUARD_TYPE, STATE_TYPE) for _tree, node in result.nodes()):
        return False
    if is_state_variable_bt(result) or is_dispatch_bt(result):
        return False
    return outcome_driven or declares_outcomes(source) or _structured_signature(source, result)


def _structured_signature(source: FSM, result: BTDocument) -> bool:
    events = {e for machine in source.machines() for e in machine.events()}
    if events <= set(LEAF_OUTCOMES):
        return False
    leaves = {
        node.name or node.type
        for _tree, node in result.nodes()
        if node.is_leaf and not node.is_builtin
    }
    if not leaves:
        return False
    try:
        view = read_structured_view(source)
    except InputError:
        return False
    return leaves <= set(view.by_label)


def outcome_machines(
    source: FSM, result: BTDocument, rules: OutcomeRules | None = None, *, faithful: bool = False
) -> tuple[OutcomeFSMMachine, OutcomeLeafMachine, str]:
    """The two machines of the outcome pairing and the mode's name (``faithful``: the tree on
    the faithful interpreter, as ``pairing.machines_for`` says).

    Raises:
        OutcomeError: the FSM is not outcome-driven (the state and the cause named).
    """
    view = read_structured_view(source, rules)
    leaves = OutcomeLeafMachine(result, view, generic=faithful)
    return OutcomeFSMMachine(view), leaves, OUTCOME_EXECUTION


def outcome_abstractions(view: OutcomeView) -> list[str]:
    """What a verdict of the outcome pairing holds under (docs/semantics.md §11), in words."""
    sentences = [
        "outcome-driven reading: each state's outcome is its leaf's status by the outcome "
        "rules (docs/semantics.md §11); userdata values and FlexBE autonomy levels are not "
        "modelled"
    ]
    if view.halts:
        sentences.append(f"'preempted' is the tree being halted ({view.halts} outcome(s))")
    rounds = [path or view.fsm.name for path, r in view.regions.items() if r.parallel]
    if rounds:
        sentences.append(
            "concurrence read in rounds (each child still running takes one turn per round, in "
            "the order added - a container child runs on until a leaf runs on or a loop goes "
            'round; docs/semantics.md §11, "Concurrences: Parallel or product", "Container '
            'children"): ' + ", ".join(rounds)
        )
    for path, region in view.regions.items():
        concurrence = region.concurrence
        if concurrence is None:
            continue
        where = path or view.fsm.name
        if "outcome_cb" in concurrence.callbacks:
            sentences.append(
                f"outcome_cb {concurrence.callbacks['outcome_cb']} of {where} not modelled: its "
                "outcome is chosen by the environment"
            )
        if "child_termination_cb" in concurrence.callbacks:
            sentences.append(
                f"child_termination_cb {concurrence.callbacks['child_termination_cb']} of "
                f"{where} not modelled: a child stopped early ends with an outcome the "
                "environment chooses"
            )
    sentences.extend(f"by declaration order: {choice}" for choice in view.order_choices)
    return sentences
