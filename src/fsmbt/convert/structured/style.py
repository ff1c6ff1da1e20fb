"""Which FSM -> BT style a conversion uses (docs/conversion.md, "Styles").

- ``structured``: the tree a person would write (``fsmbt.convert.structured``); only for
  outcome-driven machines - on an event-driven one it is bad input naming the first state
  that does not fit (exit 2);
- ``lebt`` (``paper`` is its old name, kept as an alias): the paper's LEBT shape, for any FSM;
- ``dispatch``: a balanced ``Switch`` dispatch over a state index on the blackboard
  (``fsmbt.convert.dispatch``; docs/semantics.md section 12), for event-driven machines;
- ``auto`` (the default): ``structured`` when the machine is outcome-driven, else ``dispatch``
  (a macro step in O(log states) node ticks, issue 23 item 6); ``fsmbt.convert.engines`` falls
  back to ``lebt``, with a warning naming why, where the dispatch form cannot be written (an
  event name a ``Switch`` cannot compare, an eventless transition).

A machine is outcome-driven when its format says its events are outcomes (SMACH, FlexBE,
YASMIN: ``outcome_driven``) or some state declares its outcomes (``state_info``), and it has
the shape ``semantics.outcome_view`` checks. With ``auto``, a machine that claims outcomes but
breaks that shape (an event that is no declared outcome, a container handling an event...) is
bad input too, not silently an LEBT: its author meant outcomes.

Cost: ``read_outcome_view``, O(states + transitions).
"""

from __future__ import annotations

from fsmbt.convert.structured.schedule import read_structured_view
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.semantics.outcome_rules import OutcomeError, OutcomeRules
from fsmbt.semantics.outcome_view import OutcomeView, declares_outcomes

AUTO = "auto"
STRUCTURED = "structured"
LEBT = "lebt"
DISPATCH = "dispatch"
#: Every style name ``--style`` takes; ``paper`` is ``lebt``.
STYLES = (AUTO, STRUCTURED, LEBT, DISPATCH, "paper")
ALIASES = {"paper": LEBT}


def check_style(style: str) -> str:
    """The style's canonical name (``paper`` -> ``lebt``).

    Raises:
        UnsupportedError: an unknown style; the message lists the valid ones.
    """
    if style not in STYLES:
        raise UnsupportedError(
            f"unknown style '{style}' (valid: auto, structured, lebt, dispatch, paper = lebt)",
            element="--style",
        )
    return ALIASES.get(style, style)


def resolve_style(
    style: str,
    fsm: FSM,
    *,
    outcome_driven: bool = False,
    rules: OutcomeRules | None = None,
) -> tuple[str, OutcomeView | None]:
    """``(the style chosen, the outcome view when structured)`` for an FSM source:
    ``structured``, ``lebt`` or ``dispatch``.

    Raises:
        UnsupportedError: an unknown style.
        OutcomeError: ``structured`` on an event-driven machine, or a machine that claims
        outcomes but does not have their shape (the state and the cause named).
    """
    chosen = check_style(style)
    if chosen in (LEBT, DISPATCH):
        return chosen, None
    claims = outcome_driven or declares_outcomes(fsm)
    if chosen == AUTO and not claims:
        return DISPATCH, None
    if not claims:
        first = fsm.initial or next(iter(fsm.states), fsm.name)
        raise OutcomeError(
            "--style structured needs an outcome-driven machine (SMACH, "
            "FlexBE, YASMIN, or states that declare their outcomes); this one is event-driven "
            "(use --style lebt)",
            element=f"state '{first}'",
        )
    return STRUCTURED, read_structured_view(fsm, rules)
