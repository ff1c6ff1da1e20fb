"""W3C SCXML <-> the (hierarchical) FSM model (docs/formats/scxml.md).

What is mapped: ``<state>`` (atomic, or compound = a composite state with one sub-FSM),
``<parallel>`` (one region per child), ``<final>``, the ``initial`` attribute and
``<initial><transition target/></initial>`` (default: first child in document order),
``<transition event target>`` with several event names (one transition per name), eventless
transitions of atomic states (completion transitions), ``done.state.<id>`` transitions of a
compound/parallel state (completion transitions). A transition that leaves its parent
(``a1 -> b`` with ``a1`` inside ``a``) becomes a transition to a transient final state of
``a1``'s sub-FSM plus completion transitions up to ``b``'s level (``Transition.exit`` names the
transient state), which has SCXML's priority (inner transitions first) and is written back as
the original transition.

Completion transitions of one composite state are told apart by the standard guard
``cond="In('F')"`` naming the ``<final>`` child they wait for (``Transition.exit``); the writer
writes it, the reader reads it and still reads the legacy annotation ``fsmbt:exit`` of older
files (warned: a W3C engine ignores it). ``fsmbt:`` attributes are annotations only: ids are
chosen so that no ``done.state.<id>`` descriptor prefix-matches another state's completion
event, and events SCXML would read otherwise are refused (docs/formats/scxml.md).

Refused with ``UnsupportedError`` (element, line, feature): ``cond`` other than that guard,
``<history>``, wildcard and prefix-matching event descriptors (``done.state`` ones included), targetless transitions, transitions with several targets,
``type="internal"``, behaviour-changing executable content (``<raise>``, ``<send>``,
``<assign>``, ``<script>``, ``<if>``, ``<foreach>``, ``<cancel>``, ``<invoke>``),
eventless transitions of compound states, transitions into a nested state that is not its
parent's initial state, transitions leaving a ``<parallel>`` region. Warned (``ctx.warn``):
``<log>``, ``<datamodel>``/``<data>``, ``<donedata>``, foreign-namespace elements, and a
transition dropped by document-order conflict resolution.

XInclude is expanded before reading (``fsmbt.formats.scxml.include``). Everything is iterative
over the element tree; complexity O(n + T·d) for n elements,
T transitions and nesting depth d.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from lxml import etree

from fsmbt.formats.registry import Format, ReadContext, register
from fsmbt.formats.scxml import include as scxml_include
from fsmbt.formats.scxml.w3c import read_scxml_w3c
from fsmbt.formats.xml_safe import local_name, namespace, root_tag
from fsmbt.model import Model, fsm_data, state_info
from fsmbt.model.errors import InputError, SourceLocation, UnsupportedError
from fsmbt.model.fsm import FSM, State, Transition

SCXML_NS = "http://www.w3.org/2005/07/scxml"
LEGACY_NS = "http://www.w3.org/2005/SCXML"
XINCLUDE_NS = "http://www.w3.org/2001/XInclude"
#: fsmbt's own attributes (what SCXML cannot say: a start pseudo-state, a non-default action,
#: a model name that is not a unique id, the final state a completion transition waits for).
FSMBT_NS = "https://fsmbt.dev/ns/scxml"
F_NAME, F_ACTION, F_START, F_EXIT, F_REGION = (
    f"{{{FSMBT_NS}}}{n}" for n in ("name", "action", "start", "exit", "region")
)
#: Root mark of a document whose data model fsmbt wrote from a model that keeps data
#: (``fsmbt.model.fsm_data``): read back into the same model (guards, assignments, data).
F_DATA = f"{{{FSMBT_NS}}}data"
#: ``State.attrs`` mark of the transient final states that encode a transition leaving its parent.
EXIT_MARK = f"{{{FSMBT_NS}}}exit-state"

STATE_TAGS = frozenset({"state", "parallel", "final"})
UNSUPPORTED_CONTENT = frozenset(
    {"raise", "send", "assign", "script", "if", "elseif", "else", "foreach", "cancel", "invoke"}
)
WARNED_CONTENT = frozenset({"log"})
_SCXML_KEYS = frozenset({"initial", "name", "version"})
#: ``attrs`` keys a reader of outcome-driven states adds (``fsmbt.model.state_info``, FlexBE
#: autonomy, SMACH/FlexBE container facts): written in the fsmbt namespace, so the SCXML stays
#: valid (the W3C schema allows attributes of other namespaces) and reads back the same.
_ANNOTATION_PREFIXES = ("flexbe.", "smach.", "userdata.", "params", "ros.", "children.")
_ANNOTATION_KEYS = frozenset({*state_info.KEYS, "autonomy"})


def annotation_attribute(key: str) -> str:
    """The XML attribute an ``attrs`` key is written as (fsmbt-namespaced for annotations)."""
    if key in _ANNOTATION_KEYS or key.startswith(_ANNOTATION_PREFIXES):
        return f"{{{FSMBT_NS}}}{key}"
    return key


def annotations_in(attrib: etree._Attrib, known: frozenset[str]) -> dict[str, str]:
    """An element's other attributes as ``attrs``: fsmbt-namespaced annotations by their key."""
    out: dict[str, str] = {}
    prefix = f"{{{FSMBT_NS}}}"
    for raw_key, raw_value in attrib.items():
        key, value = str(raw_key), str(raw_value)
        if key in known:
            continue
        local = key[len(prefix) :] if key.startswith(prefix) else None
        if local is not None and (
            local in _ANNOTATION_KEYS or local.startswith(_ANNOTATION_PREFIXES)
        ):
            out[local] = value
        else:
            out[key] = value
    return out


