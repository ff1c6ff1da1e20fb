"""The reference paper's FSM XML (docs/formats/paper-xml.md)::

    <FSM>
      <InitialState name="Start"/>
      <States><State name="A" type="normal"/> ... </States>
      <Transitions><Transition from="Start" to="A" event="eventSA"/> ... </Transitions>
    </FSM>

Mapping rules (docs/semantics.md, 'Models'; docs/formats/paper-xml.md):
- ``InitialState`` (a ``name`` attribute or its text) naming a start pseudo-state - a name not
  listed in ``<States>`` (or listed with ``type="start"``/``"initial"``) with exactly one outgoing
  transition - gives ``start_name`` = that name, ``initial`` = the transition's target and
  ``initial_event`` = its event; the pseudo-state's transition is not kept as a transition. An
  ``InitialState`` naming a listed state makes it the initial state, with no initial event.
- Final states: when some ``<State>`` has ``type="final"``, exactly those are final; when none
  does, every listed state without an outgoing transition is final. ``<FSM finals="marked">``
  (written when needed) switches the second rule off.
- ``State.action`` is the ``action`` attribute, else the state's name (``action=""`` = none).
Flat FSMs only; other attributes are kept. Complexity: O(n) in the size of the file.
"""

from __future__ import annotations

from lxml import etree

from fsmbt.formats.registry import Format, ReadContext, register
from fsmbt.formats.xml_safe import parse_xml, root_tag
from fsmbt.model import Model
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State

PSEUDO_TYPES = frozenset({"start", "initial"})
STATE_TYPES = frozenset({"normal", "final"}) | PSEUDO_TYPES
_STATE_KEYS = frozenset({"name", "type", "action"})
_TRANSITION_KEYS = frozenset({"from", "to", "event"})
_FSM_KEYS = frozenset({"name", "finals"})


def read_paper_xml(text: str, ctx: ReadContext) -> FSM:
    root = parse_xml(text, ctx.display_name)
    if root.tag != "FSM":
        raise InputError(
            f"not the paper's FSM XML: root element is <{str(root.tag)}>, expected <FSM>",
            location=ctx.location(root.sourceline),
        )
    fsm = FSM(
        name=root.get("name", "fsm"),
        attrs={k: v for k, v in root.attrib.items() if k not in _FSM_KEYS},
    )
    initial_name: str | None = None
    initial_line: int | None = None
    pseudo_listed: set[str] = set()
    any_marked_final = False
    for section in _elements(root):
        if section.tag == "InitialState":
            initial_name = (section.get("name") or section.text or "").strip() or None
            initial_line = section.sourceline
        elif section.tag == "States":
            for element in _children(section, "State", ctx):
                state = _state(element, ctx)
                if state.name in fsm.states or state.name in pseudo_listed:
                    raise InputError(
                        f"duplicate state '{state.name}'",
                        location=ctx.location(element.sourceline),
                        element="State",
                    )
                if element.get("type") in PSEUDO_TYPES:
                    pseudo_listed.add(state.name)
                    continue
                any_marked_final |= state.final
                fsm.states[state.name] = state
        elif section.tag == "Transitions":
            for element in _children(section, "Transition", ctx):
                attrs = dict(element.attrib)
                source, target = attrs.pop("from", None), attrs.pop("to", None)
                if not source or not target:
                    raise InputError(
                        "<Transition> needs 'from' and 'to'",
                        location=ctx.location(element.sourceline),
                        element="Transition",
                    )
                event = attrs.pop("event", None)
                fsm.add_transition(
                    source, event, target, attrs=attrs, location=ctx.location(element.sourceline)
                )
        else:
            raise InputError(
                f"unexpected element <{str(section.tag)}> in <FSM> (expected "
                "InitialState, States, Transitions)",
                location=ctx.location(section.sourceline),
                element=str(section.tag),
            )
    _set_initial(fsm, initial_name, initial_line, pseudo_listed, ctx)
    if not any_marked_final and root.get("finals") != "marked":
        sources = {t.source for t in fsm.transitions}
        for state in fsm.states.values():
            state.final = state.name not in sources
    return fsm


