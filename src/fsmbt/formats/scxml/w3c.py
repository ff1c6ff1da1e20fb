"""SCXML read by running the W3C algorithm: the flat FSM of the reachable configurations
(docs/formats/scxml.md, "Documents read by the W3C algorithm").

Used when the structural reader (``fsmbt.formats.scxml.structural``) refuses a document for a feature
that has a finite reading: ``<history>`` (shallow and deep), ``cond`` guards, ``<raise>`` and
``<send>`` without delay (``eventexpr`` included when computable or unobservable), the finite
data model (``fsmbt.formats.scxml.datamodel``), ``<script>`` that cannot affect control flow,
ignored executable content (``<log>``, ``<assign>`` to a variable no cond reads), wildcard and
prefix event descriptors, ``done.state`` on atomic states, entry
into a non-initial nested state, targetless and ``type="internal"`` transitions, several
targets, eventless transitions of compound states, ``<invoke>`` of SCXML sessions (their
configurations are part of each state: ``fsmbt.formats.scxml.invoke``). Rules:

- The interpreter follows the W3C SCXML 1.0 algorithm (appendix D): transition selection per
  atomic state in document order, innermost first; conflicts resolved by exit sets; exit in
  reverse document order recording history; entry in document order; ``done.state.<id>``
  raised on the internal queue; a macro step runs eventless transitions, then internal
  events, to stability.
- ``<send>`` without ``target`` goes to the external queue, ``target="#_internal"`` to the
  internal one. Events the machine sends itself are processed, in order, before the next
  environment event (the environment waits for the machine to be idle).
- Variables control flow reads are part of the explored state (``a/a1#x=1``, after the
  history values); conds over them are computed (docs/formats/scxml.md, "Data read exactly").
  An ``error.execution`` skips the rest of its block and is raised on the internal queue.
- Any other guard is an input: an input symbol is an event together with the truth of the
  guards it may read, in document order: ``e[g1,!g2]`` (guard ``gN`` is the N-th distinct ``cond`` text; the mapping is in the
  model's ``attrs`` and in a warning). The environment chooses the guards' values with the
  event; they hold for the whole macro step. ``In('id')`` is evaluated exactly.
- A flat state is a configuration (named as ``fsmbt.model.flatten`` names them: ``a/a1``,
  ``p/[x|y]``), followed by ``#h=...`` history values when the document has history states.

Costs: O(C · I · M) for C reachable configurations, I input symbols, M the cost of one macro
step (O(n·d) per micro step for n states of nesting depth d). Everything is iterative.
"""

from __future__ import annotations

import operator
import re
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field
from itertools import product

from lxml import etree

from fsmbt import limits
from fsmbt.formats.registry import ReadContext
from fsmbt.formats.scxml import datamodel as scxml_datamodel
from fsmbt.formats.scxml import expr as scxml_expr
from fsmbt.formats.scxml import include as scxml_include
from fsmbt.formats.scxml import invoke as scxml_invoke
from fsmbt.formats.scxml.datamodel import Assignment, Declared, SendExpr
from fsmbt.formats.xml_safe import local_name, namespace
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.fsm import FSM, State

SCXML_NS = "http://www.w3.org/2005/07/scxml"
FSMBT_NS = "https://fsmbt.dev/ns/scxml"
XINCLUDE_NS = "http://www.w3.org/2001/XInclude"
F_NAME, F_REGION, F_ACTION = (f"{{{FSMBT_NS}}}{n}" for n in ("name", "region", "action"))
STATE_TAGS = frozenset({"state", "parallel", "final", "history"})
#: Guards one event may read (2**N input symbols per event).
MAX_GUARDS_PER_EVENT = 6
#: Micro steps in one macro step, and events a machine may queue for itself.
MAX_MICROSTEPS = 10_000
_IN = re.compile(r"""\s*In\(\s*(?:'([^']+)'|"([^"]+)")\s*\)\s*$""")
_IDENT = re.compile(r"[A-Za-z_$][\w$]*")


@dataclass
class _If:
    """``<if>`` with effects: the first branch whose guard holds (``None``: ``<else>``)."""

    branches: list[tuple[int | None, list[Action]]]
    effectless: bool = (
        False  # no event, no assignment a cond reads: skipped (decided after the plan)
    )


#: ("raise" | "internal" | "external", event name), ("internal_expr" | "external_expr", index
#: of a ``<send eventexpr>``), ("assign", index), ("script", line), or an ``<if>``.
Action = tuple[str, str] | _If
_NO_EVENT = frozenset(
    {"assign", "script", "internal_expr", "external_expr", "params", "invalid_target"}
)
_EVENT_FIELD = re.compile(r"\s*_event\.[A-Za-z_$][\w$]*\s*$")


def _event_names(actions: list[Action]) -> list[str]:
    """Every event ``actions`` may raise or send (all branches)."""
    out: list[str] = []
    stack = list(actions)
    while stack:
        action = stack.pop()
        if isinstance(action, _If):
            for _guard, inner in action.branches:
                stack.extend(inner)
        elif action[0] not in _NO_EVENT:
            out.append(action[1])
    return out


def _flatten(actions: list[Action]) -> list[Action]:
    """Every action of a block, ``<if>`` branches included, in document order."""
    out: list[Action] = []
    stack: list[Action] = list(reversed(actions))
    while stack:
        action = stack.pop()
        out.append(action)
        if isinstance(action, _If):
            for _guard, inner in reversed(action.branches):
                stack.extend(reversed(inner))
    return out


_UNKNOWN = object()  # a cache miss (a cached value may be None)


@dataclass
class _T:
    source: int
    events: tuple[str, ...]  # normalised descriptors ("*" or a prefix); () = eventless
    cond: tuple[str, int | str] | None  # ("in", state id) | ("guard", index)
    targets: tuple[int, ...]
    internal: bool
    actions: list[Action]
    line: int | None


@dataclass
class _S:
    index: int
    id: str
    name: str
    kind: str  # scxml | state | parallel | final | history
    parent: int | None
    line: int | None
    wrapper: bool = False
    action: str | None = None  # fsmbt:action of an atomic state (files fsmbt wrote)
    has_action: bool = False
    deep: bool = False
    children: list[int] = field(default_factory=list)
    initial: list[int] = field(default_factory=list)
    initial_actions: list[Action] = field(default_factory=list)
    transitions: list[_T] = field(default_factory=list)
    onentry: list[Action] = field(default_factory=list)
    onexit: list[Action] = field(default_factory=list)
    invokes: list[scxml_invoke.Invocation] = field(default_factory=list)


def abstractions(value: object) -> set[str]:
    """The abstraction names of the reader option ``abstract`` (``"time,blackboard"`` or a
    list); SCXML knows ``time``: a delayed ``<send>`` is a timer whose event the environment
    sends when it likes (docs/formats/scxml.md)."""
    if value is None:
        return set()
    if isinstance(value, str):
        items: list[object] = list(value.split(","))
    elif isinstance(value, (list, tuple, set, frozenset)):
        items = list(value)
    else:
        items = [value]
    return {str(item).strip() for item in items if str(item).strip()}


def _matches(descriptor: str, event: str) -> bool:
    """W3C 5.9.3: ``*`` matches every event; ``a`` matches ``a`` and ``a.b`` (token prefix)."""
    return descriptor == "*" or event == descriptor or event.startswith(descriptor + ".")


