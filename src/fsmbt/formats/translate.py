"""The same model in another format, with every loss named (docs/cli.md, ``fsmbt translate``).

Rules:
- The model is written with the target format's writer. A writer that refuses the model
  (``UnsupportedError``: e.g. Mermaid and a completion transition naming its exit state) stops
  the translation; for a hierarchical FSM, ``flatten=True`` writes the flat machine instead,
  which is itself named as a loss.
- What the target cannot hold is listed, never dropped silently: the writer's own list where it
  keeps one (SMACH: ``smach_losses``), else every difference between the model and the model
  read back from the written text (states, transitions, attributes, nodes, the BT format
  version ...), ignoring only the order of FSM states and transitions, which no format keeps
  the same way and no semantics reads. The states' annotations (parameters, userdata keys,
  remappings, positions, autonomy levels: ``fsmbt.formats.annotations``) are named by kind,
  one line each, with the states that lose them.
- A loss that changes meaning is an error, not a warning: when the target has a reader, the
  model read back is returned with the model it must equal (``read_back``, ``checked``), and
  ``fsmbt.api.translate`` proves them equivalent before anything is written (not equivalent
  -> ``UnsupportedError`` naming the failed properties). Formats read and write; they never
  verify (the package layers forbid it).

Costs: one write and one read of the model.
"""

from __future__ import annotations

import copy
import json
import re
from dataclasses import dataclass, field
from typing import Any

from fsmbt.formats.annotations import annotation_losses
from fsmbt.formats.registry import (
    ReadContext,
    data_loss_reason,
    get_format,
    keeps_data,
    loads,
    refuse_data_loss,
)
from fsmbt.model import Model
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.flatten import flatten as flatten_fsm
from fsmbt.model.flatten import needs_flattening
from fsmbt.model.fsm import FSM
from fsmbt.model.fsm_data import DATAMODEL, data_places, parallel_states, parse_lines
from fsmbt.model.serialize import model_to_dict

#: More generic differences than this are summarised in one line.
MAX_DIFFERENCE_LINES = 25


@dataclass
class Translation:
    """The written text and what the reader and the target format reported."""

    text: str
    source_format: str | None
    target_format: str
    losses: list[str] = field(default_factory=list)  # what the target cannot hold
    warnings: list[str] = field(default_factory=list)  # the reader's warnings about the input
    verified: bool = False  # the model read back was checked equivalent (by ``fsmbt.api``)
    #: The model read back from ``text`` (``None``: the target cannot be read back).
    read_back: Model | None = None
    #: What the read-back must equal in behaviour: the source, with any renamed events.
    checked: Model | None = None