def _set_initial(
    fsm: FSM, name: str | None, line: int | None, pseudo_listed: set[str], ctx: ReadContext
) -> None:
    if name is None:
        fsm.initial = next(iter(fsm.states), None)
        return
    if name in fsm.states:
        fsm.initial = name
        return
    leaving = [t for t in fsm.transitions if t.source == name]
    if len(leaving) != 1:
        raise InputError(
            f"InitialState '{name}' is not a listed state, and as a start pseudo-state it needs "
            f"exactly one outgoing transition (it has {len(leaving)})",
            location=ctx.location(line),
            element="InitialState",
        )
    if any(t.target == name for t in fsm.transitions):
        raise InputError(
            f"start pseudo-state '{name}' has incoming transitions",
            location=ctx.location(line),
            element="InitialState",
        )
    (start,) = leaving
    fsm.transitions.remove(start)
    fsm.initial = start.target
    if start.event is not None:
        fsm.start_name = name
        fsm.initial_event = start.event


def _state(element: etree._Element, ctx: ReadContext) -> State:
    name = element.get("name")
    if not name:
        raise InputError(
            "<State> without name", location=ctx.location(element.sourceline), element="State"
        )
    kind = element.get("type", "normal")
    if kind not in STATE_TYPES:
        raise InputError(
            f"unknown state type '{kind}' (normal, final, start)",
            location=ctx.location(element.sourceline),
            element="State",
        )
    action = element.get("action", name)
    return State(
        name,
        action=action or None,
        final=kind == "final",
        attrs={k: v for k, v in element.attrib.items() if k not in _STATE_KEYS},
        location=ctx.location(element.sourceline),
    )


def _elements(element: etree._Element) -> list[etree._Element]:
    return [c for c in element if isinstance(c.tag, str)]


def _children(section: etree._Element, tag: str, ctx: ReadContext) -> list[etree._Element]:
    children = _elements(section)
    for child in children:
        if child.tag != tag:
            raise InputError(
                f"unexpected <{str(child.tag)}> in <{str(section.tag)}> (expected <{tag}>)",
                location=ctx.location(child.sourceline),
                element=str(child.tag),
            )
    return children


def write_paper_xml(model: Model) -> str:
    if not isinstance(model, FSM):
        raise InputError("the paper's FSM XML holds a state machine, not a behavior tree")
    fsm = model
    if fsm.is_hierarchical:
        raise UnsupportedError(
            "the paper's FSM XML holds flat state machines only; flatten it first or write SCXML"
        )
    root = etree.Element("FSM")
    if fsm.name != "fsm":
        root.set("name", fsm.name)
    sources = {t.source for t in fsm.transitions}
    no_final = not any(s.final for s in fsm.states.values())
    if no_final and any(name not in sources for name in fsm.states):
        root.set("finals", "marked")
    for key, value in fsm.attrs.items():
        root.set(key, value)
    start = fsm.start_name or "Start"
    initial = start if fsm.initial_event is not None else fsm.initial
    if initial is not None:
        etree.SubElement(root, "InitialState", name=initial)
    states = etree.SubElement(root, "States")
    for state in fsm.states.values():
        element = etree.SubElement(
            states, "State", name=state.name, type="final" if state.final else "normal"
        )
        if state.action != state.name:
            element.set("action", state.action or "")
        for key, value in state.attrs.items():
            element.set(key, value)
    transitions = etree.SubElement(root, "Transitions")
    if fsm.initial_event is not None and fsm.initial is not None:
        etree.SubElement(
            transitions,
            "Transition",
            {"from": start, "to": fsm.initial, "event": fsm.initial_event},
        )
    for t in fsm.transitions:
        element = etree.SubElement(transitions, "Transition", {"from": t.source, "to": t.target})
        if t.event is not None:
            element.set("event", t.event)
        for key, value in t.attrs.items():
            element.set(key, value)
    return etree.tostring(root, encoding="unicode", pretty_print=True)


def _sniff(text: str) -> bool:
    return root_tag(text) == "FSM"


register(
    Format(
        "paper-xml",
        (".fsm.xml",),
        frozenset({"fsm"}),
        "the reference paper's FSM XML (<FSM>, <States>, <Transitions>)",
        read_paper_xml,
        write_paper_xml,
        _sniff,
        priority=30,
        cannot_hold="composite or parallel states (flatten first)",
    )
)
