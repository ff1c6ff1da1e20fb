"""A concurrence read as a BehaviorTree.CPP Parallel where the semantics allow (docs/semantics.md
§11, "Concurrences: Parallel or product").

The SMACH/FlexBE/YASMIN readers build a ``Concurrence`` / ``ConcurrencyContainer`` /
``OrthogonalState`` as a composite state whose region is the *product* of the children's
progress, and record the children, the outcome map and the default outcome in the composite's
``attrs`` (leaf children: ``smach.container``, ``smach.children``, ``smach.outcome_map``,
``smach.default_outcome``; with a container child: ``smach.concurrence``, which also holds each
container child's machine; SMACH callbacks, never run: ``smach.callbacks``).
This module decides from those alone whether the concurrence has the semantics of a built-in
parallel node under the outcome rules, and gives its *round reading* (what the outcome pairing
compares the Parallel with):

- the *source decision* ``decide(done)``, ``done`` giving each child's outcome or ``None``
  while it runs: SMACH and YASMIN end the container only when every child has ended, with the
  last ``outcome_map`` entry that holds, else ``default_outcome`` (``smach/concurrence.py``,
  YASMIN's ``concurrence.cpp`` / ``orthogonal_state.cpp``);
  FlexBE ends it as soon as the first condition holds (``concurrency_container.py``), the
  children still running stopped;
- the *round reading*: entering the container, and after each round in which a child is still
  running, every child not yet ended runs once in the order it was added (its label is output,
  the environment answers one of its outcomes or ``running``); after each answer the source
  decision is taken; a decided outcome leaves the container as its completion transition says;
- a *form* is exactly equivalent when, for every combination of child outcomes reachable in
  that reading (from "all running", one child ending at a time, stopping where the source
  decides), the status of the source's decision (the container outcome's status by the outcome
  rules, ``None`` while it runs on) equals the form's decision on the children's statuses:
  ``ParallelAll max_failures=k`` (``parallel_all_node.cpp``: decides only when every child has
  ended, FAILURE iff at least k failed; the children ended are not ticked again), that
  ParallelAll under ``ForceSuccess`` / ``ForceFailure`` (a container whose reachable outcomes
  have one status), or ``Parallel success_count=S failure_count=F`` (``parallel_node.cpp``:
  after each child's tick, SUCCESS once S succeeded, FAILURE once F failed or S can no longer
  be reached; the children still running are halted). The forms are tried in that order, k,
  S and F from 1 up, and the first equivalent one is used.

Otherwise the concurrence keeps its product reading and ``Concurrence.why`` names the cause:
the outcome-map entry (or default) and the child outcomes where every form differs, a
container outcome with no status (a dispatch), an outcome that halts the tree, a combination
where FlexBE would wait for ever, a YASMIN JoinState barrier, or the size cap. A SMACH
``outcome_cb`` (its outcome the environment's choice) is a state of its own run once every
child has ended: ``ForceSuccess(ParallelAll)`` then its leaf (``outcome_view``). How a container child runs
in a round: ``outcome_view`` and docs/semantics.md §11, "Container children".

Cost: O(forms x combinations) with at most ``MAX_CHILDREN`` children and ``MAX_COMBINATIONS``
reachable combinations, else the product is kept.
"""

from __future__ import annotations

import json
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

from fsmbt.model.errors import InputError
from fsmbt.model.fsm import FSM, State
from fsmbt.model.serialize import fsm_from_dict
from fsmbt.semantics.outcome_rules import FAILURE, SUCCESS

A_CONTAINER = "smach.container"
A_CHILDREN = "smach.children"
A_MAP = "smach.outcome_map"
A_DEFAULT = "smach.default_outcome"
A_CHILD_STATES = "children.states"
A_NESTED = "smach.concurrence"
A_CALLBACKS = "smach.callbacks"
#: SMACH's and YASMIN's ``Concurrence`` (same class name, same rule: wait for every child),
#: YASMIN's ``OrthogonalState`` (its regions are machines; same rule) and FlexBE's container.
SMACH = "Concurrence"
ORTHOGONAL = "OrthogonalState"
FLEXBE = "ConcurrencyContainer"
CONCURRENT = (SMACH, ORTHOGONAL, FLEXBE)
MAX_CHILDREN = 8
MAX_COMBINATIONS = 4096

#: Each child's outcome, ``None`` while it runs.
Done = tuple[str | None, ...]


@dataclass(frozen=True)
class ParallelForm:
    """The built-in node a concurrence becomes: ``kind`` (``ParallelAll`` or ``Parallel``),
    its ports, and the status decorator above it (``ForceSuccess``/``ForceFailure``) or None."""

    kind: str
    ports: tuple[tuple[str, str], ...]
    wrapper: str | None = None

    def describe(self) -> str:
        ports = " ".join(f"{k}={v}" for k, v in self.ports)
        text = f"{self.kind} {ports}"
        return f"{self.wrapper}({text})" if self.wrapper else text