_STATE_KEYS = frozenset({"id", "initial", F_NAME, F_ACTION, F_START, F_REGION})
_TRANSITION_KEYS = frozenset({"event", "target", "cond", F_EXIT})
#: The one guard read: ``In('id')`` / ``In("id")`` (W3C's predicate, in every data model).
_IN_FINAL = re.compile(r"""\s*In\(\s*(?:'(?P<single>[^']+)'|"(?P<double>[^"]+)")\s*\)\s*""")


# -- reading -------------------------------------------------------------------------------------
@dataclass
class _Node:
    """One state element and where it sits in the model."""

    element: etree._Element
    state: State
    machine: FSM  # the machine that holds ``state``
    parent: _Node | None  # the compound/parallel state that owns ``machine``


@dataclass
class _Reader:
    ctx: ReadContext
    ns: str | None = None
    by_id: dict[str, _Node] = field(default_factory=dict)
    order: list[_Node] = field(default_factory=list)
    parent_of: dict[int, _Node | None] = field(default_factory=dict)  # id(machine) -> owner
    synthetic_states: list[tuple[FSM, State]] = field(default_factory=list)
    synthetic_transitions: list[tuple[FSM, Transition]] = field(default_factory=list)
    descriptors: dict[str, int] = field(default_factory=dict)
    done_transitions: list[tuple[_Node, etree._Element, bool]] = field(default_factory=list)
    wrapper_ids: set[str] = field(default_factory=set)
    data_ir: bool = False  # the document carries fsmbt's own data model (F_DATA)
    top: FSM = field(default_factory=FSM)

    def where(self, element: etree._Element) -> SourceLocation:
        return self.ctx.location(element.sourceline)

    def unsupported(self, element: etree._Element, feature: str) -> UnsupportedError:
        return UnsupportedError(
            feature, location=self.where(element), element=f"<{local_name(element)}>"
        )

    def tag(self, element: etree._Element) -> str | None:
        """The SCXML local name, or ``None`` for an element of another namespace."""
        if namespace(element) == XINCLUDE_NS:
            raise self.unsupported(
                element, "XInclude (include the fragment's content in the file itself)"
            )
        return local_name(element) if namespace(element) == self.ns else None

    def children(self, element: etree._Element) -> list[etree._Element]:
        return [c for c in element if isinstance(c.tag, str)]

    # structure ----------------------------------------------------------------------------------
    def read(self, text: str) -> FSM:
        root, _included = scxml_include.parse_document(text, self.ctx)
        self.ns = namespace(root)
        if self.ns == LEGACY_NS:
            raise UnsupportedError(
                "the obsolete 2005 SCXML working-draft syntax "
                f"(namespace {LEGACY_NS}); SCXML 1.0 uses {SCXML_NS}",
                location=self.where(root),
                element="<scxml>",
            )
        if local_name(root) != "scxml":
            raise InputError(
                f"not an SCXML document: root element is <{local_name(root)}>, "
                "expected <scxml> (a fragment meant for XInclude?)",
                location=self.where(root),
            )
        if self.ns not in (SCXML_NS, None):
            raise InputError(
                f"not an SCXML document: unknown namespace {self.ns}", location=self.where(root)
            )
        self.data_ir = root.get(F_DATA) == "ir"
        top = FSM(
            name=root.get("name", "fsm"),
            attrs={
                k: v
                for k, v in annotations_in(root.attrib, _SCXML_KEYS).items()
                if not (self.data_ir and k in (F_DATA, "datamodel"))
            },
        )
        self.top = top
        self.parent_of[id(top)] = None
        self.build(root, top)
        for node in self.order:
            self.transitions(node)
        self.check_prefix_matching()
        for machine, state in self.synthetic_states:
            machine.states[state.name] = state
        for machine, transition in self.synthetic_transitions:
            machine.transitions.append(transition)
        self.start_pseudo_state(top)
        return top

    def build(self, root: etree._Element, top: FSM) -> None:
        """Create every state and machine (explicit stack, document order), then initials."""
        for child in self.children(root):
            if self.tag(child) not in STATE_TAGS:
                self.content(child, root)
        initials: list[tuple[etree._Element, FSM]] = []
        stack: list[tuple[str, etree._Element, FSM, _Node | None]] = [("children", root, top, None)]
        while stack:
            mode, element, machine, owner = stack.pop()
            pending: list[tuple[str, etree._Element, FSM, _Node | None]] = []
            if mode == "single":  # a parallel state's child: the only state of its region
                node = self.state(element, machine, owner)
                pending.extend(self.regions(node))
                machine.initial = node.state.name
            else:
                for child in self.children(element):
                    if self.tag(child) in STATE_TAGS:
                        node = self.state(child, machine, owner)
                        pending.extend(self.regions(node))
                initials.append((element, machine))
            stack.extend(reversed(pending))
        for element, machine in reversed(initials):  # innermost first
            self.set_initial(element, machine)

    def state(self, element: etree._Element, machine: FSM, owner: _Node | None) -> _Node:
        tag = self.tag(element) or ""
        state_id = element.get("id") or f"_state{len(self.order) + 1}"
        if element.get(F_REGION) is not None:  # a wrapper never gets here (``regions``)
            raise InputError(
                'fsmbt:region="true" is only meaningful on a <state> child of <parallel>',
                location=self.where(element),
                element=f"<{tag}>",
            )
        if state_id in self.by_id or state_id in self.wrapper_ids:
            raise InputError(
                f"duplicate state id '{state_id}'", location=self.where(element), element=f"<{tag}>"
            )
        name = element.get(F_NAME, state_id)
        if name in machine.states:
            raise InputError(
                f"duplicate state name '{name}' in one machine",
                location=self.where(element),
                element=f"<{tag}>",
            )
        nested = []
        for child in self.children(element):
            if self.tag(child) in STATE_TAGS:
                nested.append(child)
            else:
                self.content(child, element)
        if tag == "final" and nested:
            raise InputError(
                "<final> cannot hold states", location=self.where(element), element="<final>"
            )
        action: str | None = name if not nested else None
        if F_ACTION in element.attrib:
            action = element.get(F_ACTION) or None
        attrs = annotations_in(element.attrib, _STATE_KEYS)
        if self.data_ir:
            for block in self.children(element):
                if self.tag(block) == "onexit" and self._assigned(block):
                    attrs[fsm_data.ONEXIT] = self._assigned(block)
        state = State(
            name, action=action, final=tag == "final", attrs=attrs, location=self.where(element)
        )
        machine.states[name] = state
        node = _Node(element, state, machine, owner)
        self.by_id[state_id] = node
        self.order.append(node)
        return node

    def regions(self, node: _Node) -> list[tuple[str, etree._Element, FSM, _Node | None]]:
        """The sub-machines of a compound (one) or parallel (one per child) state."""
        element = node.element
        nested = [c for c in self.children(element) if self.tag(c) in STATE_TAGS]
        if not nested:
            return []
        if local_name(element) == "parallel":
            out: list[tuple[str, etree._Element, FSM, _Node | None]] = []
            for child in nested:
                region = FSM(name=child.get(F_NAME, child.get("id") or "region"))
                self.parent_of[id(region)] = node
                node.state.regions.append(region)
                if child.get(F_REGION) == "true":
                    self.region_wrapper(child)
                    out.append(("children", child, region, node))
                else:
                    out.append(("single", child, region, node))
            return out
        region = FSM(name=node.state.name)
        self.parent_of[id(region)] = node
        node.state.regions.append(region)
        return [("children", element, region, node)]

    def region_wrapper(self, element: etree._Element) -> None:
        """A ``<state fsmbt:region="true">`` child of a ``<parallel>`` is the wrapper fsmbt
        writes around a region of several states: the region itself, not a state of it (a
        compound state with the same W3C meaning). It may hold states only."""
        if local_name(element) != "state":
            raise InputError(
                "fsmbt:region is only meaningful on a <state>",
                location=self.where(element),
                element=f"<{local_name(element)}>",
            )
        for child in self.children(element):
            if self.tag(child) not in STATE_TAGS and self.tag(child) != "initial":
                raise InputError(
                    f"a region wrapper (fsmbt:region) holds states only, not <{local_name(child)}>",
                    location=self.where(child),
                    element=f"<{local_name(child)}>",
                )
        wrapper_id = element.get("id")
        if wrapper_id is not None:
            if wrapper_id in self.by_id or wrapper_id in self.wrapper_ids:
                raise InputError(
                    f"duplicate state id '{wrapper_id}'",
                    location=self.where(element),
                    element="<state>",
                )
            self.wrapper_ids.add(wrapper_id)

    def content(self, element: etree._Element, container: etree._Element) -> None:
        """Non-state children of a state or of <scxml>: supported, warned or refused."""
        tag = self.tag(element)
        if tag is None:
            self.ctx.warn(
                f"element of another namespace ignored: <{etree.QName(element).localname}>",
                line=element.sourceline,
            )
        elif tag in ("transition", "initial"):
            return  # handled with the transitions / the initial state
        elif tag in ("onentry", "onexit", "donedata"):
            self.executable(element)
        elif tag == "datamodel" and self.data_ir:  # fsmbt's own data (fsm_data)
            self.top.attrs[fsm_data.DATAMODEL] = fsm_data.join_lines(
                [
                    (data.get("id") or "", data.get("expr") or "")
                    for data in self.children(element)
                    if self.tag(data) == "data"
                ]
            )
        elif tag == "datamodel":
            self.ctx.warn(
                "<datamodel> ignored (no supported construct reads data)",
                line=element.sourceline,
                element="<datamodel>",
            )
        elif tag in UNSUPPORTED_CONTENT:
            raise self.unsupported(
                element, f"<{tag}> (executable content and external communication change behaviour)"
            )
        elif tag == "history":
            raise self.unsupported(element, "<history> (the model has no history states)")
        elif tag == "invoke":
            raise self.unsupported(element, "<invoke> (external services)")
        else:
            raise InputError(
                f"unknown SCXML element <{tag}> in <{local_name(container)}>",
                location=self.where(element),
                element=f"<{tag}>",
            )

    def executable(self, block: etree._Element) -> None:
        """A block of executable content: only ``<log>`` (warned) is harmless."""
        for item in block.iter():
            if item is block or not isinstance(item.tag, str):
                continue
            tag = self.tag(item)
            if tag is None:
                self.ctx.warn(
                    f"element of another namespace ignored: <{etree.QName(item).localname}>",
                    line=item.sourceline,
                )
            elif tag in WARNED_CONTENT:
                self.ctx.warn(
                    f"<{tag}> ignored (no effect on the state machine)",
                    line=item.sourceline,
                    element=f"<{tag}>",
                )
            elif tag == "assign" and self.data_ir and local_name(block) in ("onexit", "transition"):
                continue  # fsmbt's own data: read into the model (``_assigned``)
            elif tag in ("param", "content") and local_name(block) == "donedata":
                self.ctx.warn("<donedata> ignored", line=item.sourceline, element="<donedata>")
            else:
                raise self.unsupported(item, f"<{tag}> (executable content that changes behaviour)")

    def _assigned(self, block: etree._Element) -> str:
        """The ``<assign>`` children of a block as ``name=expr`` lines (``fsm_data``)."""
        return fsm_data.join_lines(
            [
                (item.get("location") or "", item.get("expr") or "")
                for item in self.children(block)
                if self.tag(item) == "assign"
            ]
        )

    def set_initial(self, container: etree._Element, machine: FSM) -> None:
        """The machine's initial state: ``initial`` attribute, ``<initial>``, or first child."""
        targets = container.get("initial")
        where = container
        for child in self.children(container):
            if self.tag(child) == "initial":
                transitions = [t for t in self.children(child) if self.tag(t) == "transition"]
                if len(transitions) != 1:
                    raise InputError(
                        "<initial> needs exactly one <transition>",
                        location=self.where(child),
                        element="<initial>",
                    )
                self.executable(transitions[0])
                targets, where = transitions[0].get("target"), transitions[0]
        if not machine.states:
            return
        if not targets:
            machine.initial = next(iter(machine.states))
            return
        ids = targets.split()
        chosen: set[str] = set()
        for target_id in ids:
            node = self.by_id.get(target_id)
            if node is None:
                raise InputError(
                    f"initial state '{target_id}' does not exist",
                    location=self.where(where),
                    element=f"<{local_name(where)}>",
                )
            chosen.add(self.entry_in(node, machine, where).state.name)
        if len(chosen) != 1:
            raise self.unsupported(
                where, "an initial configuration spanning several states of one machine"
            )
        machine.initial = chosen.pop()

    # transitions --------------------------------------------------------------------------------
    def transitions(self, node: _Node) -> None:
        seen: set[tuple[str | None, str | None]] = set()
        for element in self.children(node.element):
            if self.tag(element) != "transition":
                continue
            for transition in self.transition(node, element):
                key = (transition.event, transition.exit)
                if key in seen:
                    self.ctx.warn(
                        f"transition on {transition.event or 'completion'} from "
                        f"'{node.state.name}' dropped: an earlier one in document order wins",
                        line=element.sourceline,
                        element="<transition>",
                    )
                    continue
                if fsm_data.COND not in transition.attrs:  # a data guard lets later ones fire
                    seen.add(key)
                node.machine.transitions.append(transition)

    def transition(self, node: _Node, element: etree._Element) -> list[Transition]:
        cond_exit = self.completion_guard(node, element)
        if element.get("type", "external") != "external":
            raise self.unsupported(element, f'type="{element.get("type")}" transitions')
        target_ids = (element.get("target") or "").split()
        if not target_ids:
            raise self.unsupported(
                element, "targetless transitions (they only run executable content)"
            )
        if len(target_ids) > 1:
            raise self.unsupported(element, "transitions with several targets")
        self.executable(element)
        target = self.by_id.get(target_ids[0])
        if target is None:
            raise InputError(
                f"transition to unknown state '{target_ids[0]}'",
                location=self.where(element),
                element="<transition>",
            )
        attrs = annotations_in(element.attrib, _TRANSITION_KEYS)
        if self.data_ir and cond_exit is None and element.get("cond") is not None:
            attrs[fsm_data.COND] = element.get("cond") or ""
        if self.data_ir and self._assigned(element):
            attrs[fsm_data.ASSIGN] = self._assigned(element)
        exit_name = self.exit_of(node, element, cond_exit)
        events = element.get("event")
        location = self.where(element)
        if events is None:
            if not node.state.is_atomic:
                raise self.unsupported(
                    element,
                    "eventless transitions of a compound state "
                    "(they fire at once, unlike completion)",
                )
            return [self.route(node, None, target, element, attrs, exit_name, location)]
        out = []
        names = events.split()
        if not names:
            raise InputError("empty event attribute", location=location, element="<transition>")
        for name in names:
            if name == "*" or name.endswith(".*") or name.endswith("."):
                raise self.unsupported(element, f"wildcard event descriptor '{name}'")
            event: str | None = name
            if name.startswith("done.state."):
                if node.state.is_atomic:
                    raise self.unsupported(
                        element,
                        f"'{name}' on an atomic state (only compound and parallel states complete)",
                    )
                if name != f"done.state.{node.element.get('id')}":
                    raise self.unsupported(
                        element, f"'{name}' on another state than the one that completes"
                    )
                event = None
                self.done_transitions.append((node, element, exit_name is not None))
            else:
                self.descriptors.setdefault(name, element.sourceline or 0)
            out.append(self.route(node, event, target, element, attrs, exit_name, location))
        return out

    def completion_guard(self, node: _Node, element: etree._Element) -> str | None:
        """The final state named by ``cond="In('F')"`` on a ``done.state.X`` transition of
        compound ``X`` (``F`` a ``<final>`` child of ``X``): the completion transition waits for
        ``F``. Any other ``cond`` is refused (the model has no data)."""
        cond = element.get("cond")
        if cond is None:
            return None
        match = _IN_FINAL.fullmatch(cond)
        if match is None and self.data_ir:  # a data guard of fsmbt's own data model
            return None
        events = (element.get("event") or "").split()
        own_done = f"done.state.{node.element.get('id')}"
        if match is None or events != [own_done] or local_name(node.element) != "state":
            raise self.unsupported(
                element,
                "cond guards (the model has no data; the only guard "
                "read is In('F') on a compound state's own "
                "done.state event, F one of its <final> children)",
            )
        final = self.by_id.get(match.group("single") or match.group("double"))
        if (
            final is None
            or local_name(final.element) != "final"
            or final.element.getparent() is not node.element
        ):
            raise self.unsupported(
                element,
                f"cond=\"{cond}\": In() must name a <final> child of '{node.element.get('id')}'",
            )
        return final.state.name

    def exit_of(self, node: _Node, element: etree._Element, cond_exit: str | None) -> str | None:
        """The final state a completion transition waits for: the ``In()`` guard (standard
        meaning), else the legacy annotation ``fsmbt:exit`` (files written before the guard;
        warned, since a W3C engine ignores it). Both present: they must agree."""
        legacy = element.get(F_EXIT)
        if legacy is None or cond_exit is not None:
            if legacy is not None and legacy != cond_exit:
                raise InputError(
                    f'fsmbt:exit="{legacy}" contradicts cond="'
                    f'{element.get("cond")}" (the guard is the meaning)',
                    location=self.where(element),
                    element="<transition>",
                )
            return cond_exit
        self.ctx.warn(
            f'fsmbt:exit="{legacy}" without a cond="In(...)" guard (a file '
            "written by an older fsmbt): read as fsmbt meant it, but a W3C engine "
            "takes the first done.state transition in document order; write the "
            "file again to get the guard",
            line=element.sourceline,
            element="<transition>",
        )
        return legacy

    def route(
        self,
        node: _Node,
        event: str | None,
        target: _Node,
        element: etree._Element,
        attrs: dict[str, str],
        exit_name: str | None,
        location: SourceLocation,
    ) -> Transition:
        """The model transition for ``node --event--> target``, leaving parents if needed."""
        ancestors = self.machine_chain(node.machine)
        entered = None
        for index, machine in enumerate(ancestors):  # noqa: B007 - index is read after the loop
            entered = self.entry_or_none(target, machine)
            if entered is not None:
                break
        if entered is None:
            raise InputError(
                "transition target is not in this document's tree",
                location=location,
                element="<transition>",
            )
        if entered is not target:
            entered = self.entry_in(target, entered.machine, element)
        if index == 0:
            return Transition(
                node.state.name, event, entered.state.name, exit_name, dict(attrs), location
            )
        # Leave ``index`` levels: transient final states carry the transition out.
        label = f"exit({node.state.name},{event or ''},{target.state.name})"
        first = Transition(node.state.name, event, label, exit_name, dict(attrs), location)
        source_machine = node.machine
        for level in range(1, index + 1):
            owner = self.parent_of[id(source_machine)]
            assert owner is not None
            if owner.state.is_parallel:
                raise self.unsupported(element, "transitions that leave a <parallel> region")
            self.synthetic_states.append(
                (source_machine, State(label, action=None, final=True, attrs={EXIT_MARK: "true"}))
            )
            next_label = label if level < index else entered.state.name
            self.synthetic_transitions.append(
                (owner.machine, Transition(owner.state.name, None, next_label, label))
            )
            source_machine = owner.machine
        return first

    def machine_chain(self, machine: FSM) -> list[FSM]:
        chain = [machine]
        owner = self.parent_of[id(machine)]
        while owner is not None:
            chain.append(owner.machine)
            owner = self.parent_of[id(owner.machine)]
        return chain

    def entry_or_none(self, target: _Node, machine: FSM) -> _Node | None:
        """The state of ``machine`` whose entry enters ``target``, if ``target`` is in it."""
        node: _Node | None = target
        while node is not None and node.machine is not machine:
            node = self.parent_of[id(node.machine)]
        return node

    def entry_in(self, target: _Node, machine: FSM, element: etree._Element) -> _Node:
        """As ``entry_or_none``, but the nested target must be what default entry reaches."""
        node = target
        while node.machine is not machine:
            if node.machine.initial is not None and node.machine.initial != node.state.name:
                raise self.unsupported(
                    element,
                    f"entering nested state '{target.state.name}' "
                    "that is not its parent's initial state",
                )
            owner = self.parent_of[id(node.machine)]
            if owner is None:
                raise InputError(
                    f"state '{target.state.name}' is not inside this state",
                    location=self.where(element),
                )
            node = owner
        return node

    def check_prefix_matching(self) -> None:
        for name, line in self.descriptors.items():
            if name in ("done", "done.state"):
                raise UnsupportedError(
                    f"event descriptor '{name}' also matches every "
                    "done.state.<id> completion event (SCXML prefix "
                    "matching)",
                    location=self.ctx.location(line),
                    element="<transition>",
                )
        self.check_done_prefixes()
        names = sorted(self.descriptors)
        for i, name in enumerate(names):
            for other in names[i + 1 :]:
                if not other.startswith(name):
                    break
                if other.startswith(name + "."):
                    raise UnsupportedError(
                        f"event descriptor '{name}' also matches '{other}' (SCXML prefix matching)",
                        location=self.ctx.location(self.descriptors[name]),
                        element="<transition>",
                    )

    def check_done_prefixes(self) -> None:
        """``done.state.a`` also matches ``done.state.a.b`` (SCXML prefix matching): refuse a
        completion transition of ``a`` that a W3C engine could take on the completion of another
        compound/parallel state ``a.b``, unless its ``In()`` guard rules that out (``a.b``
        inside compound ``a``, whose guard names a final child of ``a``: not active then)."""
        composite_ids = {
            state_id for state_id, node in self.by_id.items() if not node.state.is_atomic
        }
        for node, element, guarded in self.done_transitions:
            own = node.element.get("id") or ""
            for other in composite_ids:
                if not other.startswith(own + "."):
                    continue
                if guarded and self.is_inside(self.by_id[other], node):
                    continue
                raise self.unsupported(
                    element,
                    f"'done.state.{own}' also matches the "
                    f"completion event of '{other}' (SCXML prefix "
                    "matching)",
                )

    def is_inside(self, inner: _Node, outer: _Node) -> bool:
        owner = self.parent_of[id(inner.machine)]
        while owner is not None:
            if owner is outer:
                return True
            owner = self.parent_of[id(owner.machine)]
        return False

    def start_pseudo_state(self, top: FSM) -> None:
        """A state written with ``fsmbt:start`` is the FSM's start pseudo-state again."""
        for name, state in list(top.states.items()):
            node = self.by_name_top(name, top)
            if node is None or node.element.get(F_START) != "true":
                continue
            leaving = [t for t in top.transitions if t.source == name]
            if len(leaving) != 1 or top.initial != name or leaving[0].event is None:
                raise InputError(
                    "an fsmbt:start state needs to be the initial state with one "
                    "outgoing transition on an event",
                    location=state.location,
                )
            del top.states[name]
            top.transitions.remove(leaving[0])
            top.start_name, top.initial_event = name, leaving[0].event
            top.initial = leaving[0].target

    def by_name_top(self, name: str, top: FSM) -> _Node | None:
        for node in self.order:
            if node.machine is top and node.state.name == name:
                return node
        return None