class _Doc:
    """The document's states and transitions (read with an explicit stack)."""

    def __init__(
        self,
        text: str,
        ctx: ReadContext,
        element: etree._Element | None = None,
        session: scxml_invoke.Session | None = None,
    ) -> None:
        """Read ``text`` (or, for an invoked document, its ``<scxml>`` ``element``)."""
        self.ctx = ctx
        self.session = session or scxml_invoke.Session()
        self.invocations: dict[str, scxml_invoke.Invocation] = {}
        self.session_targets: list[tuple[str, int | None]] = []
        self.abstract_time = "time" in abstractions(ctx.options.get("abstract"))
        if element is None:
            root, self.included = scxml_include.parse_document(text, ctx)
        else:  # an inline invoked document: part of its parent's (included) tree
            root, self.included = element, self.session.included or scxml_include.Included()
        self.ns = namespace(root)
        self.root_name = root.get("name", "fsm")
        self.root_attrs = {
            k: v for k, v in root.attrib.items() if k not in ("initial", "name", "version")
        }
        if local_name(root) != "scxml":
            raise InputError(
                f"not an SCXML document: root element is <{local_name(root)}>",
                location=ctx.location(root.sourceline),
            )
        self.states: list[_S] = []
        self.by_id: dict[str, int] = {}
        self.guards: list[str] = []
        self.guard_lines: dict[int, int | None] = {}
        self.dialect = scxml_expr.dialect_of(root.get("datamodel"))
        self.data: list[Declared] = []
        self.assign_exprs: list[Assignment] = []
        self.send_exprs: list[SendExpr] = []
        self.scripts: list[int | None] = []
        self.ifs: list[tuple[_If, list[int], int | None]] = []  # (if, its guards, line)
        self.plan = scxml_datamodel.DataPlan(self.dialect)
        self.branch_guards: set[int] = set()  # read by <if> branches, whatever the event
        self.transition_guards: set[int] = set()
        pending: list[tuple[int, etree._Element, str]] = []  # (state, element, target text)
        initial_text: dict[int, tuple[str, etree._Element]] = {}
        stack: list[tuple[etree._Element, int | None]] = [(root, None)]
        while stack:
            element, parent = stack.pop()
            tag = "scxml" if parent is None else self.tag(element)
            index = len(self.states)
            state_id = element.get("id") or ("" if parent is None else f"_state{index}")
            if state_id in self.by_id:
                raise InputError(
                    f"duplicate state id '{state_id}'", location=ctx.location(element.sourceline)
                )
            node = _S(
                index,
                state_id,
                element.get(F_NAME, state_id),
                tag or "",
                parent,
                element.sourceline,
                wrapper=element.get(F_REGION) == "true",
                deep=element.get("type") == "deep",
                action=element.get(F_ACTION) or None,
                has_action=F_ACTION in element.attrib,
            )
            self.states.append(node)
            if parent is not None:
                self.by_id[state_id] = index
                self.states[parent].children.append(index)
            kids = []
            for child in element:
                if not isinstance(child.tag, str):
                    continue
                ctag = self.tag(child)
                if ctag in STATE_TAGS:
                    kids.append(child)
                elif ctag == "transition":
                    pending.append((index, child, child.get("target") or ""))
                elif ctag == "initial":
                    inner = [
                        t for t in child if isinstance(t.tag, str) and self.tag(t) == "transition"
                    ]
                    if len(inner) != 1:
                        raise InputError(
                            "<initial> needs exactly one <transition>",
                            location=ctx.location(child.sourceline),
                        )
                    initial_text[index] = (inner[0].get("target") or "", inner[0])
                else:
                    self.content(child, node)
            if tag == "history":
                inner = [
                    t for t in element if isinstance(t.tag, str) and self.tag(t) == "transition"
                ]
                if len(inner) != 1:
                    raise InputError(
                        "<history> needs exactly one default <transition>",
                        location=ctx.location(element.sourceline),
                    )
            if tag == "final" and any(self.tag(k) != "history" for k in kids):
                raise InputError(
                    "<final> cannot hold states", location=ctx.location(element.sourceline)
                )
            if element.get("initial"):
                initial_text[index] = (element.get("initial") or "", element)
            stack.extend((k, index) for k in reversed(kids))
        # document order = creation order only for the first child chain: sort by preorder
        self.order = self.preorder()
        for index, element, target in pending:
            self.states[index].transitions.append(self.transition(index, element, target))
        for node in self.states:
            if node.kind in ("state", "scxml") and node.children:
                if node.index in initial_text:
                    text_, where = initial_text[node.index]
                    node.initial = self.ids(text_, where)
                    if self.tag(where) == "transition":
                        node.initial_actions = self.actions(where)
                else:
                    first = [c for c in node.children if self.states[c].kind != "history"]
                    node.initial = first[:1]
        if not self.states[0].initial:
            raise InputError("the document has no state", location=ctx.location(root.sourceline))
        self.check_default_targets()
        scxml_invoke.check_targets(self)
        self.decide_data()

    def check_default_targets(self) -> None:
        """W3C 3.3 and 3.10: a state's initial states, and a history's default transition
        targets, are proper descendants of the state (of the history's parent). Anything else
        would make entry re-enter an ancestor forever, so it is an error naming the state."""
        for node in self.states:
            if node.kind == "history":
                owner = node.parent if node.parent is not None else 0
                targets = [t for tr in node.transitions for t in tr.targets]
                what = f"history '{node.id}': its default transition target"
            else:
                owner, targets, what = (
                    node.index,
                    list(node.initial),
                    f"state '{node.id}': its initial",
                )
            for target in targets:
                up = self.states[target].parent
                while up is not None and up != owner:
                    up = self.states[up].parent
                if up is None and owner != 0:
                    raise InputError(
                        f"{what} '{self.states[target].id}' is not a descendant of "
                        f"'{self.states[owner].id}' (W3C: it must be one)",
                        location=self.ctx.location(node.line),
                        element=f"<{node.kind}> '{node.id}'",
                    )

    def tag(self, element: etree._Element) -> str | None:
        if namespace(element) == XINCLUDE_NS:
            raise self.refuse(
                element, "unsupported: XInclude (include the fragment's content in the file itself)"
            )
        return local_name(element) if namespace(element) == self.ns else None

    def where(self, element: etree._Element) -> str:
        return f"<{local_name(element)}>"

    def refuse(self, element: etree._Element, feature: str) -> UnsupportedError:
        return UnsupportedError(
            f"{feature}, line {element.sourceline}",
            location=self.ctx.location(element.sourceline),
            element=self.where(element),
        )

    def preorder(self) -> dict[int, int]:
        order: dict[int, int] = {}
        stack = [0]
        while stack:
            index = stack.pop()
            order[index] = len(order)
            stack.extend(reversed(self.states[index].children))
        return order

    def content(self, element: etree._Element, node: _S) -> None:
        tag = self.tag(element)
        if tag is None:
            self.ctx.warn(
                f"element of another namespace ignored: <{local_name(element)}>",
                line=element.sourceline,
            )
        elif tag == "onentry":
            node.onentry.extend(self.actions(element))
        elif tag == "onexit":
            node.onexit.extend(self.actions(element))
        elif tag == "datamodel":
            for data in element:
                if isinstance(data.tag, str) and self.tag(data) == "data":
                    has_content = (
                        len(data) > 0 or bool((data.text or "").strip()) or "src" in data.attrib
                    )
                    self.data.append(
                        Declared(
                            data.get("id") or "", data.get("expr"), has_content, data.sourceline
                        )
                    )
        elif tag == "donedata":
            self.ctx.warn("<donedata> ignored", line=element.sourceline, element="<donedata>")
        elif tag == "invoke":
            source = scxml_invoke.read_invoke(self, element, node)
            child = _Doc(source.text, source.ctx, element=source.element, session=source.session)
            scxml_invoke.add_invocation(self, element, node, source, child, _Interpreter(child))
        elif tag == "script":
            self.scripts.append(element.sourceline)
        else:
            raise InputError(
                f"unknown SCXML element <{tag}> in <{node.kind}>",
                location=self.ctx.location(element.sourceline),
                element=f"<{tag}>",
            )

    def actions(self, block: etree._Element | list[etree._Element]) -> list[Action]:
        """The queue effects of a block of executable content, in document order."""
        out: list[Action] = []
        for item in block:
            if not isinstance(item.tag, str):
                continue
            tag = self.tag(item)
            if (
                tag is None
                and namespace(item) in scxml_datamodel.COMMONS_NS
                and (local_name(item) == "var")
            ):
                out.append(self.commons_var(item))
            elif tag is None:
                self.ctx.warn(
                    f"element of another namespace ignored: <{local_name(item)}>",
                    line=item.sourceline,
                )
            elif tag == "log":
                self.ctx.warn("<log> ignored", line=item.sourceline, element="<log>")
            elif tag == "raise":
                out.append(("raise", self.event_name(item)))
            elif tag == "send":
                sent = self.send(item)
                if sent is not None:
                    out.extend([*self.send_data(item), sent])
            elif tag == "cancel" and self.abstract_time:
                self.ctx.warn(
                    "<cancel> ignored under the abstraction 'time' (a timer's event "
                    "may arrive at any time)",
                    line=item.sourceline,
                    element="<cancel>",
                )
            elif tag == "assign":
                location = (item.get("location") or "").strip()
                self.assign_exprs.append(Assignment(location, item.get("expr"), item.sourceline))
                out.append(("assign", str(len(self.assign_exprs) - 1)))
            elif tag == "script":
                self.scripts.append(item.sourceline)
                out.append(("script", str(item.sourceline or 0)))
            elif tag == "if":
                out.extend(self.if_block(item))
            else:
                feature = {
                    "elseif": "<elseif> outside <if>",
                    "else": "<else> outside <if>",
                    "foreach": "<foreach>",
                    "cancel": "<cancel> (of a delayed <send>)",
                }.get(tag, f"<{tag}>")
                raise self.refuse(item, f"unsupported: {feature}")
        return out

    def commons_var(self, item: etree._Element) -> Action:
        """Apache Commons SCXML's ``<cs:var name expr>``: declares ``name`` and assigns it
        (read as one global variable: Commons keeps it in the state's context, which is the
        same as long as no two states declare one name; docs/formats/scxml.md)."""
        name = (item.get("name") or "").strip()
        if not name:
            raise InputError(
                "<var> needs a name", location=self.ctx.location(item.sourceline), element="<var>"
            )
        if name not in {d.name for d in self.data}:
            self.data.append(Declared(name, None, False, item.sourceline))
        self.assign_exprs.append(Assignment(name, item.get("expr"), item.sourceline, True))
        return ("assign", str(len(self.assign_exprs) - 1))

    def if_block(self, item: etree._Element) -> list[Action]:
        """``<if>``/``<elseif>``/``<else>``: branches chosen by guards (inputs of the
        environment, like transition guards); an ``<if>`` none of whose branches raises or
        sends anything has no effect on the machine and is dropped with a warning."""
        branches: list[tuple[str | None, etree._Element]] = [(item.get("cond"), item)]
        body: list[list[etree._Element]] = [[]]
        for child in item:
            if not isinstance(child.tag, str):
                continue
            tag = self.tag(child)
            if tag in ("elseif", "else"):
                if branches[-1][0] is None and len(branches) > 1:
                    raise InputError(
                        "<else> must be the last branch of <if>",
                        location=self.ctx.location(child.sourceline),
                    )
                branches.append((child.get("cond") if tag == "elseif" else None, child))
                body.append([])
            else:
                body[-1].append(child)
        if item.get("cond") is None:
            raise InputError("<if> needs a cond", location=self.ctx.location(item.sourceline))
        wrapper_actions = [self.actions(elements) for elements in body]
        if not any(wrapper_actions):
            self.ctx.warn(
                "<if> ignored: its branches are empty", line=item.sourceline, element="<if>"
            )
            return []
        guarded: list[tuple[int | None, list[Action]]] = []
        indices: list[int] = []
        for (cond, origin), effects in zip(branches, wrapper_actions):
            index = None if cond is None else self.guard(cond, origin, internal=False)
            if index is not None:
                indices.append(index)
            guarded.append((index, effects))
        block = _If(guarded)
        self.ifs.append((block, indices, item.sourceline))
        return [block]

    def event_name(self, item: etree._Element) -> str:
        event = item.get("event")
        if not event or item.get("eventexpr") is not None:
            raise self.refuse(
                item, f"unsupported: <{local_name(item)}> without a literal event name (eventexpr)"
            )
        return event

    def send_data(self, item: etree._Element) -> list[Action]:
        """The data a ``<send>`` evaluates before sending (``<param>``, ``<content expr>``,
        ``namelist``), as a ``("params", "line:unsafe:reads_event")`` action before it: its
        values are event data fsmbt does not model, but its failure (W3C: ``error.execution``,
        the send and the rest of the block skipped) is. ``unsafe``: an expression fsmbt cannot
        vouch for (checked like a ``<script>``); ``reads_event``: reads ``_event``, which fails
        before the first event (checked while exploring)."""
        texts = [
            child.get("expr") or child.get("location") or ""
            for child in item
            if isinstance(child.tag, str) and self.tag(child) in ("param", "content")
        ]
        texts = [t for t in texts if t.strip()]
        texts.extend((item.get("namelist") or "").split())
        if not texts:
            return []
        self.ctx.warn(
            "<param>/<content> of <send> not evaluated (event data fsmbt does not model)",
            line=item.sourceline,
            element="<send>",
        )
        unsafe = reads_event = False
        for text in texts:
            if _EVENT_FIELD.match(text):
                reads_event = True
                continue
            try:
                expr = scxml_expr.parse(text)
            except scxml_expr.ExpressionError:
                unsafe = True
                continue
            reads_event |= scxml_expr.EVENT_NAME in expr.names
            declared = {d.name for d in self.data}
            unsafe |= not expr.names - {scxml_expr.EVENT_NAME} <= declared
        if not unsafe and not reads_event:
            return []
        return [("params", f"{item.sourceline or 0}:{int(unsafe)}:{int(reads_event)}")]

    def send(self, item: etree._Element) -> Action | None:
        delay = (item.get("delay") or "").strip()
        if item.get("delayexpr") is not None or delay not in ("", "0", "0s", "0ms"):
            if not self.abstract_time:
                raise self.refuse(
                    item,
                    "unsupported: <send> with a delay (a timer; the "
                    "option abstract=time reads it as an environment "
                    "input)",
                )
            self.ctx.warn(
                f"verified under the abstraction 'time': the timer of <send "
                f"event='{item.get('event') or item.get('eventexpr')}'> is an "
                "input of the environment (its event may arrive at any time, or "
                "never)",
                line=item.sourceline,
                element="<send>",
            )
            return None
        if item.get("targetexpr") is not None or item.get("typeexpr") is not None:
            raise self.refuse(item, "unsupported: <send> with a computed target or type")
        kind = item.get("type")
        if kind not in (None, "http://www.w3.org/TR/scxml/#SCXMLEventProcessor", "scxml"):
            raise self.refuse(item, f"unsupported: <send> of type '{kind}'")
        target = item.get("target")
        expression = item.get("eventexpr")
        if expression is not None and item.get("event") is None:
            if target not in (None, "#_internal"):
                raise self.refuse(
                    item, f"unsupported: <send eventexpr> to target '{target}' (another session)"
                )
            queue = "external" if target is None else "internal"
            self.send_exprs.append(SendExpr(expression, item.sourceline))
            return (f"{queue}_expr", str(len(self.send_exprs) - 1))
        name = self.event_name(item)
        if target is None:
            return ("external", name)
        if target == "#_internal":
            return ("internal", name)
        routed = scxml_invoke.send_target(self, target, name, item.sourceline)
        if routed is not None:
            return routed
        if not target.startswith("#") and ":" not in target:
            # neither a special target (#_...) nor a URI: W3C 6.2.4 says an invalid target
            # places error.execution on the internal queue (python-statemachine agrees)
            self.ctx.warn(
                f"<send target='{target}'> is not a valid target (W3C: '#_internal', "
                "'#_parent', '#_<invokeid>' or a URI): read as W3C says, it raises "
                f"error.execution and sends nothing ('{target}' is an older draft's spelling?)",
                line=item.sourceline,
                element="<send>",
            )
            return ("invalid_target", str(item.sourceline or 0))
        raise self.refuse(item, f"unsupported: <send> to target '{target}' (another session)")

    def ids(self, text: str, element: etree._Element) -> list[int]:
        out = []
        for target_id in text.split():
            if target_id not in self.by_id:
                raise InputError(
                    f"target state '{target_id}' does not exist",
                    location=self.ctx.location(element.sourceline),
                    element=self.where(element),
                )
            out.append(self.by_id[target_id])
        return out

    def transition(self, source: int, element: etree._Element, target: str) -> _T:
        descriptors = []
        for token in (element.get("event") or "").split():
            if token.endswith(".*"):
                token = token[:-2]
            token = token.rstrip(".") or "*"
            descriptors.append(token)
        cond_text = element.get("cond")
        cond: tuple[str, int | str] | None = None
        if cond_text is not None:
            found = _IN.match(cond_text)
            if found:
                state_id = found.group(1) or found.group(2)
                if state_id not in self.by_id:
                    self.ctx.warn(
                        f"In('{state_id}') names no state: always false",
                        line=element.sourceline,
                        element="<transition>",
                    )
                cond = ("in", state_id)
            else:
                cond = ("guard", self.guard(cond_text, element, internal=False))
                self.transition_guards.add(int(cond[1]))
        return _T(
            source,
            tuple(descriptors),
            cond,
            tuple(self.ids(target, element)),
            element.get("type") == "internal",
            self.actions(element),
            element.sourceline,
        )

    def guard(self, cond_text: str, element: etree._Element, *, internal: bool) -> int:
        """The index of a guard (one per distinct cond text, in document order)."""
        text = " ".join(cond_text.split())
        if text not in self.guards:
            self.guards.append(text)
            self.guard_lines[len(self.guards) - 1] = element.sourceline
        index = self.guards.index(text)
        if internal:
            self.branch_guards.add(index)
        return index

    def decide_data(self) -> None:
        """The data plan (``fsmbt.formats.scxml.datamodel``: tracked variables, computed conds,
        exact event expressions), the warnings for what it ignores, and the ``<script>`` and
        failing-content checks (docs/formats/scxml.md, "Data read exactly")."""
        descriptors = sorted({d for n in self.states for t in n.transitions for d in t.events})
        dialect = None if self.ctx.options.get("data") == "inputs" else self.dialect
        used: set[int] = set(self.transition_guards)
        while True:  # an <if> with effects makes its conds used: they may make more relevant
            try:
                plan = scxml_datamodel.plan(
                    dialect,
                    self.data,
                    self.assign_exprs,
                    self.guards,
                    self.send_exprs,
                    descriptors,
                    used,
                )
            except scxml_datamodel.Refusal as refusal:
                message = refusal.message
                if refusal.line is not None and f"line {refusal.line}" not in message:
                    message += f", line {refusal.line}"
                location = self.ctx.location(refusal.line)
                raise UnsupportedError(message, location=location) from None
            self.plan = plan
            grown = set(used)
            for block, indices, _line in self.ifs:
                inner = _flatten([a for _g, branch in block.branches for a in branch])
                block.effectless = not any(
                    self.matters(a, descriptors, events=False) for a in inner
                )
                if not block.effectless:
                    grown.update(indices)
            if grown == used:
                break
            used = grown
        blocks = self.blocks()
        for block, indices, line in self.ifs:
            if block.effectless:
                self.ctx.warn(
                    "<if> ignored: no branch raises or sends an event, or changes a variable a "
                    "cond reads",
                    line=line,
                    element="<if>",
                )
            else:
                self.branch_guards.update(g for g in indices if g not in plan.computed)
        for index, a in enumerate(self.assign_exprs):
            if index not in plan.assigns:
                what = "<var>" if a.declares else "<assign>"
                self.ctx.warn(
                    f"{what} to '{a.location}' ignored (no cond reads it)",
                    line=a.line,
                    element=what,
                )
        for index in sorted(plan.dropped_sends):
            send = self.send_exprs[index]
            self.ctx.warn(
                f'<send eventexpr="{send.text}"> dropped: no event descriptor can match the '
                "event it sends",
                line=send.line,
                element="<send>",
            )
        if plan.relevant:
            constant = [n for n in plan.relevant if n not in plan.varying]
            self.ctx.warn(
                "the data model is read exactly (conds over it are computed): "
                + (
                    f"the values of {', '.join(plan.varying)} are part of each state"
                    if plan.varying
                    else ""
                )
                + ("; " if plan.varying and constant else "")
                + (f"{', '.join(constant)} never change(s)" if constant else "")
            )
        elif self.data:
            self.ctx.warn(
                "<datamodel> ignored (no cond or event expression reads a variable that changes)",
                line=self.data[0].line,
                element="<datamodel>",
            )
        live = self.live_descriptors()  # an error.execution only live transitions take matters
        self.check_scripts(live)
        self.check_failures(blocks, live)

    def live_descriptors(self) -> list[str]:
        """The descriptors of the transitions that can change something (least fixpoint): a
        transition with targets, or one whose content matters (an event a live transition
        matches, an exact computed event, an assignment a cond reads). An event no live
        transition matches is inert: taking a targetless transition without effects, or not,
        is the same run (its exit set is empty, so it preempts nothing)."""
        transitions = [t for n in self.states for t in n.transitions]
        live = [bool(t.targets) for t in transitions]
        changed = True
        while changed:
            changed = False
            descriptors = [d for t, on in zip(transitions, live) if on for d in t.events]
            for n, t in enumerate(transitions):
                if not live[n] and any(self.matters(a, descriptors) for a in _flatten(t.actions)):
                    live[n] = changed = True
        return sorted({d for t, on in zip(transitions, live) if on for d in t.events})

    def blocks(self) -> list[list[Action]]:
        """Every block of executable content (W3C: an error skips the rest of its block)."""
        out: list[list[Action]] = []
        for node in self.states:
            out.extend([node.onentry, node.onexit, node.initial_actions])
            out.extend(t.actions for t in node.transitions)
        return [block for block in out if block]

    def matters(self, action: Action, descriptors: list[str], *, events: bool = True) -> bool:
        """Whether ``action`` can change what the machine does: an event some descriptor
        matches, an exact computed event, an assignment to a variable a cond reads."""
        if isinstance(action, _If):
            return False  # its branches are walked on their own
        kind, value = action
        if kind == "assign":
            return int(value) in self.plan.assigns
        if kind in ("script", "params"):
            return False
        if kind == "invalid_target":  # it raises error.execution
            return scxml_datamodel.matches_error_execution(descriptors) or not events
        if kind.endswith("_expr"):
            return int(value) in self.plan.sends and self.send_may_match(int(value), descriptors)
        return any(scxml_datamodel.matches(d, value) for d in descriptors) or not events

    def send_may_match(self, index: int, descriptors: list[str]) -> bool:
        """Whether an exact ``eventexpr`` may send an event one of ``descriptors`` matches."""
        text = self.send_exprs[index].text
        prefix = scxml_datamodel.literal_prefix(text)
        if prefix is not None:
            return scxml_datamodel.may_match_prefix(descriptors, prefix)
        expr = self.plan.sends[index]
        if len(expr.postfix) == 1 and expr.postfix[0][0] == "value":
            name = scxml_expr.shown(expr.postfix[0][1])  # type: ignore[arg-type]
            return any(scxml_datamodel.matches(d, name) for d in descriptors)
        return True

    def may_fail(self, action: Action) -> bool:
        """Whether an ignored action may fail (W3C: ``error.execution``, the rest of its
        block skipped): a ``<script>``, an ``<assign>`` fsmbt does not evaluate whose location
        or expression it cannot vouch for."""
        if isinstance(action, _If):
            return False
        kind, value = action
        if kind == "script":
            return True
        if kind == "params":
            return value.split(":")[1] == "1"
        if kind != "assign" or int(value) in self.plan.assigns:
            return False
        a = self.assign_exprs[int(value)]
        dialect = self.plan.dialect
        if dialect is None or a.location not in self.plan.declared or a.expr is None:
            return True
        try:
            expr = scxml_expr.parse(a.expr, dialect)
        except scxml_expr.ExpressionError:
            return True
        return not dialect.undeclared_is_null and not expr.names <= self.plan.declared

    def check_scripts(self, descriptors: list[str]) -> None:
        if not self.scripts:
            return
        reason = self.plan.reads_data
        if reason is None and scxml_datamodel.matches_error_execution(descriptors):
            reason = "a transition takes error.execution, which a failing script raises"
        line = self.scripts[0]
        if reason is not None:
            raise UnsupportedError(
                f"unsupported: <script> ({reason}), line {line}",
                location=self.ctx.location(line),
                element="<script>",
            )
        for line in self.scripts:
            self.ctx.warn(
                "<script> ignored: it cannot affect control flow (no cond or event "
                "expression reads the data model, no transition takes error.execution)",
                line=line,
                element="<script>",
            )

    def check_failures(self, blocks: list[list[Action]], descriptors: list[str]) -> None:
        failing = scxml_datamodel.matches_error_execution(descriptors)
        for block in blocks:
            first_failing: Action | None = None
            for action in _flatten(block):
                if first_failing is None and self.may_fail(action):
                    first_failing = action
                    if failing:
                        break
                elif first_failing is not None and self.matters(action, descriptors):
                    break
            else:
                continue
            assert first_failing is not None and not isinstance(first_failing, _If)
            kind, value = first_failing
            if kind == "script":
                what, line = "<script>", int(value)
            elif kind == "params":
                what, line = "<param>/<content> of <send>", int(value.split(":")[0])
            else:
                a = self.assign_exprs[int(value)]
                what, line = f"<assign> to '{a.location}'", a.line or 0
            effect = (
                "a transition takes error.execution"
                if failing
                else "a failure would skip what follows it in its block"
            )
            raise UnsupportedError(
                f"unsupported: {what} that fsmbt does not evaluate may fail ({effect}), "
                f"line {line}",
                location=self.ctx.location(line),
                element=what.split(" ")[0],
            )


