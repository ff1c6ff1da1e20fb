"""NuSMV decides the local problems of a tree converted per node (docs/nusmv.md, "Trees node by
node"; issue 27 item 2).

Why: the whole-tree encoding gives up past a few dozen leaves, while a tree of 1 000 nodes
written per node has a few hundred *distinct* local problems of a few dozen states each. Each
is encoded by ``encode_local`` (the tree side from NuSMV's own tick rules) and all of them go
into one SMV file per batch, one ``INVARSPEC`` each, run with ``-coi``: NuSMV builds each
spec's cone of influence alone, which is that unit's module, so a batch costs the sum of its
units, not their product.

What is trusted from the native walk (``fsmbt.verify.pernode.NodeWalk``): *which* problems
exist (the grouping of the machine by node, the abstract children's statuses) and σ, the
pairing of each node's statuses with its exits. Neither makes a wrong proof: a wrong σ or a
wrong grouping makes a unit fail (its outputs differ), and the side conditions that make the
local checks compose (docs/semantics.md §4d) are checked by the walk on the machine alone.
What NuSMV decides is every unit's verdict.

Cost: one NuSMV run per ``BATCH`` units (measured: benchmarks/bench_nusmv_pernode.py);
encoding is O(children + fragment table) per unit.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.verify.nusmv.encode_local import (
    INPUT_ENUM,
    INPUTS,
    UnitModule,
    UnitRefused,
    encode_unit,
    event_word,
    input_word,
)
from fsmbt.verify.nusmv.runner import TraceState, run_nusmv
from fsmbt.verify.pernode import EVENTS, LocalUnit

#: Units per NuSMV run (one file, ``-coi``): measured by benchmarks/bench_nusmv_pernode.py.
BATCH = 2
_SYMBOL_OF = {smv: name for name, smv in INPUTS.items()}


@dataclass
class UnitVerdict:
    """NuSMV's verdict on one unit: the nodes it stands for, whether it holds and, when it
    fails, the counterexample in the user's words (one line per input, then the outputs that
    differ)."""

    unit: LocalUnit
    holds: bool
    steps: list[str] = field(default_factory=list)

    @property
    def node(self) -> str:
        """The node the unit stands for first: its type, label and path."""
        node = self.unit.problem.node
        return f"{node.type} '{node.label}' at {node.path or 'the root'}"


@dataclass
class LocalResult:
    """NuSMV's verdicts on a list of units (in their order) and the cost.

    Attributes:
        verdicts: one per unit NuSMV checked.
        refused: the units the encoding refused, each with why (NuSMV's limit).
        runs, nusmv_seconds, encode_seconds, smv_lines: the cost.
    """

    verdicts: list[UnitVerdict] = field(default_factory=list)
    refused: list[tuple[LocalUnit, str]] = field(default_factory=list)
    runs: int = 0
    cached: int = 0  # units whose module text was already decided (not run again)
    nusmv_seconds: float = 0.0
    encode_seconds: float = 0.0
    smv_lines: int = 0

    @property
    def failed(self) -> list[UnitVerdict]:
        return [v for v in self.verdicts if not v.holds]

    def stats(self) -> dict[str, object]:
        """The figures a verdict prints (``stats["nusmv"]``)."""
        return {
            "units": len(self.verdicts),
            "units_held": sum(v.holds for v in self.verdicts),
            "units_refused": len(self.refused),
            "units_cached": self.cached,
            "nusmv_runs": self.runs,
            "nusmv_seconds": round(self.nusmv_seconds, 6),
            "encode_seconds": round(self.encode_seconds, 6),
            "smv_lines": self.smv_lines,
        }


def batch_model(modules: list[UnitModule]) -> str:
    """The SMV text of one batch: the unit modules, ``main`` feeding them one input and one
    ``INVARSPEC`` per unit, in order."""
    lines = [m.text for m in modules]
    lines += ["MODULE main", "IVAR", f"  inp : {INPUT_ENUM};", "VAR"]
    lines += [f"  {m.name} : {m.name}(inp);" for m in modules]
    lines += [f"INVARSPEC {m.name}.ok;" for m in modules]
    return "\n".join(lines) + "\n"


#: NuSMV's verdicts by a unit module's text without its name (equal text, equal verdict):
#: whether it holds, and the counterexample with the name of the module it was run as.
Verdicts = dict[str, tuple[bool, list[TraceState], str]]


def check_units(
    units: list[LocalUnit],
    *,
    batch: int = BATCH,
    timeout: float | None = None,
    cache: Verdicts | None = None,
    coi: bool = True,
) -> LocalResult:
    """NuSMV's verdict on each unit (refused ones listed with why). ``cache``: verdicts of
    units already run, by module text (a unit whose SMV text, name aside, is in it is not run
    again: the same text is the same model); updated with the new ones. ``coi``: NuSMV's
    ``-coi`` (off only to measure it: the units' product is then one model).

    Raises:
        NuSMVLimitError: a batch passed NuSMV's time or memory cap (``runner``).
        NuSMVError: NuSMV failed otherwise (a bug in the encoding).
    """
    result = LocalResult()
    started = time.perf_counter()
    encoded: list[tuple[LocalUnit, UnitModule]] = []
    for k, unit in enumerate(units):
        try:
            encoded.append((unit, encode_unit(unit, f"u{k}")))
        except UnitRefused as exc:
            result.refused.append((unit, str(exc)))
    result.encode_seconds = time.perf_counter() - started
    known: Verdicts = {} if cache is None else cache
    to_run: list[tuple[LocalUnit, UnitModule]] = []
    queued: set[str] = set()
    for unit, module in encoded:
        body = _body(module)
        if body not in known and body not in queued:
            queued.add(body)
            to_run.append((unit, module))
    for first in range(0, len(to_run), max(batch, 1)):
        chunk = to_run[first : first + batch]
        text = batch_model([m for _u, m in chunk])
        result.smv_lines += text.count("\n")
        found, seconds = run_nusmv(
            text, len(chunk), timeout=timeout, options=["-coi"] if coi else [], mono=False
        )
        result.runs += 1
        result.nusmv_seconds += seconds
        for (_unit, module), spec in zip(chunk, found):
            known[_body(module)] = (spec.holds, spec.trace or [], module.name)
    for unit, module in encoded:
        holds, trace, run_as = known[_body(module)]
        steps = [] if holds else decode(unit, module, trace, run_as)
        result.verdicts.append(UnitVerdict(unit, holds, steps))
    result.cached = len(encoded) - len(to_run)
    return result


def _body(module: UnitModule) -> str:
    """The module's text without its first line (``MODULE <name>(inp)``)."""
    return module.text.split("\n", 1)[1]


def decode(unit: LocalUnit, module: UnitModule, trace: list[TraceState], run_as: str) -> list[str]:
    """A failing unit's counterexample in the user's words: each input at a stable point (one
    line each), then what each side output on the last step. ``run_as``: the name of the
    module NuSMV ran (a unit of equal text, ``check_units``' cache)."""
    prefix = run_as + "."
    steps: list[str] = []
    before: dict[str, str] | None = None
    for state in trace:
        values = {k[len(prefix) :]: v for k, v in state.values.items() if k.startswith(prefix)}
        if before is not None and before.get("stable") == "TRUE":
            position = module.positions.get(before.get("cur", ""), -1)
            symbol = _SYMBOL_OF.get(state.inputs.get("inp", ""), "")
            if position != -1 and symbol in _offered(unit, position):
                steps.append(input_word(unit, position, symbol))
        before = values
    if before is not None:
        steps.append("then the tree: " + _outputs(unit, module, before, "te", "th"))
        steps.append("the fragment: " + _outputs(unit, module, before, "fe", "fh"))
    return steps


def _offered(unit: LocalUnit, position: int | None) -> tuple[str, ...]:
    if position is None:
        return ("tick", "halt") if unit.can_halt else ("tick",)
    return tuple(EVENTS[s] for s in unit.problem.allowed[position])


def _outputs(
    unit: LocalUnit, module: UnitModule, values: dict[str, str], event: str, halt: str
) -> str:
    token = module.events.name(values.get(event, "")) or "?"
    halts = [
        f"halts child {i} ('{unit.child_labels[i]}')"
        for i in range(len(module.leaf_ids))
        if values.get(f"{halt}{i}") == "TRUE"
    ]
    never = unit.problem.never
    unproven = (
        values.get("fb") == "TRUE"
        if halt == "fh"
        else any(values.get(f"th{i}") == "TRUE" for i in never)
    )
    if unproven:
        halts.append("halts a child whose own halt was not proven")
    return ", ".join([event_word(unit, token), *halts])


#: Most nodes a part checked whole (a region, the skeleton) may have for NuSMV's whole-tree
#: encoding here; past it the part is NuSMV's limit (docs/nusmv.md: the whole encoding gives
#: up past ~32 leaves).
WHOLE_LIMIT = 64


@dataclass
class PlanResult:
    """NuSMV's verdicts on a ``compositional.CheckPlan``: the units (all regions), each whole
    part's equivalence, and what NuSMV could not check (its limit, named)."""

    local: LocalResult = field(default_factory=LocalResult)
    regions: list[str] = field(default_factory=list)  # the region of each verdict, in order
    wholes: list[tuple[str, bool]] = field(default_factory=list)
    limits: list[str] = field(default_factory=list)

    @property
    def holds(self) -> bool:
        """Every unit and every whole part holds, and nothing was left unchecked."""
        return (
            not self.limits
            and all(v.holds for v in self.local.verdicts)
            and all(equivalent for _name, equivalent in self.wholes)
        )

    def first_failure(self) -> str | None:
        """The first unit or whole part NuSMV found failing, in the user's words."""
        for region, verdict in zip(self.regions, self.local.verdicts):
            if not verdict.holds:
                return f"{region}, node {verdict.node}"
        for name, equivalent in self.wholes:
            if not equivalent:
                return name
        return None

    def stats(self) -> dict[str, object]:
        found = self.local.stats()
        found["whole_parts"] = len(self.wholes)
        failure = self.first_failure()
        if failure is not None:
            found["failed"] = failure
            failing = next((v for v in self.local.verdicts if not v.holds), None)
            if failing is not None:
                found["counterexample"] = failing.steps
        return found


def check_plan(
    units: list[tuple[str, list[LocalUnit]]],
    wholes: list[tuple[str, BTDocument, FSM]],
    *,
    batch: int = BATCH,
    cache: Verdicts | None = None,
) -> PlanResult:
    """NuSMV on what a compositional check decided (``compositional.CheckPlan``'s two lists):
    every distinct local check of the regions proven per node (``check_units``), and each
    part checked whole (a region, the skeleton) by the whole encoders when it has at most
    ``WHOLE_LIMIT`` nodes; anything else is listed in ``limits``. ``cache``: as for
    ``check_units`` (shared by the regions).

    Raises:
        NuSMVLimitError: a run passed NuSMV's time or memory cap.
    """
    from fsmbt.verify.nusmv import check as whole_check

    result = PlanResult()
    known: Verdicts = {} if cache is None else cache  # equal units across regions: run once
    for region, region_units in units:
        found = check_units(region_units, batch=batch, cache=known)
        _merge(result.local, found)
        result.regions += [region] * len(found.verdicts)
        result.limits += [
            f"region {region}: the local check of {u.problem.node.type} "
            f"'{u.problem.node.label}' is not encoded ({why})"
            for u, why in found.refused
        ]
    for name, doc, fsm in wholes:
        why = _whole_refusal(doc)
        if why is not None:
            result.limits.append(f"{name}: {why}")
            continue
        try:
            report = whole_check(doc, fsm)
        except UnsupportedError as exc:
            result.limits.append(f"{name}: {exc}")
            continue
        result.wholes.append((name, report.equivalent))
    return result


def _merge(total: LocalResult, part: LocalResult) -> None:
    total.verdicts += part.verdicts
    total.refused += part.refused
    total.runs += part.runs
    total.cached += part.cached
    total.nusmv_seconds += part.nusmv_seconds
    total.encode_seconds += part.encode_seconds
    total.smv_lines += part.smv_lines


def _whole_refusal(doc: BTDocument) -> str | None:
    """Why NuSMV does not check a whole part here, else ``None``: past ``WHOLE_LIMIT`` nodes
    (the whole-tree encoding's scale; a machine's data is expanded by ``flatten`` as for any
    pair)."""
    root = doc.main.root
    count, stack = 0, [root] if root is not None else []
    while stack:
        node = stack.pop()
        count += 1
        stack.extend(node.children)
    if count > WHOLE_LIMIT:
        return f"{count} nodes, past the whole encoding's {WHOLE_LIMIT}"
    return None
