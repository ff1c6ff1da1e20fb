"""Seeded outcome-driven machines, the shape SMACH, FlexBE and YASMIN readers produce
(docs/semantics.md §11): states declare their outcomes (``fsmbt.model.state_info``), events are
those outcomes, containers are composite states with one final state per outcome and
completion transitions ``exit=<outcome>``.

``random_outcome_fsm(seed, states=8)``: a pipeline of ``states`` units from the initial state
(so every state is reachable), each of a class from a small vocabulary:
- two-outcome states (``succeeded``/``aborted``, or ``done``/``failed``) whose failure goes to
  the machine's ``aborted`` outcome, back to an earlier state (a retry loop) or forward past the
  next state (a branch);
- one-outcome states (``done``);
- action states (``succeeded``/``aborted``/``preempted``, the ``preempted`` outcome leading to
  the machine's ``preempted`` outcome, modelled as a halt);
- three-outcome states (``found``/``lost``/``blocked``) whose outcomes go three ways;
- containers (with probability ``containers``): a nested pipeline of 2-3 states with outcomes
  ``succeeded``/``aborted``, at most ``depth`` levels;
some states with parameters and userdata keys. Same seed, same machine. Built with a work list,
O(states).
"""

from __future__ import annotations

import random

from fsmbt.model import state_info
from fsmbt.model.fsm import FSM, State

_BINARY = (("succeeded", "aborted"), ("done", "failed"))
_CLASSES = ("MoveTo", "Detect", "Grasp", "Place", "Dock", "Charge", "Scan", "Speak", "Wait")
_KEYS = ("goal", "pose", "object", "target")


def random_outcome_fsm(
    seed: int | str, states: int = 8, *, containers: float = 0.15, depth: int = 2
) -> FSM:
    """A seeded outcome-driven machine (see the module docstring)."""
    rng = random.Random(f"outcome-fsm:{seed}")
    top = FSM(name=f"outcome_{seed}")
    work: list[tuple[FSM, int, int, str]] = [(top, states, depth, "")]
    counter = [0]
    while work:
        machine, count, levels, prefix = work.pop()
        finals = (
            ("succeeded", "aborted", "preempted") if machine is top else ("succeeded", "aborted")
        )
        names = [f"{prefix}S{counter[0] + i}" for i in range(count)]
        counter[0] += count
        for index, name in enumerate(names):
            nxt = names[index + 1] if index + 1 < count else "succeeded"
            if levels > 0 and rng.random() < containers:
                inner = FSM(name=f"{name}_sm")
                composite = State(name, action=None, regions=[inner])
                machine.add_state(composite)
                work.append((inner, rng.randint(2, 3), levels - 1, f"{name}_"))
                machine.add_transition(name, None, nxt, exit="succeeded")
                machine.add_transition(
                    name, None, _failure_target(rng, names, index), exit="aborted"
                )
                continue
            _add_leaf(rng, machine, names, index, nxt, finals)
        for final in finals:
            machine.add_state(final, action=None, final=True)
        machine.initial = names[0]
    return top


def _failure_target(rng: random.Random, names: list[str], index: int) -> str:
    roll = rng.random()
    if roll < 0.2 and index > 0:
        return names[rng.randrange(0, index + 1)]  # a retry loop (possibly a self-loop)
    if roll < 0.35 and index + 2 < len(names):
        return names[index + 2]  # a branch past the next state
    return "aborted"


def _add_leaf(
    rng: random.Random,
    machine: FSM,
    names: list[str],
    index: int,
    nxt: str,
    finals: tuple[str, ...],
) -> None:
    name = names[index]
    cls = rng.choice(_CLASSES)
    roll = rng.random()
    targets: dict[str, str]
    if roll < 0.15:
        targets = {"done": nxt}
    elif roll < 0.3 and "preempted" in finals:
        targets = {"succeeded": nxt, "aborted": _failure_target(rng, names, index),
                   "preempted": "preempted"}  # fmt: skip
        cls = "SimpleActionState"
    elif roll < 0.42:
        later = names[index + 1 :] + ["aborted", "succeeded"]
        targets = {"found": nxt, "lost": rng.choice(later), "blocked": rng.choice(later)}
    else:
        ok, bad = rng.choice(_BINARY)
        targets = {ok: nxt, bad: _failure_target(rng, names, index)}
    params: dict[str, str] = {}
    inputs: list[str] = []
    if rng.random() < 0.3:
        params["timeout"] = str(rng.randint(1, 30))
    if rng.random() < 0.3:
        inputs.append(rng.choice(_KEYS))
    attrs = state_info.encode(outcomes=list(targets), params=params, inputs=inputs)
    attrs[state_info.CLASS] = cls
    machine.add_state(State(name, action=cls, attrs=attrs))
    for outcome, target in targets.items():
        machine.add_transition(name, outcome, target)