@dataclass
class _Run:
    """One macro step's state (mutable)."""

    config: set[int]
    history: dict[int, frozenset[int]]
    internal: deque[str] = field(default_factory=deque)
    external: deque[str] = field(default_factory=deque)
    running: bool = True
    moved: bool = False
    valuation: dict[int, bool] = field(default_factory=dict)  # the environment's guard values
    data: dict[str, scxml_expr.Value] = field(default_factory=dict)  # the relevant variables
    read: set[int] = field(default_factory=set)  # guards read so far
    # invoked sessions (fsmbt.formats.scxml.invoke)
    sessions: dict[str, scxml_invoke.Child] = field(default_factory=dict)
    to_invoke: list[int] = field(default_factory=list)  # states entered in this macro step
    outbox: list[str] = field(default_factory=list)  # events for the parent session
    serial: int = 0
    event: str | None = None  # _event.name: the event being processed (None: none yet)

    def spawn(
        self,
        config: set[int],
        history: dict[int, frozenset[int]],
        data: dict[str, scxml_expr.Value],
    ) -> _Run:
        """A fresh run for a child session (``scxml_invoke.Run``)."""
        return _Run(config, history, data=data)


#: A value that could not be computed: ``error.execution`` was raised.
_FAILED = object()


class _Interpreter:
    def __init__(self, doc: _Doc) -> None:
        self.doc = doc
        self.s = doc.states
        self.order = doc.order
        self.descriptors = sorted({d for n in doc.states for t in n.transitions for d in t.events})
        self.ancestors: list[list[int]] = []
        for node in self.s:
            chain, parent = [], node.parent
            while parent is not None:
                chain.append(parent)
                parent = self.s[parent].parent
            self.ancestors.append(chain)
        #: values of pure expressions (no ``In()``, no ``_event``) by the values they read:
        #: id(expr) -> the names read, and (id(expr), values) -> value (same result, computed
        #: once: a guard is asked again in every configuration with the same data)
        self.pure: dict[int, tuple[str, ...] | None] = {}
        self.memo: dict[tuple[int, tuple[object, ...], tuple[type, ...]], object] = {}
        #: the value of each pure expression that reads no variable (a literal reset, the most
        #: common assignment of a converted tree's halts), once it evaluated without error
        self.constant: dict[int, object] = {}
        # the document's shape does not change while it runs: atomic/compound once per state
        self.is_atomic: list[bool] = [
            not any(self.s[c].kind != "history" for c in node.children) for node in self.s
        ]
        self.fixed_domain: dict[int, int | None] = {}
        self.names: dict[frozenset[int], str] = {}  # configuration -> its part of a name
        self.actions: dict[frozenset[int], str | None] = {}  # configuration -> its action
        self.fitting: dict[tuple[int, str | None], list[_T]] = {}  # (state, event) -> matching
        self.shown: dict[tuple[str, type, object], str] = {}  # (var, type, value) -> "var=v"
        self.is_compound: list[bool] = [
            node.kind in ("state", "scxml") and not self.is_atomic[i]
            for i, node in enumerate(self.s)
        ]

    # -- tree helpers ---------------------------------------------------------------------------
    def atomic(self, i: int) -> bool:
        return self.is_atomic[i]

    def compound(self, i: int) -> bool:
        return self.is_compound[i]

    def descendant(self, i: int, of: int) -> bool:
        return of in self.ancestors[i]

    def proper_ancestors(self, i: int, stop: int | None) -> list[int]:
        out = []
        for a in self.ancestors[i]:
            if a == stop:
                break
            out.append(a)
        return out

    def in_final(self, i: int, config: set[int]) -> bool:
        stack, pending = [i], True
        while stack and pending:
            node = stack.pop()
            if self.compound(node):
                if not any(
                    c in config and self.s[c].kind == "final" for c in self.s[node].children
                ):
                    return False
            elif self.s[node].kind == "parallel":
                stack.extend(self.s[node].children)
            else:
                return False
        return True

    # -- selection ------------------------------------------------------------------------------
    def cond_ok(self, t: _T, run: _Run, valuation: dict[int, bool], read: set[int]) -> bool:
        if t.cond is None:
            return True
        kind, value = t.cond
        if kind == "in":
            return self.doc.by_id.get(str(value), -1) in run.config
        return self.guard_holds(int(value), run, valuation, read)

    def guard_holds(
        self, index: int, run: _Run, valuation: dict[int, bool], read: set[int]
    ) -> bool:
        """A guard's value: computed from the data when the plan computes it (an
        ``error.execution`` is false, W3C 5.9.1), else the environment's choice."""
        expr = self.doc.plan.computed.get(index)
        if expr is None:
            read.add(index)
            return valuation.get(index, False)
        value = self.value(expr, run, self.doc.guard_lines.get(index))
        return value is not _FAILED and scxml_expr.truthy(value)  # type: ignore[arg-type]

    def value(self, expr: scxml_expr.Expr, run: _Run, line: int | None) -> object:
        """``expr``'s value in ``run``; ``_FAILED`` after raising ``error.execution``. Pure
        expressions are memoized by the values they read (a constant once), so the data
        expansion evaluates each distinct case once."""
        hit = self.constant.get(id(expr), _UNKNOWN)
        if hit is not _UNKNOWN:
            return hit
        if id(expr) in self.pure:
            reads = self.pure[id(expr)]
        else:
            pure = scxml_expr.EVENT_NAME not in expr.names and all(
                kind != "call" for kind, _item in expr.postfix
            )
            reads = self.pure[id(expr)] = tuple(sorted(expr.names)) if pure else None
        key = None
        if reads is not None:
            data = run.data
            try:
                read = tuple([data[n] for n in reads])
            except KeyError:
                pass  # a variable not yet defined: evaluated (and raises) below
            else:  # types too: 1, 1.0 and True are equal keys but print differently
                key = (id(expr), read, tuple(map(type, read)))
                hit = self.memo.get(key, _UNKNOWN)
                if hit is not _UNKNOWN:
                    return hit
        try:
            value = scxml_expr.evaluate(
                expr,
                run.data,
                lambda state_id: self.doc.by_id.get(state_id, -1) in run.config,
                run.event,
            )
        except scxml_expr.ExecutionError:
            run.internal.append(scxml_datamodel.ERROR_EXECUTION)
            return _FAILED
        except scxml_expr.ExpressionError as exc:
            raise UnsupportedError(
                f"unsupported: '{expr.text}': {exc}, line {line}",
                location=self.doc.ctx.location(line),
            ) from None
        if reads == ():
            self.constant[id(expr)] = value
        elif key is not None:
            self.memo[key] = value
        return value

    def select(
        self, run: _Run, event: str | None, valuation: dict[int, bool], read: set[int]
    ) -> list[_T]:
        enabled: list[_T] = []
        is_atomic = self.is_atomic
        atoms = sorted((i for i in run.config if is_atomic[i]), key=self.order.__getitem__)
        for atom in atoms:
            for state in [atom, *self.ancestors[atom]]:
                chosen = None
                fitting = self.fitting.get((state, event))
                if fitting is None:  # the transitions whose descriptors match, in order
                    fitting = self.fitting[(state, event)] = [
                        t
                        for t in self.s[state].transitions
                        if (
                            not t.events
                            if event is None
                            else any(_matches(d, event) for d in t.events)
                        )
                    ]
                for t in fitting:
                    if self.cond_ok(t, run, valuation, read):
                        chosen = t
                        break
                if chosen is not None:
                    if chosen not in enabled:
                        enabled.append(chosen)
                    break
        return self.remove_conflicts(enabled, run)

    def remove_conflicts(self, enabled: list[_T], run: _Run) -> list[_T]:
        kept: list[_T] = []
        for t1 in enabled:
            preempted, removed = False, []
            for t2 in kept:
                if self.exit_set(t1, run) & self.exit_set(t2, run):
                    if self.descendant(t1.source, t2.source):
                        removed.append(t2)
                    else:
                        preempted = True
                        break
            if not preempted:
                kept = [t for t in kept if t not in removed] + [t1]
        return kept

    def effective_targets(self, t: _T, run: _Run) -> list[int]:
        out: list[int] = []
        work = list(reversed(t.targets))
        while work:
            s = work.pop()
            if self.s[s].kind == "history":
                if s in run.history:
                    out.extend(
                        x
                        for x in sorted(run.history[s], key=self.order.__getitem__)
                        if x not in out
                    )
                else:
                    work.extend(reversed(self.s[s].transitions[0].targets))
            elif s not in out:
                out.append(s)
        return out

    def domain(self, t: _T, run: _Run) -> int | None:
        """W3C getTransitionDomain. Without a history target it depends on ``t`` alone and is
        computed once per transition (``fixed_domain``)."""
        cached = self.fixed_domain.get(id(t), _UNKNOWN)
        if cached is not _UNKNOWN:
            return cached  # type: ignore[return-value]
        found = self._domain(t, run)
        if not any(self.s[x].kind == "history" for x in t.targets):
            self.fixed_domain[id(t)] = found  # ``t`` lives as long as the document
        return found

    def _domain(self, t: _T, run: _Run) -> int | None:
        targets = self.effective_targets(t, run)
        if not targets:
            return None
        if (
            t.internal
            and self.compound(t.source)
            and all(self.descendant(x, t.source) for x in targets)
        ):
            return t.source
        for anc in self.ancestors[t.source]:
            if (self.compound(anc) or anc == 0) and all(self.descendant(x, anc) for x in targets):
                return anc
        return 0

    def exit_set(self, t: _T, run: _Run) -> set[int]:
        if not t.targets:
            return set()
        domain = self.domain(t, run)
        return {s for s in run.config if domain is not None and self.descendant(s, domain)}

    # -- micro step -----------------------------------------------------------------------------
    def perform(self, actions: Sequence[Action], run: _Run) -> None:
        """Run a block of executable content; an ``error.execution`` skips the rest of it."""
        plan = self.doc.plan
        stack = list(reversed(actions))
        while stack:
            action = stack.pop()
            if isinstance(action, _If):
                if action.effectless:
                    continue
                for guard, inner in action.branches:
                    if guard is None or self.guard_holds(guard, run, run.valuation, run.read):
                        stack.extend(reversed(inner))
                        break
                continue
            kind, name = action
            if kind == "parent" or kind.startswith("session:"):
                scxml_invoke.route(run, self.doc.session.invoked, kind, name)
                continue
            if kind == "script":
                continue
            if kind == "invalid_target":  # W3C 6.2.4: error.execution, the block ends
                run.internal.append(scxml_datamodel.ERROR_EXECUTION)
                return
            if kind == "params":
                if name.endswith(":1") and run.event is None:  # _event before any event
                    run.internal.append(scxml_datamodel.ERROR_EXECUTION)
                    return
                continue
            if kind == "assign":
                index = int(name)
                if index in plan.assigns:
                    a = self.doc.assign_exprs[index]
                    value = self.value(plan.assigns[index], run, a.line)
                    if value is _FAILED:
                        return
                    run.data[a.location] = value  # type: ignore[assignment]
                continue
            if kind.endswith("_expr"):
                index = int(name)
                if index in plan.dropped_sends:
                    continue
                event = self.sent_event(index, run)
                if event is None:
                    return
                (run.external if kind == "external_expr" else run.internal).append(event)
                continue
            (run.external if kind == "external" else run.internal).append(name)

    def sent_event(self, index: int, run: _Run) -> str | None:
        """The event name a ``<send eventexpr>`` computes (``None``: ``error.execution``)."""
        expr = self.doc.plan.sends[index]
        line = self.doc.send_exprs[index].line
        value = self.value(expr, run, line)
        if value is _FAILED:
            return None
        try:
            name = scxml_expr.text_of(value)  # type: ignore[arg-type]
        except scxml_expr.ExpressionError as exc:
            raise UnsupportedError(
                f'unsupported: <send eventexpr="{expr.text}">: {exc}, line {line}',
                location=self.doc.ctx.location(line),
            ) from None
        if scxml_expr.EVENT_NAME in expr.names and any(
            d.startswith(name + ".") for d in self.descriptors
        ):
            raise UnsupportedError(
                f"unsupported: <send eventexpr=\"{expr.text}\"> sends '{name}', and a longer "
                "event name for which fsmbt's event stands would send an event another "
                f"descriptor matches, line {line}",
                location=self.doc.ctx.location(line),
            )
        return name

    def microstep(self, enabled: list[_T], run: _Run) -> None:
        run.moved = True
        leaving: set[int] = set()
        for t in enabled:
            leaving |= self.exit_set(t, run)
        ordered = sorted(leaving, key=self.order.__getitem__, reverse=True)
        for s in ordered:
            for h in self.s[s].children:
                if self.s[h].kind != "history":
                    continue
                if self.s[h].deep:
                    value = {x for x in run.config if self.atomic(x) and self.descendant(x, s)}
                else:
                    value = {x for x in run.config if self.s[x].parent == s}
                run.history[h] = frozenset(value)
        for s in ordered:
            self.perform(self.s[s].onexit, run)
            scxml_invoke.on_exit(run, self.s[s])
            run.config.discard(s)
        for t in enabled:
            self.perform(t.actions, run)
        self.enter(enabled, run)

    def enter(self, enabled: list[_T], run: _Run) -> None:
        to_enter: set[int] = set()
        default_entry: set[int] = set()
        history_content: dict[int, list[Action]] = {}
        tasks: list[tuple[str, int, int | None]] = []
        for t in reversed(enabled):
            if not t.targets:
                continue
            domain = self.domain(t, run)
            for s in reversed(self.effective_targets(t, run)):
                tasks.append(("anc", s, domain))
            for s in reversed(t.targets):
                tasks.append(("desc", s, None))
        while tasks:  # W3C's addDescendant/AncestorStatesToEnter, depth first on a stack
            kind, s, extra = tasks.pop()
            node = self.s[s]
            if kind == "desc":
                if node.kind == "history":
                    if s in run.history:
                        targets = sorted(run.history[s], key=self.order.__getitem__)
                    else:
                        history_content[node.parent or 0] = node.transitions[0].actions
                        targets = list(node.transitions[0].targets)
                    tasks.extend(("anc", x, node.parent) for x in reversed(targets))
                    tasks.extend(("desc", x, None) for x in reversed(targets))
                    continue
                to_enter.add(s)
                if self.compound(s):
                    default_entry.add(s)
                    tasks.extend(("anc", x, s) for x in reversed(node.initial))
                    tasks.extend(("desc", x, None) for x in reversed(node.initial))
                elif node.kind == "parallel":
                    tasks.append(("par", s, 0))
            elif kind == "par":
                kids = [c for c in node.children if self.s[c].kind != "history"]
                index = extra or 0
                if index < len(kids):
                    tasks.append(("par", s, index + 1))
                    child = kids[index]
                    if not any(self.descendant(x, child) or x == child for x in to_enter):
                        tasks.append(("desc", child, None))
            else:  # "anc": ancestors of s below extra
                chain = self.proper_ancestors(s, extra)
                for anc in chain:
                    to_enter.add(anc)
                for anc in reversed(chain):  # innermost parallel popped first (W3C order)
                    if self.s[anc].kind == "parallel":
                        tasks.append(("par", anc, 0))
        for s in sorted(to_enter, key=self.order.__getitem__):
            if s == 0:
                continue
            run.config.add(s)
            node = self.s[s]
            scxml_invoke.on_enter(run, node)
            self.perform(node.onentry, run)
            if s in default_entry:
                self.perform(node.initial_actions, run)
            if s in history_content:
                self.perform(history_content[s], run)
            if node.kind == "final":
                parent = node.parent or 0
                if parent == 0:
                    run.running = False
                    continue
                run.internal.append(f"done.state.{self.s[parent].id}")
                grand = self.s[parent].parent
                if (
                    grand is not None
                    and self.s[grand].kind == "parallel"
                    and all(
                        self.in_final(c, run.config)
                        for c in self.s[grand].children
                        if self.s[c].kind != "history"
                    )
                ):
                    run.internal.append(f"done.state.{self.s[grand].id}")

    # -- macro step -----------------------------------------------------------------------------
    def stabilise(self, run: _Run, valuation: dict[int, bool], read: set[int]) -> None:
        for _ in range(MAX_MICROSTEPS):
            if not run.running:
                return
            enabled = self.select(run, None, valuation, read)
            if not enabled:
                if not run.internal:
                    return
                run.event = run.internal.popleft()
                enabled = self.select(run, run.event, valuation, read)
            if enabled:
                self.microstep(enabled, run)
        raise InputError(
            f"a macro step does not end within {MAX_MICROSTEPS} micro steps "
            "(eventless transitions or raised events form a cycle)"
        )

    def process(
        self, run: _Run, event: str | None, valuation: dict[int, bool], read: set[int]
    ) -> None:
        run.valuation, run.read = valuation, read
        if event is None:
            self.enter(
                [
                    _T(
                        0,
                        (),
                        None,
                        tuple(self.s[0].initial),
                        False,
                        list(self.s[0].initial_actions),
                        None,
                    )
                ],
                run,
            )
        else:
            self.take_external(run, event)
        self.stabilise(run, valuation, read)
        scxml_invoke.start_pending(self, run)
        for _ in range(MAX_MICROSTEPS):
            if not run.external or not run.running:
                scxml_invoke.finish(self, run)
                return
            self.take_external(run, run.external.popleft())
            self.stabilise(run, valuation, read)
            scxml_invoke.start_pending(self, run)
        raise InputError("events the machine sends itself never run out")

    def take_external(self, run: _Run, item: str) -> None:
        """One external event: finalize and autoforward (W3C main loop), then its transitions."""
        event = scxml_invoke.before_external(self, run, item)
        if event is None:
            return
        run.event = event  # _event.name while its transitions run
        enabled = self.select(run, event, run.valuation, run.read)
        if enabled:
            self.microstep(enabled, run)

    # -- naming ---------------------------------------------------------------------------------
    def name(
        self,
        config: frozenset[int],
        history: tuple[tuple[int, frozenset[int]], ...],
        data: tuple[tuple[str, scxml_expr.Value], ...] = (),
    ) -> str:
        """A flat state's name: the configuration, then the history values, then the data
        (``on/cooking#door_closed=true;timer=3``). The configuration part and each shown
        value are computed once (many flat states share them)."""
        text = self.names.get(config)
        if text is None:
            text = self.names[config] = self._config_name(config)
        if history:
            parts = []
            for h, value in history:
                inner = ",".join(self.s[x].name for x in sorted(value, key=self.order.__getitem__))
                parts.append(f"{self.s[h].name}={inner}")
            text += "#" + ";".join(parts)
        if data:
            shown = self.shown
            pieces = []
            for k, v in data:
                key = (k, type(v), v)
                piece = shown.get(key)
                if piece is None:
                    piece = shown[key] = f"{k}={scxml_expr.shown(v)}"
                pieces.append(piece)
            text += ("#" if not history else ";") + ";".join(pieces)
        return text

    def _config_name(self, config: frozenset[int]) -> str:
        out: list[str] = []
        top = [c for c in self.s[0].children if c in config]
        stack: list[int | str] = list(reversed(top))
        while stack:
            item = stack.pop()
            if isinstance(item, str):
                out.append(item)
                continue
            node = self.s[item]
            kids = [c for c in node.children if self.s[c].kind != "history"]
            if node.wrapper:
                stack.extend(k for k in kids if k in config)
                continue
            out.append(node.name)
            if not kids:
                continue
            if node.kind == "parallel" and len(kids) > 1:
                pieces: list[int | str] = ["/["]
                for n, kid in enumerate(kids):
                    pieces.extend(["|", kid] if n else [kid])
                pieces.append("]")
                stack.extend(reversed(pieces))
            else:
                stack.extend([k for k in kids if k in config][:1] + ["/"])
        return "".join(out)

    def action(self, config: frozenset[int]) -> str | None:
        found = self.actions.get(config, _UNKNOWN)
        if found is _UNKNOWN:
            found = self.actions[config] = self._action(config)
        return found  # type: ignore[return-value]

    def _action(self, config: frozenset[int]) -> str | None:
        atoms = sorted(
            (i for i in config if self.atomic(i) and not self.s[i].wrapper),
            key=self.order.__getitem__,
        )
        parts = [self.s[i].action if self.s[i].has_action else self.s[i].name for i in atoms]
        return "+".join(p for p in parts if p) or None