def read_scxml(text: str, ctx: ReadContext) -> FSM:
    """The hierarchical model of the document; a document the structural reader refuses for a
    feature with a finite reading is read by running the W3C algorithm instead (a flat model,
    ``fsmbt.formats.scxml.w3c``; docs/formats/scxml.md)."""
    try:
        return _read_either(text, ctx)
    except InputError as exc:  # UnsupportedError too: name the file included content came from
        raise scxml_include.annotate(exc, text, ctx) from None


def _read_either(text: str, ctx: ReadContext) -> FSM:
    kept = len(ctx.warnings)
    try:
        return _Reader(ctx).read(text)
    except UnsupportedError as first:
        if "working-draft" in str(first) or "XInclude" in str(first):
            raise
        del ctx.warnings[kept:]  # the W3C reading warns about the same content again
        try:
            flat = read_scxml_w3c(text, ctx)
        except UnsupportedError as remaining:
            raise remaining from None
        ctx.warn(
            f"read by running the W3C algorithm (the structural reader refuses: "
            f"{first.message}); the model is the "
            "flat machine of the reachable configurations"
        )
        return flat


# -- writing -------------------------------------------------------------------------------------
@dataclass
class _Writer:
    """Writes the model back; transient exit states become the transitions they came from."""

    top: FSM
    owner: dict[int, tuple[FSM, State]] = field(default_factory=dict)  # id(region) -> owner
    ids: dict[tuple[int, str], str] = field(default_factory=dict)
    skip_states: set[tuple[int, str]] = field(default_factory=set)
    skip_transitions: set[int] = field(default_factory=set)
    rerouted: dict[int, tuple[FSM, str]] = field(default_factory=dict)  # id(t) -> real target
    taken: set[str] = field(default_factory=set)
    composite_ids: set[str] = field(default_factory=set)
    composite_prefixes: set[str] = field(default_factory=set)  # proper dot-prefixes of those
    #: id(machine) -> source state -> its transitions in document order (built on first use,
    #: so writing a state costs its own transitions, not the machine's: O(T) in all)
    outgoing: dict[int, dict[str, list[Transition]]] = field(default_factory=dict)

    def prepare(self) -> None:
        machines = [self.top]  # pre-order without recursion (FSM.walk recurses)
        stack = [self.top]
        while stack:
            machine = stack.pop()
            found = []
            for state in machine.states.values():
                for region in state.regions:
                    self.owner[id(region)] = (machine, state)
                    found.append(region)
            machines.extend(found)
            stack.extend(reversed(found))
        for machine in machines:
            for t in machine.transitions:
                resolved = self.resolve(machine, t.target)
                if resolved is not None:
                    self.rerouted[id(t)] = resolved
        used: dict[str, int] = {}
        reserved = {self.top.start_name} if self.top.initial_event is not None else set()
        for machine in machines:
            for state in machine.states.values():
                if (id(machine), state.name) not in self.skip_states:
                    used[state.name] = used.get(state.name, 0) + 1
        self.taken.update(n for n in reserved if n)
        for machine in machines:
            owner = self.owner.get(id(machine))
            for state in machine.states.values():
                if (id(machine), state.name) in self.skip_states:
                    continue
                prefix = self.ids[(id(owner[0]), owner[1].name)] if owner else "top"
                self.ids[(id(machine), state.name)] = self.allocate(
                    state.name, prefix, composite=not state.is_atomic, shared=used[state.name] > 1
                )

    def allocate(self, name: str, prefix: str, *, composite: bool, shared: bool) -> str:
        """A unique id for ``name`` (``<prefix>.<name>`` when the name repeats or is taken).

        The id of a compound/parallel state (it raises ``done.state.<id>``) is never a
        dot-prefix of another one's, nor has one as a dot-prefix: SCXML's event matching takes
        ``done.state.a`` for ``done.state.a.b`` too. Such ids get ``_`` for ``.``; a character
        an NCName cannot hold becomes ``_`` (``ncname``; the model name is kept in
        ``fsmbt:name``).
        """
        name = ncname(name)  # an id is one token (targets are lists of ids), an NCName
        unique = f"{prefix}.{name}" if shared or name in self.taken else name
        while unique in self.taken or (composite and self.dot_related(unique)):
            unique = unique.replace(".", "_") if composite and "." in unique else unique + "_"
        self.taken.add(unique)
        if composite:
            self.composite_ids.add(unique)
            parts = unique.split(".")
            self.composite_prefixes.update(".".join(parts[:n]) for n in range(1, len(parts)))
        return unique

    def dot_related(self, candidate: str) -> bool:
        """Is ``candidate`` a dot-prefix of a compound state's id, or the reverse?"""
        if candidate in self.composite_prefixes:
            return True
        parts = candidate.split(".")
        return any(".".join(parts[:n]) in self.composite_ids for n in range(1, len(parts)))

    def resolve(self, machine: FSM, target: str) -> tuple[FSM, str] | None:
        """Follow transient exit states up to the real target (``None`` if not one)."""
        chain_states: list[tuple[int, str]] = []
        chain_transitions: list[int] = []
        while True:
            state = machine.states.get(target)
            if state is None or state.attrs.get(EXIT_MARK) != "true":
                break
            up = self.owner.get(id(machine))
            if up is None:
                return None
            parent, composite = up
            completion = [
                t
                for t in parent.transitions
                if t.source == composite.name and t.event is None and t.exit == target
            ]
            if len(completion) != 1 or not composite.is_composite:
                return None
            chain_states.append((id(machine), target))
            chain_transitions.append(id(completion[0]))
            machine, target = parent, completion[0].target
        if not chain_states:
            return None
        self.skip_states.update(chain_states)
        self.skip_transitions.update(chain_transitions)
        return machine, target

    def write(self) -> str:
        fsm = self.top
        self.prepare()
        root = etree.Element(f"{{{SCXML_NS}}}scxml", nsmap={None: SCXML_NS, "fsmbt": FSMBT_NS})
        root.set("version", "1.0")
        if fsm.name != "fsm":
            root.set("name", fsm.name)
        start = None
        if fsm.initial_event is not None:
            start = fsm.start_name or "Start"
            root.set("initial", start)
        elif fsm.initial is not None:
            root.set("initial", self.ids[(id(fsm), fsm.initial)])
        for key, value in fsm.attrs.items():
            if key != fsm_data.DATAMODEL:
                root.set(annotation_attribute(key), value)
        if fsm_data.has_data(fsm):  # docs/semantics.md, "Data in state machines"
            root.set("datamodel", fsm_data.DIALECT)
            root.set(F_DATA, "ir")
            block = etree.SubElement(root, _q("datamodel"))
            for name, expr in fsm_data.parse_lines(fsm.attrs[fsm_data.DATAMODEL]):
                etree.SubElement(block, _q("data"), id=name, expr=expr)
        if start is not None and fsm.initial is not None:
            element = etree.SubElement(root, _q("state"), id=start)
            element.set(F_START, "true")
            etree.SubElement(
                element,
                _q("transition"),
                event=_event_descriptor(fsm.initial_event or "", start),
                target=self.ids[(id(fsm), fsm.initial)],
            )
        stack: list[tuple[FSM, etree._Element]] = [(fsm, root)]
        while stack:
            machine, container = stack.pop()
            if machine is not fsm and machine.initial_event is not None:
                raise UnsupportedError(
                    "a sub-machine with a start pseudo-state and initial "
                    "event cannot be written as SCXML",
                    element=machine.name,
                )
            pending = []
            for state in machine.states.values():
                if (id(machine), state.name) in self.skip_states:
                    continue
                element = self.state_element(container, machine, state)
                pending.extend(self.region_elements(element, state))
            stack.extend(reversed(pending))
        text = etree.tostring(root, encoding="unicode", pretty_print=True)
        return '<?xml version="1.0" encoding="UTF-8"?>\n' + text

    def state_element(
        self, container: etree._Element, machine: FSM, state: State
    ) -> etree._Element:
        tag = (
            "final"
            if state.final and state.is_atomic
            else "parallel"
            if _is_parallel(state)
            else "state"
        )
        state_id = self.ids[(id(machine), state.name)]
        element = etree.SubElement(container, _q(tag), id=state_id)
        if state_id != state.name:
            element.set(F_NAME, state.name)
        default_action = state.name if state.is_atomic else None
        if state.action != default_action:
            element.set(F_ACTION, state.action or "")
        if tag == "state" and state.is_composite:
            region = state.regions[0]
            if region.initial is not None:
                element.set("initial", self.ids[(id(region), region.initial)])
        for key, value in state.attrs.items():
            if key == fsm_data.ONEXIT:
                _assignments(etree.SubElement(element, _q("onexit")), value)
            else:
                element.set(annotation_attribute(key), value)
        by_source = self.outgoing.get(id(machine))
        if by_source is None:
            by_source = {}
            for t in machine.transitions:
                by_source.setdefault(t.source, []).append(t)
            self.outgoing[id(machine)] = by_source
        for t in by_source.get(state.name, ()):
            if id(t) in self.skip_transitions:
                continue
            self.transition_element(element, machine, state, state_id, t)
        return element

    def transition_element(
        self, element: etree._Element, machine: FSM, state: State, state_id: str, t: Transition
    ) -> None:
        out = etree.SubElement(element, _q("transition"))
        if t.event is not None:
            out.set("event", _event_descriptor(t.event, state.name))
        elif not state.is_atomic:
            out.set("event", f"done.state.{state_id}")
            if t.exit is not None:
                out.set("cond", _in_predicate(self.final_id(state, t.exit), state.name))
        target_machine, target = self.rerouted.get(id(t), (machine, t.target))
        key = (id(target_machine), target)
        if key not in self.ids:
            raise InputError(f"transition to unknown state '{target}'", element=state.name)
        out.set("target", self.ids[key])
        for k, v in t.attrs.items():
            if k == fsm_data.ASSIGN:
                _assignments(out, v)
            else:
                out.set(annotation_attribute(k), v)

    def final_id(self, state: State, exit_name: str) -> str:
        """The id of the final state a completion transition of ``state`` waits for."""
        region = state.regions[0]
        final = region.states.get(exit_name)
        if not state.is_composite or final is None or not final.final or not final.is_atomic:
            where = "a parallel state" if state.is_parallel else f"'{state.name}'"
            raise UnsupportedError(
                f"a completion transition of {where} waiting for "
                f"'{exit_name}', which is not a final state of its "
                "sub-machine, cannot be written as SCXML (it never fires)",
                element=state.name,
            )
        return self.ids[(id(region), exit_name)]

    def region_elements(
        self, element: etree._Element, state: State
    ) -> list[tuple[FSM, etree._Element]]:
        if not state.regions:
            return []
        if state.is_composite and not _is_parallel(state):
            return [(state.regions[0], element)]
        out = []
        for region in state.regions:
            if len(region.states) == 1 and region.initial in region.states:
                out.append((region, element))
            else:  # a region of several states needs a wrapper state in SCXML
                wrapper_id = self.allocate(
                    region.name, element.get("id") or state.name, composite=True, shared=True
                )
                wrapper = etree.SubElement(element, _q("state"), id=wrapper_id)
                wrapper.set(F_REGION, "true")
                if wrapper_id != region.name:
                    wrapper.set(F_NAME, region.name)
                if region.initial is not None:
                    wrapper.set("initial", self.ids[(id(region), region.initial)])
                out.append((region, wrapper))
        return out


