"""Structural checks of an LLM's answer, before behavior is verified.

They catch the mistakes an LLM makes most (a state left out, a node written twice, a reference
to something that does not exist) and name them precisely, which makes better feedback than a
counterexample alone, and they are cheap. Each check returns a list of problems; empty = pass.

FSM -> BT (an LEBT): each reachable FSM state has exactly one ``LebtState`` with the right
action, final flag and exits; every ``LebtGuard`` guards a known state with pairs that are real
transitions (or the start); nodes are only Sequence, Fallback, LebtGuard, LebtState; no empty
control node. BT -> FSM: every transition and initial state points at an existing state, events
are leaf outcomes, at most one target per (state, event), no state names a leaf the tree lacks,
and, in the paper's node set (Sequence, Fallback, custom leaves), every leaf has exactly one
state (counted per leaf name).
Complexity: linear in the size of both models.
"""

from __future__ import annotations

from collections import Counter, deque

from fsmbt.model import fsm_data
from fsmbt.model.bt import BTDocument
from fsmbt.model.fsm import FSM
from fsmbt.semantics.lebt.spec import DEFAULT_START, GUARD_TYPE, STATE_TYPE, GuardSpec, StateSpec
from fsmbt.semantics.nodes import PLAIN_CONTROLS
from fsmbt.semantics.status import LeafOutcome, RootResult

#: The paper's controls: the plain Sequence and Fallback of the node registry.
PAPER_CONTROLS = PLAIN_CONTROLS
LEBT_NODE_TYPES = PAPER_CONTROLS | {GUARD_TYPE, STATE_TYPE}
LEAF_EVENTS = frozenset(outcome.value for outcome in LeafOutcome)
TERMINAL_STATES = frozenset(result.value for result in RootResult)
MAX_LISTED = 12  # problems listed per check; more are summarised (feedback stays short)


def reachable_states(fsm: FSM) -> list[str]:
    """States reachable from the initial state, breadth first, in FSM order of discovery."""
    if fsm.initial is None or fsm.initial not in fsm.states:
        return []
    table: dict[str, list[str]] = {}
    for t in fsm.transitions:
        table.setdefault(t.source, []).append(t.target)
    seen = {fsm.initial}
    queue = deque([fsm.initial])
    while queue:
        for target in table.get(queue.popleft(), []):
            if target not in seen and target in fsm.states:
                seen.add(target)
                queue.append(target)
    return [name for name in fsm.states if name in seen]


def check_lebt(source: FSM, result: BTDocument) -> list[str]:
    """Problems of an LEBT written for ``source`` (a flat FSM)."""
    problems: list[str] = []
    try:
        root = result.main.root
    except KeyError:
        return ["the document holds no behavior tree"]
    if root is None:
        return ["the main tree is empty"]
    start = source.start_name or DEFAULT_START
    initial_event = source.initial_event or ""
    real_pairs = {(t.source, t.event or "", t.target) for t in source.transitions}
    real_pairs.add((start, initial_event, source.initial or ""))
    exits: dict[str, list[str]] = {}
    for t in source.transitions:
        if t.event is not None and t.event not in exits.setdefault(t.source, []):
            exits[t.source].append(t.event)
    state_nodes: Counter[str] = Counter()
    guard_targets: Counter[str] = Counter()
    for node in root.walk():
        where = _where(node)
        if node.type not in LEBT_NODE_TYPES:
            problems.append(
                f"{where}: node type {node.type} is not allowed (use Sequence, Fallback, "
                f"{GUARD_TYPE}, {STATE_TYPE})"
            )
        elif node.type in PAPER_CONTROLS and not node.children:
            problems.append(f"{where}: empty {node.type}")
        elif node.type == STATE_TYPE:
            spec = StateSpec.from_attrs(node.attrs)
            state_nodes[spec.state] += 1
            problems.extend(_check_state_leaf(source, spec, exits, where))
        elif node.type == GUARD_TYPE:
            problems.extend(_check_guard(source, node.attrs, real_pairs, guard_targets, where))
    for name in reachable_states(source):
        if state_nodes[name] == 0:
            problems.append(f"state {name} has no {STATE_TYPE} node")
        if guard_targets[name] == 0 and _needs_guard(source, name):
            problems.append(f"state {name} has no {GUARD_TYPE} guarding it")
    for name, count in state_nodes.items():
        if count > 1:
            problems.append(
                f"state {name} has {count} {STATE_TYPE} nodes; it must have exactly one"
            )
    for name, count in guard_targets.items():
        if count > 1:
            problems.append(
                f"state {name} has {count} {GUARD_TYPE} nodes; all transitions into a "
                "state share one guard"
            )
    return _summarise(problems)


def _needs_guard(source: FSM, name: str) -> bool:
    return name == source.initial or any(t.target == name for t in source.transitions)


