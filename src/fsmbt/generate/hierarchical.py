"""Seeded event-driven hierarchical machines (composite states, W3C priority, ``done.state``
completions): the inputs of the hierarchical dispatch form (docs/semantics.md §12a).

``random_hfsm(seed, states=20, depth=3)``: a top machine whose children are atomic or (with
probability ``composites``, down to ``depth`` levels) composite states holding a sub-machine
of 2-5 children (up to 10 while many states are still to make), until about ``states``
states exist (``depth`` and the draws may stop it earlier). In each machine:

- a chain from the initial child makes every child reachable; extra edges (back, self, cross)
  are added; a source has at most one transition per event;
- events come from one small pool shared by every level (``e0``..``e{k-1}``), so a child and
  its ancestor often react to the same event (the child's transition must win);
- a sub-machine has a final child with probability 0.6; its owner then gets a completion
  transition (``done.state``, ``exit`` that final state or ``None``) with probability
  ``completions`` (0.7);
- the top machine's second child is always composite (when ``depth`` > 0);
- the top machine has a final child with probability 0.5; half the machines start from a
  start pseudo-state with an initial event.

Composite states have no action (SCXML's compound states run none in fsmbt's model); atomic
ones their name. Same seed, same machine; built with a work list, O(states).
"""

from __future__ import annotations

import random

from fsmbt.model.fsm import FSM, State


def random_hfsm(
    seed: int | str,
    states: int = 20,
    *,
    depth: int = 3,
    composites: float = 0.35,
    events: int = 5,
    start_event: bool | None = None,
    completions: float = 0.7,
) -> FSM:
    """A seeded hierarchical event-driven machine (see the module docstring)."""
    rng = random.Random(f"hfsm:{seed}")
    pool = [f"e{i}" for i in range(max(1, events))]
    top = FSM(name=f"hfsm_{seed}")
    budget = [max(2, states)]
    work: list[tuple[FSM, int, str]] = [(top, depth, "")]
    counter = [0]
    while work:
        machine, levels, prefix = work.pop()
        if machine is top:
            count = max(2, min(10, budget[0] // 4))
        else:
            count = rng.randint(2, min(10, 5 + budget[0] // 40))
        names = []
        for _ in range(count):
            name = f"{prefix}s{counter[0]}"
            counter[0] += 1
            budget[0] -= 1
            names.append(name)
            forced = machine is top and len(names) == 2  # at least one composite state
            if levels > 0 and (forced or (budget[0] > 2 and rng.random() < composites)):
                inner = FSM(name=f"{name}_sm")
                machine.add_state(State(name, action=None, regions=[inner]))
                work.append((inner, levels - 1, f"{name}_"))
            else:
                machine.add_state(State(name, action=name))
        final = None
        if rng.random() < (0.5 if machine is top else 0.6):
            final = f"{prefix}done{counter[0]}"
            counter[0] += 1
            machine.add_state(State(final, action=final, final=True))
        machine.initial = names[0]
        _edges(rng, machine, names, final, pool)
    _completions(rng, top, completions)
    if start_event if start_event is not None else rng.random() < 0.5:
        top.start_name, top.initial_event = "Start", "go"
    return top


def _edges(
    rng: random.Random, machine: FSM, names: list[str], final: str | None, pool: list[str]
) -> None:
    """A chain through ``names`` (and into ``final``), then extra edges."""
    used: dict[str, set[str]] = {name: set() for name in names}

    def add(source: str, target: str) -> None:
        free = [e for e in pool if e not in used[source]]
        if free:
            event = rng.choice(free)
            used[source].add(event)
            machine.add_transition(source, event, target)

    chain = [*names, final] if final is not None else names
    for source, target in zip(chain, chain[1:]):
        add(source, target)
    targets = [*names, *([final] if final else [])]
    for _ in range(rng.randint(0, len(names) + 1)):
        source = rng.choice(names)
        kind = rng.random()
        if kind < 0.3:
            add(source, source)  # a self-loop (on a composite: re-enter its initial child)
        elif kind < 0.6:
            add(source, names[rng.randrange(0, names.index(source) + 1)])  # back
        else:
            add(source, rng.choice(targets))  # cross


def _completions(rng: random.Random, top: FSM, chance: float) -> None:
    """``done.state`` transitions: a composite with a final child completes on it (with
    probability ``chance``)."""
    for _path, machine, state in list(top.walk()):
        if not state.is_composite:
            continue
        finals = [s.name for s in state.regions[0].states.values() if s.final]
        if not finals or rng.random() >= chance:
            continue
        siblings = [s for s in machine.states if s != state.name] or [state.name]
        exit_name = rng.choice([None, finals[0]])
        machine.add_transition(state.name, None, rng.choice(siblings), exit=exit_name)