def _assignments(parent: etree._Element, text: str) -> None:
    """``<assign location expr>`` children for ``name=expr`` lines (``fsmbt.model.fsm_data``)."""
    for name, expr in fsm_data.parse_lines(text):
        etree.SubElement(parent, _q("assign"), location=name, expr=expr)


_NOT_NCNAME = re.compile(r"[^\w.\-\u00B7\u0300-\u036F\u203F-\u2040]")


def ncname(name: str) -> str:
    """``name`` as an XML NCName, the type of SCXML's ``id`` (W3C SCXML §3.14, XML Namespaces
    §3): every character an NCName cannot hold (``:``, whitespace, punctuation) becomes ``_``,
    and a first character that cannot start one (a digit, ``-``, ``.``) gets a ``_`` before it.
    docs/formats/scxml.md "What fsmbt writes"."""
    out = _NOT_NCNAME.sub("_", name) or "_"
    if not (out[0].isalpha() or out[0] == "_"):
        out = "_" + out
    return out


def _in_predicate(state_id: str, source: str) -> str:
    """W3C's ``In('id')`` (``In("id")`` when the id holds a single quote)."""
    if "'" not in state_id:
        return f"In('{state_id}')"
    if '"' not in state_id:
        return f'In("{state_id}")'
    raise UnsupportedError(
        f"the state id {state_id!r} holds both quote characters and cannot "
        "be named in a cond guard",
        element=source,
    )