def _symbols(doc: _Doc, interp: _Interpreter) -> list[tuple[str, str, dict[int, bool]]]:
    """(input symbol, event, guard valuation) for every event and guard combination."""
    events: dict[str, None] = {}
    generated: set[str] = set()
    for node in doc.states:
        for t in node.transitions:
            for d in t.events:
                if d != "*" and not d.startswith("done."):
                    events.setdefault(d, None)
            generated.update(_event_names(t.actions))
        generated.update(_event_names([*node.onentry, *node.onexit, *node.initial_actions]))
    forwarded, from_children = scxml_invoke.session_events(doc)
    for name in sorted(forwarded):
        events.setdefault(name, None)
    generated.update(from_children)
    if not events and any("*" in t.events for n in doc.states for t in n.transitions):
        events["event"] = None
    all_t = [t for n in doc.states for t in n.transitions]

    def guards_of(names: list[str], eventless: bool) -> set[int]:
        out: set[int] = set()
        for t in all_t:
            if t.cond is None or t.cond[0] != "guard" or int(t.cond[1]) in doc.plan.computed:
                continue
            hit = (eventless and not t.events) or any(
                _matches(d, e) for d in t.events for e in names
            )
            if hit or (eventless and any(d == "*" or d.startswith("done") for d in t.events)):
                out.add(int(t.cond[1]))
        return out

    internal = guards_of(sorted(generated), True) | doc.branch_guards
    if doc.plan.sends:  # computed event names: any transition's input guard may be read
        internal |= {
            int(t.cond[1])
            for t in all_t
            if t.cond is not None
            and t.cond[0] == "guard"
            and int(t.cond[1]) not in doc.plan.computed
        }
    symbols: list[tuple[str, str, dict[int, bool]]] = []  # sorted below
    for event in events:
        relevant = sorted(guards_of([event], False) | internal)
        if len(relevant) > MAX_GUARDS_PER_EVENT:
            raise UnsupportedError(
                f"unsupported: {len(relevant)} guards read on event "
                f"'{event}' (at most {MAX_GUARDS_PER_EVENT})"
            )
        if not relevant:
            symbols.append((event, event, {}))
            continue
        for values in product((True, False), repeat=len(relevant)):
            label = ",".join(("" if v else "!") + f"g{g + 1}" for g, v in zip(relevant, values))
            symbols.append((f"{event}[{label}]", event, dict(zip(relevant, values))))
    # one canonical order (more dot tokens first, then by name): transitions on ``a.b`` come
    # before those on ``a`` in each state, so the SCXML writer's document order means the same
    # to a W3C engine, and a written file reads back in the same order
    return sorted(symbols, key=lambda item: (-item[1].count("."), item[0]))


