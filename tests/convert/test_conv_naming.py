"""Names made during a BT -> FSM conversion (``bt_compact.Namer`` for variables,
``bt_to_hfsm._Builder._unique`` for states): the rule is "the base when free, else the smallest
free suffix from 2", and a search that resumes where the last one stopped must give exactly the
names a search from 2 gives, at a cost linear in the names made (issue 27: the 15 560-node trees
make thousands of names of one base)."""

from __future__ import annotations

import random
import re

from fsmbt.convert.bt_compact import Namer
from fsmbt.convert.bt_to_hfsm import _Builder
from fsmbt.model.fsm import FSM, State

BASES = ("a", "a_2", "a 3", "Sequence", "Sequence_idx", "Sequence#2", "9lives", "", "__")


class CountingSet(set[str]):
    """A set that counts membership tests."""

    looked = 0

    def __contains__(self, item: object) -> bool:
        CountingSet.looked += 1
        return super().__contains__(item)


class CountingDict(dict[str, State]):
    """A state table that counts membership tests."""

    looked = 0

    def __contains__(self, item: object) -> bool:
        CountingDict.looked += 1
        return super().__contains__(item)


def reference_variable(taken: set[str], base: str) -> str:
    """``Namer.name``'s rule, searched from 2 every time."""
    base = re.sub(r"[^A-Za-z0-9_]+", "_", base).strip("_") or "v"
    if not (base[0].isalpha() or base[0] == "_"):
        base = "n_" + base
    unique, n = base, 2
    while unique in taken:
        unique, n = f"{base}_{n}", n + 1
    taken.add(unique)
    return unique


def reference_state(states: dict[str, State], base: str) -> str:
    """``_Builder._unique``'s rule, searched from 2 every time."""
    if base not in states:
        return base
    n = 2
    while f"{base}#{n}" in states:
        n += 1
    return f"{base}#{n}"


def test_variable_names_are_those_of_a_search_from_two() -> None:
    rng = random.Random(27)
    for _ in range(50):
        seeded = {f"a_{n}" for n in rng.sample(range(2, 30), 6)} | {"v", "Sequence_idx_4"}
        namer, taken = Namer(taken=set(seeded)), set(seeded)
        for _ in range(300):
            base = rng.choice(BASES)
            assert namer.name(base) == reference_variable(taken, base)
        assert namer.taken == taken


def test_state_names_are_those_of_a_search_from_two() -> None:
    rng = random.Random(23)
    for _ in range(50):
        builder, fsm, copy = _Builder(), FSM(name="m"), FSM(name="m")
        for _ in range(300):
            base = rng.choice(BASES[:6])
            if rng.random() < 0.1:  # a suffixed name added by other means
                added = f"{base}#{rng.randrange(2, 40)}"
                for machine in (fsm, copy):
                    machine.states.setdefault(added, State(added))
                continue
            name = builder._unique(fsm, base)  # noqa: SLF001 - the rule under test
            assert name == reference_state(copy.states, base)
            if rng.random() < 0.8:  # sometimes asked again before the name is used
                fsm.add_state(State(name))
                copy.add_state(State(name))


def test_naming_costs_are_linear_in_the_names_made() -> None:
    made = 5000
    taken = CountingSet()
    namer = Namer(taken=taken)
    CountingSet.looked = 0
    for _ in range(made):
        namer.name("SequenceWithMemory_idx")
    assert len(taken) == made
    assert CountingSet.looked <= 3 * made  # a search from 2 each time: about made**2 / 2

    builder, fsm = _Builder(), FSM(name="m")
    fsm.states = CountingDict()
    CountingDict.looked = 0
    for _ in range(made):
        fsm.add_state(State(builder._unique(fsm, "Sequence")))  # noqa: SLF001
    assert len(fsm.states) == made
    assert CountingDict.looked <= 3 * made
