"""What a translation loses of the states' annotations, named by what they are.

SMACH, FlexBE (and YASMIN) states carry what they were configured with - parameters, userdata
keys, remappings, editor positions (``fsmbt.model.state_info``) - and FlexBE transitions their
autonomy level. A target format that keeps ``attrs`` (fsmbt JSON / YAML, SCXML in the fsmbt
namespace, the SMACH writer) carries them; one that does not (Mermaid, DOT, tables) loses them.
``annotation_losses`` compares the model written with the model read back and says, per kind of
annotation, how many states lost it and which ("parameters of 12 state(s) have no place in
mermaid; dropped: Forward0, Forward1, ..."), instead of one raw attribute diff per state; the
rest of the comparison is left to the generic differences, on copies without annotations.

Rules (docs/cli.md, "translate"): an annotation is a ``state_info`` key, a ``flexbe.`` or
``smach.`` key, or a transition's ``autonomy``; a state keeps it when the state read back at
the same path has the same value; a changed value is named as changed. Costs: O(S + T) over
both models plus the copies.
"""

from __future__ import annotations

import copy

from fsmbt.model import Model, state_info
from fsmbt.model.fsm import FSM

#: Most state names listed in one loss line.
MAX_NAMES = 5


def is_annotation(key: str) -> bool:
    """Whether an ``attrs`` key is a reader's annotation of a state (see the module rules)."""
    return key in state_info.KEYS or key.startswith(("flexbe.", "smach."))


def annotation_losses(before: Model, after: Model, target: str) -> tuple[list[str], Model, Model]:
    """Loss lines for annotations ``after`` lacks, and both models without annotations.

    Args:
        before: the model written.
        after: the model read back from the written text.
        target: the target format's name, for the messages.

    Returns:
        ``(losses, before stripped, after stripped)``; for behavior trees no losses and the
        models unchanged.
    """
    if not isinstance(before, FSM) or not isinstance(after, FSM):
        return [], before, after
    old = _annotations(before)
    new = _annotations(after)
    lost: dict[str, list[str]] = {}
    changed: dict[str, list[str]] = {}
    for path, entries in old.items():
        kept = new.get(path, {})
        for key, value in entries.items():
            if key not in kept:
                lost.setdefault(key, []).append(path or "the machine")
            elif kept[key] != value:
                changed.setdefault(key, []).append(path or "the machine")
    lines = [
        f"{_what(key)} of {len(paths)} state(s) have no place in {target}; dropped: {_names(paths)}"
        for key, paths in sorted(lost.items())
    ]
    lines += [
        f"{_what(key)} of {len(paths)} state(s) read back different from {target}: {_names(paths)}"
        for key, paths in sorted(changed.items())
    ]
    autonomy_before = _autonomy(before)
    autonomy_after = _autonomy(after)
    if autonomy_before > autonomy_after:
        lines.append(
            f"FlexBE autonomy levels of {autonomy_before - autonomy_after} transition(s) have "
            f"no place in {target}; dropped"
        )
    return lines, _stripped(before), _stripped(after)


#: Reader annotations outside ``state_info``, in words.
_OTHER = {
    "flexbe.behaviour": "embedded FlexBE behaviour names",
    "flexbe.opaque": "opaque-behaviour marks",
    "smach.container": "SMACH/FlexBE container classes",
    "smach.children": "concurrence children",
    "smach.outcome_map": "concurrence outcome maps",
    "smach.default_outcome": "concurrence default outcomes",
    "smach.concurrence": "concurrences with container children",
    "smach.callbacks": "Concurrence callbacks (outcome_cb, child_termination_cb)",
}


def _what(key: str) -> str:
    return state_info.DESCRIPTIONS.get(key) or _OTHER.get(key, f"annotation '{key}'")


def _names(paths: list[str]) -> str:
    shown = ", ".join(paths[:MAX_NAMES])
    return shown + (f" and {len(paths) - MAX_NAMES} more" if len(paths) > MAX_NAMES else "")


def _annotations(fsm: FSM) -> dict[str, dict[str, str]]:
    """Path ("" = the top machine) -> its annotations."""
    out = {"": {k: v for k, v in fsm.attrs.items() if is_annotation(k)}}
    for path, _machine, state in fsm.walk():
        found = {k: v for k, v in state.attrs.items() if is_annotation(k)}
        if found:
            out[path] = found
    return out


def _autonomy(fsm: FSM) -> int:
    return sum(1 for m in fsm.machines() for t in m.transitions if "autonomy" in t.attrs)


def _stripped(fsm: FSM) -> FSM:
    """A copy without annotations (states, machines, transitions' autonomy)."""
    out = copy.deepcopy(fsm)
    for machine in out.machines():
        machine.attrs = {k: v for k, v in machine.attrs.items() if not is_annotation(k)}
        for state in machine.states.values():
            state.attrs = {k: v for k, v in state.attrs.items() if not is_annotation(k)}
        for t in machine.transitions:
            t.attrs = {k: v for k, v in t.attrs.items() if k != "autonomy"}
    return out