def _check_state_leaf(
    source: FSM, spec: StateSpec, exits: dict[str, list[str]], where: str
) -> list[str]:
    if not spec.state:
        return [f"{where}: {STATE_TYPE} without a 'state' port"]
    state = source.states.get(spec.state)
    if state is None:
        return [f"{where}: {STATE_TYPE} names state {spec.state!r}, which the FSM does not have"]
    problems = []
    if (spec.action or None) != (state.action or None):
        problems.append(
            f"{where}: state {spec.state} must have action={state.action or ''!r}, "
            f"not {spec.action or ''!r}"
        )
    if spec.final != state.final:
        problems.append(
            f"{where}: state {spec.state} must have final={'true' if state.final else 'false'}"
        )
    expected = exits.get(spec.state, [])
    if sorted(spec.exits) != sorted(expected):
        problems.append(
            f"{where}: state {spec.state} must have exits={';'.join(expected)!r}, "
            f"not {';'.join(spec.exits)!r}"
        )
    return problems


def _check_guard(
    source: FSM,
    attrs: dict[str, str],
    real_pairs: set[tuple[str, str, str]],
    targets: Counter[str],
    where: str,
) -> list[str]:
    try:
        spec = GuardSpec.from_attrs(attrs)
    except ValueError as exc:
        return [f"{where}: {exc}"]
    if spec.target not in source.states:
        return [f"{where}: {GUARD_TYPE} guards {spec.target!r}, which the FSM does not have"]
    targets[spec.target] += 1
    problems = []
    for src, event in spec.pairs:
        if (src, event, spec.target) not in real_pairs:
            problems.append(
                f"{where}: guard of {spec.target} lists {src}/{event}, but the FSM has "
                f"no transition {src} --{event or '(start)'}--> {spec.target}"
            )
    missing = sorted({(s, e) for s, e, t in real_pairs if t == spec.target} - set(spec.pairs))
    for src, event in missing:
        problems.append(f"{where}: guard of {spec.target} misses the pair {src}/{event}")
    return problems


def check_hfsm(source: BTDocument, result: FSM) -> list[str]:
    """Problems of an (H)FSM written for the BT ``source``."""
    problems: list[str] = []
    actions: Counter[str] = Counter()
    stack: list[tuple[str, FSM]] = [("", result)]
    while stack:
        prefix, machine = stack.pop()
        level = prefix.rstrip("/") or "top level"
        if machine.initial is None or machine.initial not in machine.states:
            problems.append(f"{level}: initial state {machine.initial!r} does not exist")
        seen: dict[tuple[str, str | None], str] = {}
        for t in machine.transitions:
            for end in (t.source, t.target):
                if end not in machine.states:
                    problems.append(
                        f"{level}: transition {t.source} --{t.event}--> {t.target} "
                        f"refers to a missing state {end!r}"
                    )
            if t.event is not None and t.event not in LEAF_EVENTS:
                problems.append(
                    f"{level}: event {t.event!r} is not a leaf outcome (success, failure, running)"
                )
            key = (t.source, t.event if t.event is not None else f"exit:{t.exit}")
            if fsm_data.COND in t.attrs:
                # a data guard (docs/semantics.md §6a): transitions on one event are tried in
                # order, so guarded ones are not a second target; the checker decides them
                continue
            if key in seen and seen[key] != t.target:
                problems.append(
                    f"{level}: {t.source} has two transitions on {key[1]} "
                    f"({seen[key]} and {t.target})"
                )
            seen.setdefault(key, t.target)
        for state in machine.states.values():
            if state.regions:
                stack.extend((f"{prefix}{state.name}/", region) for region in state.regions)
            elif not state.final and state.action and state.action not in TERMINAL_STATES:
                # an empty action is a state that runs nothing (a <parallel> region's wait)
                actions[state.action] += 1
    leaves: Counter[str] = Counter()
    for _, node in source.nodes():
        if node.is_leaf:
            leaves[node.label] += 1
    exact = _one_state_per_leaf(source)
    for name in sorted(set(leaves) | set(actions)):
        if leaves[name] == 0:
            problems.append(f"a state runs {name!r}, which is not a leaf of the tree")
        elif exact and leaves[name] != actions[name]:
            problems.append(
                f"leaf {name} occurs {leaves[name]} time(s) in the tree but has "
                f"{actions[name]} state(s)"
            )
    return _summarise(problems)


def _one_state_per_leaf(source: BTDocument) -> bool:
    """Whether each leaf must have exactly one state: only in the paper's node set (Sequence,
    Fallback, custom Action/Condition leaves), where no node keeps memory or counters and every
    leaf can be ticked. Elsewhere a leaf may need several states (memory, counters, Parallel)
    or none (never ticked), which the verifier's reachability property judges instead."""
    for _, node in source.nodes():
        if node.is_leaf:
            if node.is_builtin:
                return False
        elif node.type not in PAPER_CONTROLS:
            return False
    return True


def _where(node: object) -> str:
    location = getattr(node, "location", None)
    label = getattr(node, "label", "node")
    if location is not None and location.line is not None:
        return f"line {location.line} ({label})"
    return str(label)


def _summarise(problems: list[str]) -> list[str]:
    unique = list(dict.fromkeys(problems))
    if len(unique) <= MAX_LISTED:
        return unique
    return unique[:MAX_LISTED] + [f"... and {len(unique) - MAX_LISTED} more problem(s)"]
