"""Which outcome of an outcome-driven state means SUCCESS and which FAILURE
(docs/semantics.md, "11. Outcome-driven machines").

A SMACH, FlexBE or YASMIN state runs and returns one of its declared outcomes; a behavior tree
leaf returns SUCCESS or FAILURE. The structured FSM -> BT conversion and its checker read every
outcome through the same rules, here:

1. An outcome named in the per-machine option (``--outcomes arrived=success,lost=failure``)
   has that status.
2. Otherwise a default name: ``DEFAULT_SUCCESS`` or ``DEFAULT_FAILURE`` (case-insensitive).
3. Otherwise, among the outcomes of one state (or one container) that no rule above names:
   a lone one is SUCCESS; of exactly two, the first declared is SUCCESS and the second
   FAILURE (SMACH's and FlexBE's habit: the nominal outcome comes first) - a choice the
   verdict names; with one named outcome and one unnamed, the unnamed one takes the status
   the named one leaves free. Any other unnamed outcome has no status (``None``): the state
   needs a dispatch on its outcome (its leaf writes it to an output port).
4. ``preempted`` (``HALT_OUTCOME``) is no failure: a state cancelled from outside must not
   start a Fallback's recovery. When every ``preempted`` path ends the whole machine with its
   own ``preempted`` outcome (SMACH's usual wiring) it is modelled as the tree being halted
   (``haltTree``): no node of the tree stands for it. Otherwise it is an ordinary third
   outcome with no status (rule 3).

Costs: O(outcomes) per state.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from fsmbt.model.errors import InputError

SUCCESS = "success"
FAILURE = "failure"
STATUSES = (SUCCESS, FAILURE)
#: The outcome modelled as halting the tree (rule 4).
HALT_OUTCOME = "preempted"
#: Outcome names read as SUCCESS unless the option says otherwise.
DEFAULT_SUCCESS = frozenset(
    {"succeeded", "success", "succeed", "successful", "done", "finished", "complete",
     "completed", "ok", "true", "yes"}
)  # fmt: skip
#: Outcome names read as FAILURE unless the option says otherwise.
DEFAULT_FAILURE = frozenset(
    {"aborted", "abort", "failed", "failure", "fail", "error", "false", "no", "invalid"}
)  # fmt: skip


class OutcomeError(InputError):
    """An outcome-driven machine the structured conversion cannot read (exit 2)."""


def parse_outcomes_option(text: str | None) -> dict[str, str]:
    """``"arrived=success,lost=failure"`` -> ``{"arrived": "success", "lost": "failure"}``.

    Raises:
        OutcomeError: a malformed item, a status that is neither ``success`` nor ``failure``,
            or one outcome mapped to both.
    """
    mapping: dict[str, str] = {}
    if not text:
        return mapping
    for raw in text.split(","):
        item = raw.strip()
        if not item:
            continue
        name, sep, status = item.partition("=")
        name, status = name.strip(), status.strip().lower()
        if not sep or not name or status not in STATUSES:
            raise OutcomeError(
                f"'{item}' is not OUTCOME=success or OUTCOME=failure",
                element="--outcomes",
            )
        if mapping.get(name, status) != status:
            raise OutcomeError(
                f"outcome '{name}' is mapped to both success and failure",
                element="--outcomes",
            )
        mapping[name] = status
    return mapping


@dataclass(frozen=True)
class OutcomeRules:
    """The status rules of one conversion: the defaults plus the per-machine option."""

    overrides: Mapping[str, str] = field(default_factory=dict)

    @classmethod
    def from_option(cls, text: str | Mapping[str, str] | None) -> OutcomeRules:
        """Rules from the ``--outcomes`` text (or an already parsed mapping)."""
        if text is None or isinstance(text, str):
            return cls(parse_outcomes_option(text))
        return cls(parse_outcomes_option(",".join(f"{k}={v}" for k, v in text.items())))

    def named(self, outcome: str) -> str | None:
        """The status rules 1-2 give ``outcome`` (``None``: not named)."""
        if outcome in self.overrides:
            return self.overrides[outcome]
        low = outcome.lower()
        if low in DEFAULT_SUCCESS:
            return SUCCESS
        if low in DEFAULT_FAILURE:
            return FAILURE
        return None

    def statuses(self, outcomes: Sequence[str]) -> tuple[dict[str, str | None], bool]:
        """Every outcome's status by rules 1-3, and whether rule 3's order choice was used.

        Args:
            outcomes: one state's (or container's) outcomes in declaration order, without
                those modelled as a halt.
        """
        result: dict[str, str | None] = {o: self.named(o) for o in outcomes}
        unnamed = [o for o in outcomes if result[o] is None]
        order_choice = False
        if len(unnamed) == 1 and len(unnamed) == len(outcomes):
            result[unnamed[0]] = SUCCESS
        elif len(unnamed) == 2 and len(outcomes) == 2:
            result[unnamed[0]], result[unnamed[1]] = SUCCESS, FAILURE
            order_choice = True
        elif len(unnamed) == 1:
            used = {s for s in result.values() if s is not None}
            free = [s for s in STATUSES if s not in used]
            if len(free) == 1:
                result[unnamed[0]] = free[0]
        return result, order_choice