def _event_descriptor(event: str, source: str) -> str:
    """The event as an SCXML descriptor; names SCXML would read as something else are refused
    (see also ``_check_event_prefixes``)."""
    if (
        not event
        or any(c.isspace() for c in event)
        or event == "*"
        or event.endswith(".*")
        or event.endswith(".")
        or event in ("done", "done.state")
        or event.startswith("done.state.")
    ):
        raise UnsupportedError(
            f"event '{event}' cannot be an SCXML event name (whitespace, a "
            "wildcard, or a done.state event)",
            element=source,
        )
    return event


def _check_event_prefixes(fsm: FSM) -> None:
    """SCXML's descriptor ``a`` also matches event ``a.b``: such an alphabet cannot be written,
    except in a flat machine whose every state takes ``a.b`` by its own transition written
    before the one on ``a`` (or by neither): there the first transition in document order a W3C
    engine picks for ``a.b`` is the model's (the W3C reading of a document with prefix
    descriptors gives such machines; docs/formats/scxml.md)."""
    names: set[str] = set()
    for machine in fsm.machines():
        names.update(t.event for t in machine.transitions if t.event is not None)
        if machine.initial_event is not None:
            names.add(machine.initial_event)
    ordered = sorted(names)
    for i, name in enumerate(ordered):
        for other in ordered[i + 1 :]:
            if not other.startswith(name):
                break
            if other.startswith(name + ".") and not _prefix_order_exact(fsm, other):
                raise UnsupportedError(
                    f"events '{name}' and '{other}' cannot both be written as "
                    f"SCXML: the descriptor '{name}' also matches '{other}' "
                    "(SCXML prefix matching)"
                )


