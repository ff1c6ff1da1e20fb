"""The verdict both engines (native, NuSMV) give: five named properties, each with a shortest
counterexample when it fails (docs/verification.md, 'The product and the five properties';
the paper's tables III and VIII)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

REACHABILITY = "reachability"
COMPLETENESS = "completeness"
NO_ADDITIONAL_BEHAVIOR = "no_additional_behavior"
DEADLOCK_ABSENCE = "deadlock_absence"
TERMINATION_CONSISTENCY = "termination_consistency"
PROPERTIES = (
    REACHABILITY,
    COMPLETENESS,
    NO_ADDITIONAL_BEHAVIOR,
    DEADLOCK_ABSENCE,
    TERMINATION_CONSISTENCY,
)

#: The proof methods a verdict names (docs/verification.md, "What a verdict says"):
#: the explicit product of the machines on faithful interpreter states; the same product with
#: a BT side on its static leaf table (pure reactive trees) or on canonical states
#: (docs/semantics.md §4a); NuSMV's symbolic (BDD) invariant check.
WHOLE_PRODUCT = "whole product"
TABLE = "table"
CANONICAL = "canonical"
SYMBOLIC = "symbolic"
#: per region of the tree and its composite state, plus the plain skeleton
#: (``fsmbt.verify.compositional``; docs/semantics.md §4c)
COMPOSITIONAL = "compositional"
#: the same, with regions written per node checked node by node against the interpreter over
#: abstract children (``fsmbt.verify.pernode``; docs/semantics.md §4d)
PER_NODE = "compositional (per node)"
#: a NOT EQUIVALENT verdict whose counterexample the per-node check found locally and
#: ``fsmbt.verify.lift`` lifted to the whole tree and confirmed by replay (not always shortest)
PER_NODE_LIFTED = "per node, lifted"
#: NuSMV deciding each distinct local check of the per-node decomposition (and the parts
#: checked whole), the native walk choosing which (``fsmbt.verify.nusmv.pernode``)
SYMBOLIC_PER_NODE = "symbolic (per node)"
#: a NOT EQUIVALENT verdict whose counterexample a region checked alone found (its own shortest,
#: from the region's fresh tick) and ``fsmbt.verify.lift`` lifted to the whole tree and
#: confirmed by replay
COMPOSITIONAL_LIFTED = "compositional, lifted"
#: the methods whose counterexample is lifted (real, confirmed by replay; not claimed shortest)
LIFTED = (PER_NODE_LIFTED, COMPOSITIONAL_LIFTED)
METHODS = (
    WHOLE_PRODUCT,
    TABLE,
    CANONICAL,
    SYMBOLIC,
    COMPOSITIONAL,
    PER_NODE,
    PER_NODE_LIFTED,
    SYMBOLIC_PER_NODE,
    COMPOSITIONAL_LIFTED,
)


@dataclass
class TraceStep:
    """One step of a counterexample: the input given and what each model did."""

    step: int
    input: str | None  # None for the start
    source_outputs: list[str]
    result_outputs: list[str]
    source_state: str
    result_state: str
    source_status: str
    result_status: str
    note: str = ""  # what differs at this step (empty when both agree)


@dataclass
class PropertyResult:
    """The outcome of one property.

    Attributes:
        name: One of :data:`PROPERTIES`.
        holds: Whether the property holds.
        detail: One line: what was checked, or what failed.
        counterexample: A shortest trace showing the failure (``None`` when it holds).
    """

    name: str
    holds: bool
    detail: str = ""
    counterexample: list[TraceStep] | None = None


@dataclass
class Report:
    """The verdict of one verification, as both engines give it.

    Attributes:
        engine: ``native``, ``nusmv`` or ``native+nusmv``.
        source: The source model's name.
        result: The converted model's name.
        mode: ``macro-step`` (events in, actions out) or ``leaf-execution`` (leaf outcomes in,
            leaf labels and root results out); see docs/verification.md.
        properties: The five properties by name, in :data:`PROPERTIES` order.
        stats: Figures of the run (states, edges, seconds, ...).
        method: What was proven and how (docs/verification.md, "What a verdict says"): one of
            :data:`METHODS`, joined with ``+`` when two engines decided the same pair.
        engines: Each engine that decided the pair and its version (``fsmbt``, ``NuSMV``).
        abstractions: Every abstraction the verdict holds under, one sentence each (the BT
            side's representation, events not stepped, modelled leaves...).
    """

    engine: str
    source: str
    result: str
    mode: str  # "macro-step" (FSM vs BT) or "leaf-execution" (BT vs FSM) ...
    properties: dict[str, PropertyResult] = field(default_factory=dict)
    stats: dict[str, Any] = field(default_factory=dict)
    method: str = ""
    engines: dict[str, str] = field(default_factory=dict)
    abstractions: list[str] = field(default_factory=list)

    @property
    def equivalent(self) -> bool:
        """Whether all five properties were checked and hold."""
        return all(p.holds for p in self.properties.values()) and len(self.properties) == len(
            PROPERTIES
        )

    def verdicts(self) -> dict[str, bool]:
        """Each checked property's name and whether it holds.

        Returns:
            A dict from property name to verdict.
        """
        return {name: p.holds for name, p in self.properties.items()}

    def to_dict(self) -> dict[str, Any]:
        """The report as plain data (for ``--json``), with ``equivalent`` added.

        Returns:
            Nested dicts and lists of strings, numbers and booleans.
        """
        data = asdict(self)
        data["equivalent"] = self.equivalent
        return data
