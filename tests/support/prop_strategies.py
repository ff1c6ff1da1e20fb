"""Hypothesis strategies over fsmbt's models, shared by the property tests.

Two sources of valid models, as issue 18 asks: the project's generator (``fsmbt.generate``,
seeded draws of its parameters) and strategies that build models field by field here (names
with blanks, quotes and non-ASCII letters, actions that differ from names, start events, final
states), plus the random behavior trees of ``random_trees`` over every node type.

Budget: every test draws ``EXAMPLES`` examples (``FSMBT_PROPERTY_EXAMPLES`` overrides it), with
a derandomized (seeded) search and no example database, so CI runs the same examples each time.
"""

from __future__ import annotations

import os

from hypothesis import HealthCheck, settings
from hypothesis import strategies as st

from fsmbt.generate import random_bt, random_fsm
from fsmbt.model.fsm import FSM, State

# the random-tree helpers move to tests/support/random_trees.py; this is the one line to change
from support.random_trees import ALL_CONTROLS, ALL_DECORATORS, bt_documents

EXAMPLES = int(os.environ.get("FSMBT_PROPERTY_EXAMPLES", "40"))  # CI budget; raise for a full run

#: The CI profile: seeded, bounded, no deadline (the checker's time varies with the machine).
BUDGET = settings(
    max_examples=EXAMPLES,
    derandomize=True,
    database=None,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

PLAIN_NAME = st.from_regex(r"\A[A-Za-z][A-Za-z0-9_]{0,5}\Z", fullmatch=True)
ODD_NAME = st.sampled_from(["with space", "dash-name", "Ünïcode", "dot.ted", "x/y", "q'uote"])
NAME = st.one_of(PLAIN_NAME, PLAIN_NAME, PLAIN_NAME, ODD_NAME)
EVENT = st.from_regex(r"\A[a-z][a-z0-9_]{0,4}\Z", fullmatch=True)


def generated_fsms() -> st.SearchStrategy[FSM]:
    """FSMs from ``fsmbt.generate.random_fsm`` (seed, size, shape, scenario drawn)."""
    return st.builds(
        lambda seed, n, shape, scenario, start: random_fsm(
            seed=seed, n_states=n, shape=shape, scenario=scenario, start_event=start
        ),
        st.integers(0, 2**31),
        st.integers(1, 9),
        st.sampled_from(["chain", "tree", "loop", "mixed"]),
        st.sampled_from(["basic", "robot", "game"]),
        st.sampled_from([None, True, False]),
    )


@st.composite
def drawn_fsms(draw: st.DrawFn) -> FSM:
    """A flat deterministic FSM built field by field: at most one transition per (state,
    event), final states without outgoing transitions, the first state initial."""
    n = draw(st.integers(1, 6))
    names = draw(st.lists(NAME, min_size=n, max_size=n, unique=True))
    events = draw(st.lists(EVENT, min_size=1, max_size=3, unique=True))
    finals = draw(st.sets(st.sampled_from(names[1:]))) if n > 1 else set()
    fsm = FSM(name=draw(PLAIN_NAME))
    for name in names:
        action = draw(st.sampled_from([name, name, f"do_{len(name)}"]))
        fsm.add_state(State(name, action=action, final=name in finals))
    for source in names:
        if source in finals:
            continue
        for event in events:
            if draw(st.booleans()):
                fsm.add_transition(source, event, draw(st.sampled_from(names)))
    if draw(st.booleans()):
        fsm.start_name = "Start" if "Start" not in fsm.states else "Begin"
        fsm.initial_event = draw(EVENT)
    return fsm


def generated_bts() -> st.SearchStrategy:
    """BT documents from ``fsmbt.generate.random_bt`` (seed, depth, breadth drawn)."""
    return st.builds(
        lambda seed, depth, breadth, scenario: random_bt(
            seed=seed, depth=depth, breadth=breadth, scenario=scenario, max_nodes=16
        ),
        st.integers(0, 2**31),
        st.integers(2, 4),
        st.integers(1, 3),
        st.sampled_from(["basic", "robot", "game"]),
    )


def drawn_bts() -> st.SearchStrategy:
    """Random trees over every control and decorator node type the interpreter supports."""
    return bt_documents(controls=ALL_CONTROLS, decorators=ALL_DECORATORS, max_nodes=10)


def bts() -> st.SearchStrategy:
    return st.one_of(generated_bts(), drawn_bts())


@st.composite
def drawn_hfsms(draw: st.DrawFn) -> FSM:
    """A hierarchical FSM: a drawn flat machine whose first non-final state becomes composite,
    holding a drawn sub-machine (names made distinct); when the sub-machine has a final state,
    the composite state gets a completion (eventless) transition."""
    top = draw(drawn_fsms())
    inner = draw(drawn_fsms())
    inner.start_name = inner.initial_event = None
    candidates = [s for s in top.states.values() if not s.final]
    if not candidates:
        return top
    host = candidates[0]
    renamed = FSM(name=host.name)  # a region is named after its state (every reader does so)
    for state in inner.states.values():
        renamed.add_state(
            State(f"{host.name}.{state.name}", action=state.action, final=state.final)
        )
    for t in inner.transitions:
        renamed.add_transition(f"{host.name}.{t.source}", t.event, f"{host.name}.{t.target}")
    renamed.initial = f"{host.name}.{inner.initial}"
    host.regions = [renamed]
    host.action = None
    if any(s.final for s in renamed.states.values()):
        top.add_transition(host.name, None, draw(st.sampled_from(sorted(top.states))))
    return top


def fsms() -> st.SearchStrategy[FSM]:
    """Flat (generated, drawn) and hierarchical (drawn) FSMs."""
    return st.one_of(generated_fsms(), drawn_fsms(), drawn_hfsms())
