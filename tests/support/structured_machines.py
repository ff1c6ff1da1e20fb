"""Outcome-driven FSMs written out by hand for the structured-style tests: a state is
``name: {outcome: target}``; states declare their outcomes through ``fsmbt.model.state_info``
(as the SMACH/FlexBE readers do), unless ``declared=False``."""

from __future__ import annotations

from collections.abc import Mapping

from fsmbt.model import state_info
from fsmbt.model.fsm import FSM, State

Spec = Mapping[str, Mapping[str, str]]


def machine(
    spec: Spec,
    *,
    finals: tuple[str, ...] = ("succeeded", "aborted"),
    classes: Mapping[str, str] | None = None,
    declared: bool = True,
    name: str = "m",
    extra: Mapping[str, dict[str, str]] | None = None,
) -> FSM:
    """An outcome-driven machine; ``extra[state]`` adds ``State.attrs`` (parameters...)."""
    fsm = FSM(name=name)
    for state, targets in spec.items():
        attrs = state_info.encode(outcomes=list(targets)) if declared else {}
        cls = (classes or {}).get(state, f"{state.title()}Action")
        attrs[state_info.CLASS] = cls
        attrs.update((extra or {}).get(state, {}))
        fsm.add_state(State(state, action=cls, attrs=attrs))
    for final in finals:
        fsm.add_state(State(final, action=None, final=True))
    for state, targets in spec.items():
        for outcome, target in targets.items():
            fsm.add_transition(state, outcome, target)
    fsm.initial = next(iter(spec))
    return fsm


def container(
    outer: FSM, label: str, inner: FSM, exits: Mapping[str, str], *, first: bool = False
) -> FSM:
    """Add ``inner`` to ``outer`` as the composite state ``label``; ``exits[o]`` is where the
    container's outcome ``o`` leads."""
    outer.states[label] = State(label, action=None, regions=[inner])
    for outcome, target in exits.items():
        outer.add_transition(label, None, target, exit=outcome)
    if first:
        outer.initial = label
    return outer


def pipeline(n: int) -> FSM:
    """``S0 -> S1 -> ... -> succeeded``, every state's ``aborted`` ends the machine."""
    names = [f"S{i}" for i in range(n)]
    spec = {
        s: {"succeeded": names[i + 1] if i + 1 < n else "succeeded", "aborted": "aborted"}
        for i, s in enumerate(names)
    }
    return machine(spec, classes=dict.fromkeys(names, "Step"))
