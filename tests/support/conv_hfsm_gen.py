"""A small seeded generator of hierarchical FSMs for the SubTree conversion tests: nested
composite states (up to ``max_depth`` levels), events shared between levels (so an event an
inner state ignores goes to the enclosing state's transition), inner final states with
completion transitions, self-loops, and - with ``parallel=True`` - parallel states of two
regions. Deterministic per (source, event); iterative."""

from __future__ import annotations

import random

from fsmbt.model.fsm import FSM, State

EVENTS = ("a", "b", "c", "d", "e")


def random_hfsm(
    seed: int, *, max_depth: int = 3, parallel: bool = False, max_states: int = 5
) -> FSM:
    rng = random.Random(seed)
    top = FSM(name=f"hfsm_{seed}")
    if rng.random() < 0.5:
        top.start_name, top.initial_event = "Start", "go"
    # work list of (machine, name prefix, depth)
    work: list[tuple[FSM, str, int]] = [(top, "", 0)]
    counter = 0
    while work:
        machine, prefix, depth = work.pop()
        count = rng.randint(2, max_states)
        names = []
        for _ in range(count):
            counter += 1
            name = f"{prefix}S{counter}"
            names.append(name)
            roll = rng.random()
            state = State(name, action=name)
            if depth < max_depth and roll < 0.3:
                sub = FSM(name=f"{name}_sub")
                state.regions = [sub]
                state.action = None
                work.append((sub, f"{name}_", depth + 1))
            elif parallel and depth < max_depth and roll < 0.4:
                state.action = None
                for region_index in range(2):
                    sub = FSM(name=f"{name}_r{region_index}")
                    state.regions.append(sub)
                    work.append((sub, f"{name}_r{region_index}_", max_depth))  # flat regions
            machine.add_state(state)
        finals = [
            n
            for n in names[1:]
            if rng.random() < (0.3 if depth else 0.15) and machine.states[n].is_atomic
        ]
        for name in finals:
            machine.states[name].final = True
        for name in names:
            if machine.states[name].final:
                continue
            used: set[str] = set()
            for _ in range(rng.randint(0, 3)):
                event = rng.choice(EVENTS)
                if event in used:
                    continue
                used.add(event)
                machine.add_transition(name, event, rng.choice(names))
            state = machine.states[name]
            if state.is_composite and rng.random() < 0.6:
                machine.add_transition(name, None, rng.choice(names))  # completion
    return top