def translate(
    model: Model,
    to: str,
    *,
    flatten: bool = False,
    source_format: str | None = None,
) -> Translation:
    """Write ``model`` in format ``to`` and name everything the format cannot hold.

    Args:
        model: the model read from the source.
        to: the target format's name (``fsmbt formats`` lists them).
        flatten: write a hierarchical FSM as its flat machine (a named loss).
        source_format: the source format's name, for the report.

    Returns:
        The translation: text, losses, the model read back and the model it must equal in
        behaviour (``fsmbt.api.translate`` proves that; formats never verify).

    Raises:
        InputError / UnsupportedError: the target cannot hold the model, or what it loses
        changes the model's behaviour.
    """
    target = get_format(to)
    kind = "fsm" if isinstance(model, FSM) else "bt"
    if target.write is None:
        raise InputError(f"format '{target.name}' can be read but not written")
    if kind not in target.kinds:
        raise InputError(f"format '{target.name}' cannot hold a {kind.upper()}")
    losses: list[str] = []
    written = model
    if flatten and isinstance(model, FSM) and needs_flattening(model):
        written = flatten_fsm(model)
        losses.append(
            f"flattened: {len(written.states)} flat states replace the composite, "
            "parallel and transient states"
        )
        losses.extend(annotation_losses(model, written, "the flattened machine")[0])
    written, data_loss = expand_data_for(written, target.name)
    if data_loss is not None:
        losses.append(data_loss)
    checked = model  # what the read-back must equal in behaviour (events renamed, if any)
    if target.name == "scxml" and isinstance(written, FSM):
        events = scxml_event_renames(written)
        if events:
            written = rename_events(written, events)
            if isinstance(model, FSM):
                checked = rename_events(model, events)
            shown = ", ".join(f"'{a}' -> '{b}'" for a, b in list(events.items())[:5])
            more = f" and {len(events) - 5} more" if len(events) > 5 else ""
            losses.append(
                f"{len(events)} event name(s) mean something else to an SCXML engine "
                "(done.state prefixes, wildcards, blanks, or one event a dot-prefix of "
                f"another): renamed {shown}{more}; send the new names to the engine"
            )
        written, renamed = scxml_safe_names(written)
        if renamed:
            shown = ", ".join(f"'{a}' -> '{b}'" for a, b in list(renamed.items())[:5])
            more = f" and {len(renamed) - 5} more" if len(renamed) > 5 else ""
            losses.append(
                f"{len(renamed)} state name(s) are not SCXML ids (an id is an XML "
                f"NCName; a space would split a transition's target): renamed "
                f"{shown}{more}"
            )
    try:
        if target.name == "btcpp3":  # what v3 cannot say: refused, or dropped and named
            from fsmbt.formats.btcpp.v3_write import prepare_v3

            written, v3_losses = prepare_v3(written)
            losses.extend(v3_losses)
        refuse_data_loss(written, target.name)
        text = target.write(written)
    except UnsupportedError as exc:
        hint = ""
        if isinstance(written, FSM) and needs_flattening(written):
            hint = " (--flatten writes the flat machine instead, naming that as a loss)"
        reason = exc.message.removeprefix("unsupported: ")
        raise UnsupportedError(
            f"{target.name} cannot hold this model: {reason}{hint}",
            location=exc.location,
            element=exc.element,
        ) from None
    own_losses = _writer_losses(target.name, written)
    losses.extend(own_losses or [])
    losses.extend(_program_losses(target.name, written))
    result = Translation(text, source_format, target.name, losses, checked=checked)
    if target.read is None and target.read_back_as is None:
        losses.append(f"{target.name} cannot be read back, so what it loses is not checked")
        return result
    try:
        back = loads(text, target.name)  # a write-only format: its read_back_as reader
    except InputError as exc:
        losses.append(
            f"fsmbt cannot read this {target.name} back ({exc.message}), so what it "
            "loses is not checked"
        )
        return result
    if isinstance(checked, FSM) != isinstance(back, FSM):
        raise InputError(f"{target.name} read back a different kind of model")
    result.read_back = back
    if own_losses is None:
        named, written_rest, back_rest = annotation_losses(written, back, target.name)
        losses.extend(named)
        losses.extend(differences_between(written_rest, back_rest))
    return result


def expand_data_for(model: Model, fmt: str) -> tuple[Model, str | None]:
    """A machine with data for a format that cannot keep it (``registry.keeps_data``): its
    exact expansion (configuration x values, the W3C reading; docs/semantics.md §6a) and the
    loss, which names the variables and where each is read and assigned; any other model as it
    is, with no loss. Cost: the expansion's."""
    if not isinstance(model, FSM) or keeps_data(model, fmt):
        return model, None
    variables = [name for name, _expr in parse_lines(model.attrs[DATAMODEL])]
    expanded = flatten_fsm(model)
    return expanded, (
        f"{data_loss_reason(model, fmt)}: the {len(variables)} variable(s) and the guards and "
        "assignments reading them are written as the machine's exact expansion, "
        f"{len(expanded.states)} flat states (configuration x values) instead of "
        f"{sum(1 for _ in model.walk())}; lost: {data_places(model)}; SCXML, JSON, YAML"
        f"{'' if parallel_states(model) else ' and SMACH'} keep them as data"
    )