def read_scxml_w3c(text: str, ctx: ReadContext) -> FSM:
    """The flat FSM of ``text``'s reachable configurations under the W3C algorithm.

    Args:
        text: An SCXML document.
        ctx: Where it was read (warnings, locations).

    Returns:
        A flat FSM; its events are the input symbols (see module docstring).

    Raises:
        UnsupportedError: A feature without a finite reading, with its line.
        InputError: A malformed document, or more configurations than ``limits.max_states``.
    """
    doc = _Doc(text, ctx)
    interp = _Interpreter(doc)
    symbols = _symbols(doc, interp)
    has_history = any(s.kind == "history" for s in doc.states)
    flat = FSM(name=doc.root_name, attrs=dict(doc.root_attrs))
    for n, guard in enumerate(doc.guards):
        if n in doc.plan.computed:
            continue
        flat.attrs[f"{{{FSMBT_NS}}}guard.g{n + 1}"] = guard
        ctx.warn(f"guard g{n + 1} is an input of the environment: {guard}")
    start = _Run(set(), {}, data=dict(doc.plan.initial))
    read: set[int] = set()
    interp.process(start, None, {}, read)
    if read:
        raise UnsupportedError(
            "unsupported: a cond guard read before the first event "
            f"(g{min(read) + 1}: {doc.guards[min(read)]})"
        )
    bounds = limits.current()
    max_states = bounds.max_states
    if doc.plan.has_data:  # configurations x valuations: an exploration like a conversion's
        max_states = min(max_states, bounds.conversion_max_states)
    Key = tuple[
        frozenset[int],
        tuple[tuple[int, frozenset[int]], ...],
        bool,
        tuple[tuple[str, scxml_expr.Value], ...],
        tuple[object, ...],  # invoked sessions (scxml_invoke.sessions_key)
    ]

    varying = tuple(doc.plan.varying)
    # the varying values of a run, in ``varying``'s order (one C-level call: a converted
    # tree's region can have hundreds of variables, read once per configuration reached)
    values_of = operator.itemgetter(*varying) if len(varying) > 1 else None

    def key_of(run: _Run) -> Key:
        hist = tuple(sorted(run.history.items())) if has_history else ()
        if values_of is not None:
            data = tuple(zip(varying, values_of(run.data), strict=True))
        else:
            data = tuple((n, run.data[n]) for n in varying)
        return (frozenset(run.config), hist, run.running, data, scxml_invoke.sessions_key(run))

    names: dict[Key, str] = {}
    queue: deque[Key] = deque()
    values: dict[str, set[scxml_expr.Value]] = {n: set() for n in doc.plan.varying}

    def visit(key: Key) -> str:
        if key not in names:
            for var, value in key[3]:  # an unbounded variable stops long before max_states
                taken = values[var]
                taken.add(value)
                if len(taken) > bounds.max_data_values:
                    raise scxml_datamodel.StateLimitError(
                        f"the variable '{var}' took more than {bounds.max_data_values} "
                        "distinct values (is it unbounded?) (limit max_data_values; raise it "
                        f"with {limits.env_name('max_data_values')})"
                    )
            if len(names) >= max_states:
                if doc.plan.has_data:
                    raise scxml_datamodel.limit_error(
                        max_states,
                        "conversion_max_states",
                        limits.env_name("conversion_max_states"),
                        (dict(seen[3]) for seen in names),
                    )
                raise InputError(f"more than {max_states} reachable configurations")
            suffix, child_actions = scxml_invoke.describe(doc, key[4])
            name = interp.name(key[0], key[1], key[3]) + suffix
            action = "+".join(a for a in [interp.action(key[0]), *child_actions] if a) or None
            names[key] = name
            flat.add_state(State(name, action=action, final=not key[2]))
            queue.append(key)
        return names[key]

    flat.initial = visit(key_of(start))
    while queue:
        key = queue.popleft()
        if not key[2]:
            continue
        source = names[key]
        for symbol, event, valuation in symbols:
            run = _Run(set(key[0]), dict(key[1]), data={**doc.plan.initial, **dict(key[3])})
            scxml_invoke.restore(doc, run, key[4])
            interp.process(run, event, valuation, set())
            if run.moved:
                flat.add_transition(source, symbol, visit(key_of(run)))
    return flat


def representative_event(event: str, events: list[str]) -> str | None:
    """The model's event an arbitrary SCXML event behaves like.

    The descriptors matching an event are the token prefixes of it (W3C 5.9.3), so an event
    matches exactly the descriptors its longest matching descriptor token matches: the model's
    events (the descriptor tokens) stand for every event name.

    Args:
        event: Any event name (``foo.bar.bat.bif``).
        events: The model's events (without guard suffixes).

    Returns:
        The longest event of ``events`` that is ``event`` or a token prefix of it, or ``None``.
    """
    best = None
    for candidate in events:
        if (
            _matches(candidate, event)
            and candidate != "*"
            and (best is None or len(candidate) > len(best))
        ):
            best = candidate
    return best
