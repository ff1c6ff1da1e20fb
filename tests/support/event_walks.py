"""Seeded event sequences for an FSM, the input of the differential runtime tests: mostly an
event the current state reacts to (80 %), else any event of the alphabet or one no state
knows, walked on the FSM so that each choice depends on the state reached."""

from __future__ import annotations

import random

from fsmbt.semantics.machine import FSMMachine

#: The event no machine of the tests declares.
UNKNOWN_EVENT = "no_such_event"


def event_walks(machine: FSMMachine, rng: random.Random, runs: int, length: int) -> list[list[str]]:
    """``runs`` walks of ``length`` events each from the machine's start."""
    alphabet = [*machine.alphabet, UNKNOWN_EVENT]
    sequences = []
    for _ in range(runs):
        events, state = [], machine.start()[0]
        for _ in range(length):
            active = list(machine.active_inputs(state))
            event = rng.choice(active) if active and rng.random() < 0.8 else rng.choice(alphabet)
            events.append(event)
            state = machine.step(state, event)[0]
        sequences.append(events)
    return sequences