def _writer_losses(target: str, model: Model) -> list[str] | None:
    """The writer's own list of losses, for writers that keep one (else ``None``)."""
    if target == "smach" and isinstance(model, FSM):
        from fsmbt.formats.pysm.smach_write import smach_losses

        return smach_losses(model)
    return None


def _program_losses(target: str, model: Model) -> list[str]:
    """What the target program cannot do although the written file keeps it for fsmbt (the
    read-back comparison cannot see these)."""
    if target == "yasmin":
        from fsmbt.formats.yasmin.xml_write import yasmin_losses

        return yasmin_losses(model)
    return []


_NCNAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.\-]*\Z")


def _all_events(fsm: FSM) -> list[str]:
    """Every event of ``fsm`` and its sub-machines, in walk order, once each."""
    seen: dict[str, None] = {}
    for machine in fsm.machines():
        if machine.initial_event is not None:
            seen.setdefault(machine.initial_event, None)
        for t in machine.transitions:
            if t.event is not None:
                seen.setdefault(t.event, None)
    return list(seen)


def scxml_event_renames(fsm: FSM) -> dict[str, str]:
    """The events an SCXML engine would read differently, each with a safe new name.

    An SCXML event descriptor matches by dot-prefix (``a`` also matches ``a.b``, ``done`` every
    ``done.state.X``), ``*`` is a wildcard and blanks separate descriptors; such names get their
    blanks, ``*`` and (where they make a prefix) dots replaced by ``_``, and a ``done`` name an
    ``ev_`` prefix, numbered when that clashes.
    """
    events = _all_events(fsm)
    taken = set(events)
    prefixes = {e for e in events if any(o.startswith(e + ".") for o in events if o != e)}
    renames: dict[str, str] = {}
    for event in events:
        related = event in prefixes or any(event.startswith(p + ".") for p in prefixes)
        bad = (
            not event
            or any(c.isspace() for c in event)
            or "*" in event
            or event.endswith(".")
            or event == "done"
            or event.startswith("done.")
        )
        if not (bad or related):
            continue
        base = re.sub(r"[\s*]+", "_", event)
        if related:
            base = base.replace(".", "_")
        base = base.rstrip(".") or "_"
        if base == "done" or base.startswith("done.") or base.startswith("done_"):
            base = f"ev_{base}"
        candidate, index = base, 2
        while candidate in taken:
            candidate, index = f"{base}_{index}", index + 1
        taken.add(candidate)
        renames[event] = candidate
    return renames


def rename_events(fsm: FSM, renames: dict[str, str]) -> FSM:
    """A copy of ``fsm`` with its events renamed (every level)."""
    copy_ = copy.deepcopy(fsm)
    for machine in copy_.machines():
        if machine.initial_event is not None:
            machine.initial_event = renames.get(machine.initial_event, machine.initial_event)
        for t in machine.transitions:
            if t.event is not None:
                t.event = renames.get(t.event, t.event)
    return copy_