@dataclass
class Concurrence:
    """One concurrence of leaf children, as the reader recorded it."""

    cls: str
    labels: list[str]
    classes: list[str]
    outcomes: list[list[str]]
    outcome_map: list[tuple[str, dict[str, str]]]
    default: str | None
    child_attrs: dict[str, dict[str, str]] = field(default_factory=dict)
    #: A container child's machine (its label -> the machine; leaf children have none).
    machines: dict[str, FSM] = field(default_factory=dict)
    #: YASMIN JoinState barriers between its regions (no parallel node waits on them).
    barriers: int = 0
    #: SMACH callbacks (never run): name -> source text.
    callbacks: dict[str, str] = field(default_factory=dict)
    form: ParallelForm | None = None
    why: str = ""

    @property
    def callback_state(self) -> str | None:
        """The product state standing for a SMACH ``outcome_cb`` (run once every child has
        ended; its outcome is the environment's choice), or None."""
        return self.callbacks.get("outcome_cb_state")

    @property
    def smach(self) -> bool:
        """Whether it waits for every child (SMACH, YASMIN), not ends at a condition (FlexBE)."""
        return self.cls != FLEXBE

    def decide(self, done: Done) -> str | None:
        """The source decision (module docstring): the container outcome, or None."""
        by_label = dict(zip(self.labels, done))
        if self.smach:
            if any(o is None for o in done):
                return None
            outcome = self.default
            for candidate, required in self.outcome_map:
                if all(by_label.get(label) == o for label, o in required.items()):
                    outcome = candidate  # SMACH lets the last matching entry win
            return outcome
        for candidate, required in self.outcome_map:
            if all(by_label.get(label) == o for label, o in required.items()):
                return candidate
        return None

    def deciding_entry(self, done: Done) -> str:
        """In words, what decides ``done``: the map entry, or the default."""
        outcome = self.decide(done)
        if outcome is None:
            return "no entry"
        word = "outcome_map entry" if self.smach else "condition"
        by_label = dict(zip(self.labels, done))
        entries = [
            c
            for c, req in self.outcome_map
            if c == outcome and all(by_label.get(k) == v for k, v in req.items())
        ]
        if entries:
            return f"{word} '{outcome}'"
        return f"default_outcome '{outcome}'"

    def child_states(self) -> list[State]:
        """Each child as an atomic state: its label, class and recorded configuration."""
        return [
            State(label, action=cls, attrs=dict(self.child_attrs.get(label, {})))
            for label, cls in zip(self.labels, self.classes)
        ]


def read_concurrence(owner: State | FSM) -> Concurrence | None:
    """The concurrence recorded on a composite state (or a machine), else None: of leaf
    children under the ``smach.*`` keys, with a container child under ``smach.concurrence``
    (its machines in fsmbt's JSON form, ``model.serialize``)."""
    try:
        raw = json.loads(owner.attrs.get(A_CALLBACKS, "{}"))
        callbacks = {str(k): str(v) for k, v in raw.items()}
        if A_NESTED in owner.attrs:
            return _nested(owner.attrs[A_NESTED], callbacks)
        cls = owner.attrs.get(A_CONTAINER)
        if cls not in CONCURRENT or A_CHILDREN not in owner.attrs:
            return None
        children = json.loads(owner.attrs[A_CHILDREN])
        mapping = json.loads(owner.attrs.get(A_MAP, "[]"))
        child_attrs = json.loads(owner.attrs.get(A_CHILD_STATES, "{}"))
    except (ValueError, InputError, KeyError, TypeError):
        return None
    return Concurrence(
        str(cls),
        [str(c[0]) for c in children],
        [str(c[1]) for c in children],
        [[str(o) for o in c[2]] for c in children],
        [(str(o), {str(k): str(v) for k, v in req.items()}) for o, req in mapping],
        owner.attrs.get(A_DEFAULT),
        {str(k): {str(a): str(b) for a, b in v.items()} for k, v in child_attrs.items()},
        callbacks=callbacks,
    )


def _nested(text: str, callbacks: dict[str, str]) -> Concurrence | None:
    spec = json.loads(text)
    cls = str(spec["class"])
    if cls not in CONCURRENT:
        return None
    children = spec["children"]
    machines = {str(k): fsm_from_dict(v, where=f"child '{k}'") for k, v in spec["machines"].items()}
    default = spec.get("default")
    return Concurrence(
        cls,
        [str(c[0]) for c in children],
        [str(c[1]) for c in children],
        [[str(o) for o in c[2]] for c in children],
        [(str(o), {str(k): str(v) for k, v in req.items()}) for o, req in spec["outcome_map"]],
        None if default is None else str(default),
        machines=machines,
        barriers=int(spec.get("barriers", 0)),
        callbacks=callbacks,
    )