def _prefix_order_exact(fsm: FSM, event: str) -> bool:
    """In flat ``fsm``, is the first transition of each state whose descriptor matches
    ``event`` the transition on ``event`` itself (or is there none)?"""
    if fsm.is_hierarchical or fsm.initial_event is not None:
        return False
    first: dict[str, str] = {}
    for t in fsm.transitions:
        if t.event is None or t.source in first:
            continue
        if t.event == event or event.startswith(t.event + "."):
            first[t.source] = t.event
    return all(matched == event for matched in first.values())


def _is_parallel(state: State) -> bool:
    """Several regions, or one region holding one state named like it (a one-child parallel)."""
    if len(state.regions) > 1:
        return True
    if len(state.regions) == 1:
        region = state.regions[0]
        return (
            len(region.states) == 1 and region.name in region.states and region.name != state.name
        )
    return False


def _q(tag: str) -> str:
    return f"{{{SCXML_NS}}}{tag}"


def write_scxml(model: Model) -> str:
    if not isinstance(model, FSM):
        raise InputError("SCXML holds a state machine, not a behavior tree")
    _check_event_prefixes(model)
    try:
        return _Writer(model).write()
    except ValueError as exc:  # lxml: a name or value XML cannot hold
        raise InputError(f"cannot write as SCXML: {exc}") from None


def _sniff(text: str) -> bool:
    return root_tag(text) == "scxml"


def expand_data(fsm: FSM) -> FSM:
    """The exact flat meaning of a machine with data (``fsmbt.model.fsm_data``): the machine
    written as SCXML, read back by the W3C algorithm (every reachable configuration and
    valuation; docs/semantics.md, "Data in state machines"). Cost: the W3C reading's."""
    return read_scxml_w3c(write_scxml(fsm), ReadContext())


fsm_data.register_expander(expand_data)


register(
    Format(
        "scxml",
        (".scxml",),
        frozenset({"fsm"}),
        "W3C SCXML (states, compound and parallel states, final, initial, events)",
        read_scxml,
        write_scxml,
        _sniff,
        priority=30,
    )
)