def scxml_safe_names(fsm: FSM) -> tuple[FSM, dict[str, str]]:
    """A copy of ``fsm`` whose state names are valid SCXML ids, and the renames made.

    A name that is not an XML NCName gets its other characters replaced by ``_`` (a leading
    ``_`` when it starts with a digit or ``.``/``-``), numbered when that clashes; transitions,
    exits, initial states and the start pseudo-state follow. Iterative over the machines.
    """
    copy_ = copy.deepcopy(fsm)
    taken = {state.name for _p, _m, state in copy_.walk()}
    if copy_.start_name is not None:
        taken.add(copy_.start_name)
    renamed: dict[str, str] = {}

    def safe(name: str) -> str:
        if _NCNAME.match(name):
            return name
        if name in renamed:
            return renamed[name]
        base = re.sub(r"[^A-Za-z0-9_.\-]", "_", name)
        if not re.match(r"[A-Za-z_]", base):
            base = f"_{base}"
        candidate, index = base, 2
        while candidate in taken:
            candidate, index = f"{base}_{index}", index + 1
        taken.add(candidate)
        renamed[name] = candidate
        return candidate

    for machine in copy_.machines():
        if (
            not any(not _NCNAME.match(n) for n in machine.states)
            and machine.initial is not None
            and _NCNAME.match(machine.initial)
            and not any(
                t.exit is not None and not _NCNAME.match(t.exit) for t in machine.transitions
            )
        ):
            continue
        machine.states = {safe(name): state for name, state in machine.states.items()}
        for new_name, state in machine.states.items():
            state.name = new_name
        if machine.initial is not None:
            machine.initial = safe(machine.initial)
        for t in machine.transitions:
            t.source, t.target = safe(t.source), safe(t.target)
            if t.exit is not None:
                t.exit = safe(t.exit)
    if copy_.start_name is not None:
        copy_.start_name = safe(copy_.start_name)
    return copy_, renamed


# -- generic differences ------------------------------------------------------------------------
def differences_between(before: Model, after: Model) -> list[str]:
    """Every difference between two models, one line each (order of FSM states and
    transitions ignored), iteratively over their JSON form."""
    old = _normalised(model_to_dict(before))
    new = _normalised(model_to_dict(after))
    lines: list[str] = []
    stack: list[tuple[str, Any, Any]] = [("", old, new)]
    while stack:
        path, a, b = stack.pop()
        if isinstance(a, dict) and isinstance(b, dict):
            for key in sorted(set(a) | set(b), key=str, reverse=True):
                sub = f"{path}.{key}" if path else str(key)
                if key not in b:
                    lines.append(f"{sub}: {_short(a[key])} is lost")
                elif key not in a:
                    lines.append(f"{sub}: {_short(b[key])} added")
                elif a[key] != b[key]:
                    stack.append((sub, a[key], b[key]))
        elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
            for index in reversed(range(len(a))):
                if a[index] != b[index]:
                    stack.append((f"{path}[{index}]", a[index], b[index]))
        else:
            lines.append(f"{path or 'model'}: {_short(a)} becomes {_short(b)}")
    lines.sort()
    if len(lines) > MAX_DIFFERENCE_LINES:
        extra = len(lines) - MAX_DIFFERENCE_LINES
        lines = [*lines[:MAX_DIFFERENCE_LINES], f"... and {extra} more differences"]
    return lines


def _normalised(data: Any) -> Any:
    """FSM ``states`` keyed by name and ``transitions`` as a sorted set (explicit stack)."""
    root = {"": data}
    stack: list[Any] = [root]
    while stack:
        node = stack.pop()
        items = node.items() if isinstance(node, dict) else enumerate(node)
        for key, value in list(items):
            if isinstance(value, dict) and "states" in value and isinstance(value["states"], list):
                value["states"] = {s.get("name"): s for s in value["states"] if isinstance(s, dict)}
                if isinstance(value.get("transitions"), list):
                    value["transitions"] = {
                        _transition_key(t): t.get("attrs", {})
                        for t in value["transitions"]
                        if isinstance(t, dict)
                    }
            if isinstance(value, (dict, list)):
                stack.append(value)
            node[key] = value
    return root[""]


def _transition_key(t: dict[str, Any]) -> str:
    exit_name = f" (exit {t['exit']})" if t.get("exit") is not None else ""
    event = t.get("event")
    return (
        f"{t.get('source')} --{event if event is not None else ''}--> {t.get('target')}{exit_name}"
    )


def _short(value: Any) -> str:
    text = json.dumps(value, sort_keys=True, default=str)
    return text if len(text) <= 80 else text[:77] + "..."


__all__ = ["Translation", "translate", "differences_between", "ReadContext"]