def reachable(c: Concurrence) -> list[Done] | None:
    """Every combination reachable in the round reading (start excluded), in BFS order; None
    past ``MAX_COMBINATIONS``."""
    start: Done = tuple(None for _ in c.labels)
    seen = {start}
    order: list[Done] = []
    queue = deque([start])
    while queue:
        done = queue.popleft()
        for i, outs in enumerate(c.outcomes):
            if done[i] is not None:
                continue
            for o in outs:
                after = done[:i] + (o,) + done[i + 1 :]
                if after in seen:
                    continue
                seen.add(after)
                order.append(after)
                if len(order) > MAX_COMBINATIONS:
                    return None
                if c.decide(after) is None:
                    queue.append(after)
    return order


Decision = Callable[[int, int, int], str | None]


def _forms(n: int, flexbe: bool) -> list[tuple[ParallelForm, Decision]]:
    """Candidate forms, each with its decision on (successes, failures, children ended)."""

    def parallel_all(k: int, const: str | None) -> Decision:
        def d(sc: int, fc: int, ended: int) -> str | None:
            if ended < n:
                return None
            return const or (FAILURE if fc >= k else SUCCESS)

        return d

    def parallel(s: int, f: int) -> Decision:
        def d(sc: int, fc: int, ended: int) -> str | None:
            if sc >= s:
                return SUCCESS
            if n - fc < s or fc >= f:
                return FAILURE
            return None

        return d

    alls = [
        (ParallelForm("ParallelAll", (("max_failures", str(k)),)), parallel_all(k, None))
        for k in range(1, n + 1)
    ]
    for wrapper, status in (("ForceSuccess", SUCCESS), ("ForceFailure", FAILURE)):
        form = ParallelForm("ParallelAll", (("max_failures", "1"),), wrapper)
        alls.append((form, parallel_all(1, status)))
    halting = [
        (
            ParallelForm("Parallel", (("success_count", str(s)), ("failure_count", str(f)))),
            parallel(s, f),
        )
        for s in range(1, n + 1)
        for f in range(1, n + 1)
    ]
    return [*halting, *alls] if flexbe else [*alls, *halting]


def choose_form(
    c: Concurrence,
    child_status: list[dict[str, str]],
    outcome_status: Callable[[str], tuple[str | None, str]],
) -> None:
    """Set ``c.form`` to the first exactly equivalent form, else ``c.why`` (module docstring).

    Args:
        child_status: each child's outcome -> SUCCESS/FAILURE (its leaf's status).
        outcome_status: a container outcome's status, or ``(None, why)`` when it has none
            (a dispatch, an outcome that halts the tree).
    """
    n = len(c.labels)
    if "outcome_cb" in c.callbacks:
        c.why = (
            f"its outcome_cb {c.callbacks['outcome_cb']} decides its outcome (not modelled: "
            "the environment chooses; a leaf for the callback in the product)"
        )
        return
    if c.barriers:
        c.why = f"{c.barriers} JoinState barrier(s) make its regions wait for each other"
        return
    if n > MAX_CHILDREN:
        c.why = f"more than {MAX_CHILDREN} children"
        return
    combos = reachable(c)
    if combos is None:
        c.why = f"more than {MAX_COMBINATIONS} combinations of child outcomes"
        return
    wanted: list[tuple[Done, str | None, int, int, int]] = []
    for done in combos:
        outcome = c.decide(done)
        ended = sum(1 for o in done if o is not None)
        if outcome is None and ended == n:
            c.why = (
                f"when its children end as {_combo(c, done)} no condition holds (FlexBE waits "
                "for ever; a Parallel always ends)"
            )
            return
        status: str | None = None
        if outcome is not None:
            status, why = outcome_status(outcome)
            if status is None:
                c.why = f"its outcome '{outcome}' {why}"
                return
        sc = sum(1 for i, o in enumerate(done) if o is not None and child_status[i][o] == SUCCESS)
        wanted.append((done, status, sc, ended - sc, ended))
    best: tuple[int, ParallelForm, Done, str | None, str | None] | None = None
    for form, decision in _forms(n, not c.smach):
        misses = [(d, s, decision(sc, fc, e)) for d, s, sc, fc, e in wanted
                  if decision(sc, fc, e) != s]  # fmt: skip
        if not misses:
            c.form = form
            return
        if best is None or len(misses) < best[0]:
            best = (len(misses), form, *misses[0])
    assert best is not None
    _count, form, done, source, got = best
    decided = c.decide(done)
    gives = f"'{decided}' ({source})" if decided is not None else "no outcome yet"
    c.why = (
        f"children ending {_combo(c, done)}: its {c.deciding_entry(done)} gives {gives}, "
        f"the closest form ({form.describe()}) {got or 'goes on'}"
    )


def _combo(c: Concurrence, done: Done) -> str:
    return ", ".join(
        f"{lab}={o if o is not None else '(running)'}" for lab, o in zip(c.labels, done)
    )


def next_child(done: Done, index: int) -> int:
    """The round reading's next child after ``index``: the next one still running, wrapping
    round to the first one still running (a new round). -1 when none runs."""
    n = len(done)
    for step in range(1, n + 1):
        i = (index + step) % n
        if done[i] is None:
            return i
    return -1
