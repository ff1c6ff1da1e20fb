"""``<invoke>`` of SCXML sessions in the W3C reader (docs/formats/scxml.md, "XInclude and
<invoke>"): a child session's configuration is part of each explored state.

What is read: ``<invoke>`` of type SCXML (no ``type``, ``scxml``,
``http://www.w3.org/TR/scxml/``, its ``#SCXMLEventProcessor`` form) whose document is inline
(``<content><scxml>...</scxml></content>``) or a file (``src="child.scxml"``, resolved and
confined like an XInclude, ``fsmbt.formats.scxml.include``). Other types (``vxml2``, http,
...) are external services: ``UnsupportedError`` with the line. Rules (W3C SCXML 1.0, 6.4 and
appendix D):

- A state's invocations start at the end of the macro step that entered it, in entry order,
  only if the state is still active then; exiting the state cancels them (the child's further
  events are ignored, no ``done.invoke``).
- The invoke id is ``id``, else ``<state id>.<n>`` (n-th ``<invoke>`` of that state).
- ``<send target="#_<invokeid>">`` gives the event to that child; ``<send target="#_parent">``
  in a child puts it on the parent's external queue (tagged with the invoke id); an
  unreachable target (not started, finished, cancelled, no parent) raises
  ``error.communication`` on the sender's internal queue.
- With ``autoforward="true"`` every external event the parent takes off its queue is given to
  the child first (the W3C algorithm forwards all of them, the child's own included).
- ``<finalize>`` runs in the parent before an event from that child is processed; only content
  that neither raises nor sends (``<log>``, ignored assignments) - else unsupported.
- A child that reaches a top-level final state runs its ``onexit`` handlers (W3C
  ``exitInterpreter``; ``#_parent`` sends still go out) and the parent then gets
  ``done.invoke.<invokeid>``.

Scheduling (the W3C leaves the timing of separate sessions open; fsmbt fixes one order, so the
reading is deterministic): an event given to a child is processed by the child at once, to
its own stability, before the sender goes on; the environment waits for every session to be
idle. Refused: ``typeexpr``, ``srcexpr``, ``idlocation``, ``<content expr>``, ``cond`` guards
other than ``In()`` in an invoked document, data passed (``<param>``, ``namelist``) to a child
whose data is read exactly (``data=exact``; otherwise the child's data model is ignored, so is
the data). Nested invocations chain at most ``limits.max_include_depth`` documents (and never more than
``MAX_SESSION_DEPTH``), and a file
that invokes itself (directly or not) is an error: the nesting is bounded, so the recursion
over sessions below is too. The ``src`` files read for one document (each ``<invoke>``
counted) stay within ``limits.max_input_bytes`` in all.

Costs: a child multiplies the reachable configurations by its own (bounded by
``limits.max_states`` for the whole product); delivering one event costs a macro step of
the receiving session.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

from lxml import etree

from fsmbt import limits
from fsmbt.formats.registry import ReadContext
from fsmbt.formats.scxml import include as scxml_include
from fsmbt.formats.xml_safe import local_name, namespace
from fsmbt.model.errors import InputError, UnsupportedError

SCXML_TYPES = frozenset(
    {
        "scxml",
        "http://www.w3.org/TR/scxml/",
        "http://www.w3.org/TR/scxml",
        "http://www.w3.org/TR/scxml/#SCXMLEventProcessor",
    }
)
#: What a child puts in its outbox when it ends (the parent turns it into done.invoke.<id>).
DONE = "\x00done"
#: Sessions nest at most this deep whatever ``max_include_depth`` says: running them recurses
#: once per level (a few frames each), far below Python's recursion limit.
MAX_SESSION_DEPTH = 48
_TAG = "\x00"  # parent-queue entries from a child: "\x00<invokeid>\x00<serial>\x00<event>"


@dataclass(frozen=True)
class Session:
    """How a document is read: invoked or not, and the chain of invoked files above it."""

    invoked: bool = False
    chain: tuple[Path, ...] = ()
    depth: int = 0
    #: characters of ``src`` files read so far in this read, shared by all sessions (a file
    #: invoking another twice, which invokes another twice... must not blow up)
    read_chars: list[int] = field(default_factory=lambda: [0])
    #: what XInclude brought into the document an inline child is part of (its base files)
    included: scxml_include.Included | None = None


@dataclass
class Invocation:
    """One ``<invoke>`` element, read: its child document and interpreter."""

    state: int
    invokeid: str
    doc: Document
    interp: Interpreter
    autoforward: bool
    finalize: list[Any]
    line: int | None


@dataclass
class Child:
    """A running child session of one run."""

    invocation: Invocation
    run: Run
    serial: int


# -- what this module reads of the W3C reader's objects (fsmbt.formats.scxml.w3c) ----------------
# The reader imports this module, never the other way round: these protocols name what the
# sessions use of a document, a state, an interpreter and a run.
class StateNode(Protocol):
    """A state of a document being read."""

    @property
    def index(self) -> int: ...
    @property
    def id(self) -> str: ...
    @property
    def kind(self) -> str: ...
    @property
    def invokes(self) -> list[Invocation]: ...
    @property
    def onentry(self) -> Sequence[Any]: ...
    @property
    def onexit(self) -> Sequence[Any]: ...
    @property
    def initial_actions(self) -> Sequence[Any]: ...
    @property
    def transitions(self) -> Sequence[Any]: ...


class Document(Protocol):
    """A document read by the W3C reader (the parent of an invocation, or a child)."""

    @property
    def ctx(self) -> ReadContext: ...
    @property
    def ns(self) -> str | None: ...
    @property
    def session(self) -> Session: ...
    @property
    def included(self) -> scxml_include.Included: ...
    @property
    def invocations(self) -> dict[str, Invocation]: ...
    @property
    def session_targets(self) -> list[tuple[str, int | None]]: ...
    @property
    def guards(self) -> list[str]: ...
    @property
    def plan(self) -> Any: ...
    @property
    def states(self) -> Sequence[StateNode]: ...
    def tag(self, element: etree._Element) -> str | None: ...
    def refuse(self, element: etree._Element, feature: str) -> UnsupportedError: ...
    def actions(self, block: etree._Element | list[etree._Element]) -> list[Any]: ...


class Run(Protocol):
    """One session's run state (mutable)."""

    config: set[int]
    history: dict[int, frozenset[int]]
    internal: deque[str]
    external: deque[str]
    running: bool
    moved: bool
    data: dict[str, Any]
    sessions: dict[str, Child]
    to_invoke: list[int]
    outbox: list[str]
    serial: int

    def spawn(
        self,
        config: set[int],
        history: dict[int, frozenset[int]],
        data: dict[str, Any],
    ) -> Run:
        """A fresh run of the same kind (for a child session)."""
        ...


class Interpreter(Protocol):
    """The W3C algorithm over one document."""

    @property
    def doc(self) -> Document: ...
    @property
    def s(self) -> Sequence[StateNode]: ...
    @property
    def order(self) -> dict[int, int]: ...
    def process(
        self, run: Any, event: str | None, valuation: dict[int, bool], read: set[int]
    ) -> Any: ...
    def perform(self, actions: Sequence[Any], run: Any) -> None: ...
    def name(self, config: frozenset[int], history: Any, data: Any) -> str: ...
    def action(self, config: frozenset[int]) -> str | None: ...


# -- reading -------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ChildSource:
    """What the child document of one ``<invoke>`` is read from, checked (``read_invoke``).

    The W3C reader reads ``text`` (or the inline ``element``) with ``ctx`` as a document of
    ``session``, then hands it to ``add_invocation``.
    """

    text: str
    ctx: ReadContext
    element: etree._Element | None
    session: Session
    autoforward: bool
    finalize: etree._Element | None
    data_passed: bool


def read_invoke(doc: Document, element: etree._Element, node: StateNode) -> ChildSource:
    """Check an ``<invoke>`` element of state ``node`` and find its child document.

    Args:
        doc: The document being read (the parent).
        element: The ``<invoke>`` element.
        node: The state holding it.

    Returns:
        Where the child document is (its text or inline element) and how it is invoked.

    Raises:
        UnsupportedError: an external service, computed attributes, guards in the child.
        InputError: a malformed ``<invoke>`` or child document, limits, cycles.
    """
    ctx = doc.ctx
    where = ctx.location(element.sourceline)
    if node.kind not in ("state", "parallel"):
        raise InputError(
            f"<invoke> in <{node.kind}> (only <state> and <parallel> invoke)",
            location=where,
            element="<invoke>",
        )
    for attribute in ("typeexpr", "srcexpr", "idlocation"):
        if element.get(attribute) is not None:
            raise doc.refuse(element, f"unsupported: <invoke {attribute}=...> (computed)")
    kind = element.get("type")
    src = element.get("src")
    if kind is not None and kind.strip() not in SCXML_TYPES:
        raise doc.refuse(element, f"unsupported: <invoke> (external services) of type '{kind}'")
    if src is not None and _is_url(src):
        raise doc.refuse(element, f"unsupported: <invoke> (external services) at '{src}'")
    autoforward = element.get("autoforward", "false")
    if autoforward not in ("true", "false"):
        raise InputError(
            f'<invoke autoforward="{autoforward}"> (true or false)',
            location=where,
            element="<invoke>",
        )
    depth = limits.current().max_include_depth
    if doc.session.depth + 1 > min(depth, MAX_SESSION_DEPTH):
        raise InputError(
            limits.exceeded(
                f"{doc.session.depth + 1} nested <invoke> documents", "max_include_depth", depth
            )
            if depth <= MAX_SESSION_DEPTH
            else f"{doc.session.depth + 1} nested <invoke> documents exceed fsmbt's bound of "
            f"{MAX_SESSION_DEPTH} nested sessions",
            location=where,
            element="<invoke>",
        )
    contents, finalizes, data_passed = [], [], element.get("namelist") is not None
    for child in element:
        if not isinstance(child.tag, str):
            continue
        tag = doc.tag(child)
        if tag == "content":
            contents.append(child)
        elif tag == "finalize":
            finalizes.append(child)
        elif tag == "param":
            data_passed = True
        elif tag is not None:
            raise InputError(
                f"unknown element <{tag}> in <invoke>",
                location=ctx.location(child.sourceline),
                element=f"<{tag}>",
            )
    if (src is not None) + len(contents) != 1 or len(finalizes) > 1:
        raise InputError(
            "<invoke> needs exactly one of src and <content>, and at most one <finalize>",
            location=where,
            element="<invoke>",
        )
    text, child_ctx, inline, session = _child_document(doc, element, src, contents)
    return ChildSource(
        text,
        child_ctx,
        inline,
        session,
        autoforward == "true",
        finalizes[0] if finalizes else None,
        data_passed,
    )


def add_invocation(
    doc: Document,
    element: etree._Element,
    node: StateNode,
    source: ChildSource,
    child_doc: Document,
    child_interp: Interpreter,
) -> Invocation:
    """Record the invocation of ``child_doc`` (read from ``source``) by state ``node``.

    Returns:
        The invocation; it is also recorded in ``doc.invocations`` and ``node.invokes``.

    Raises:
        UnsupportedError: guards in the child, data passed to an exactly read session, a
            ``<finalize>`` that raises or sends.
        InputError: a duplicate invoke id.
    """
    ctx = doc.ctx
    where = ctx.location(element.sourceline)
    if child_doc.guards:
        raise doc.refuse(
            element,
            "unsupported: a cond guard in an invoked document "
            f"('{child_doc.guards[0]}'; only In() is read there)",
        )
    if source.data_passed:
        if child_doc.plan.relevant:  # control flow there reads its data
            raise doc.refuse(
                element, "unsupported: <param>/namelist passing data to an exactly read session"
            )
        ctx.warn(
            "<param>/namelist ignored (the invoked document's data model is not read)",
            line=element.sourceline,
            element="<invoke>",
        )
    finalize = doc.actions(source.finalize) if source.finalize is not None else []
    if sent_names(finalize, ("raise", "internal", "external", "parent", "session:")):
        assert source.finalize is not None
        raise doc.refuse(
            source.finalize, "unsupported: <finalize> that raises or sends events (in the parent)"
        )
    invokeid = element.get("id") or f"{node.id}.{len(node.invokes) + 1}"
    if invokeid in doc.invocations:
        raise InputError(f"duplicate <invoke> id '{invokeid}'", location=where, element="<invoke>")
    invocation = Invocation(
        node.index,
        invokeid,
        child_doc,
        child_interp,
        source.autoforward,
        finalize,
        element.sourceline,
    )
    doc.invocations[invokeid] = invocation
    node.invokes.append(invocation)
    return invocation


def _is_url(src: str) -> bool:
    scheme, sep, _rest = src.partition(":")
    return bool(sep) and len(scheme) > 1 and scheme != "file" and "/" not in scheme


def _child_document(
    doc: Document,
    element: etree._Element,
    src: str | None,
    contents: list[etree._Element],
) -> tuple[str, ReadContext, etree._Element | None, Session]:
    """(text, context, inline element, session) of the child document."""
    ctx = doc.ctx
    where = ctx.location(element.sourceline)
    if src is None:
        content = contents[0]
        if content.get("expr") is not None:
            raise doc.refuse(content, "unsupported: <content expr=...> (computed)")
        documents = [c for c in content if isinstance(c.tag, str)]
        if (
            len(documents) != 1
            or local_name(documents[0]) != "scxml"
            or namespace(documents[0]) != doc.ns
        ):
            raise InputError(
                "<content> of <invoke> must hold one <scxml> document",
                location=ctx.location(content.sourceline),
                element="<content>",
            )
        session = Session(
            True, doc.session.chain, doc.session.depth + 1, doc.session.read_chars, doc.included
        )
        return "", ctx, documents[0], session
    # relative to the file the <invoke> is written in: an included fragment's, else the document's
    base = doc.included.base_of(element) or (Path(ctx.path) if ctx.path is not None else None)
    resolved = scxml_include.resolve_confined(ctx, base, src, "<invoke src>", where, "<invoke>")
    chain = doc.session.chain or ((Path(ctx.path).resolve(),) if ctx.path is not None else ())
    scxml_include.check_chain(chain, resolved, "<invoke src>", where)
    text = scxml_include.read_confined(resolved, src, "invoked file", where, "<invoke>")
    doc.session.read_chars[0] += len(text)
    budget = limits.current().max_input_bytes
    if doc.session.read_chars[0] > budget:
        raise InputError(
            limits.exceeded(
                f"the invoked files ({doc.session.read_chars[0]}+ characters, each <invoke> "
                "counted)",
                "max_input_bytes",
                budget,
            ),
            location=where,
            element="<invoke>",
        )
    options = dict(ctx.options)
    options["include_root"] = str(scxml_include.confinement_root(ctx))
    child_ctx = ReadContext(resolved, options, ctx.warnings)
    session = Session(True, (*chain, resolved), doc.session.depth + 1, doc.session.read_chars)
    return text, child_ctx, None, session


def send_target(doc: Document, target: str, name: str, line: int | None) -> tuple[str, str] | None:
    """The action of ``<send target=...>`` to another session of this system: ``#_parent`` or
    ``#_<invokeid>`` (checked once the document is read, ``check_targets``); ``None`` for
    another target."""
    if target == "#_parent":
        return ("parent", name)
    if target.startswith("#_") and not target.startswith("#_scxml_") and len(target) > 2:
        doc.session_targets.append((target[2:], line))
        return (f"session:{target[2:]}", name)
    return None


def check_targets(doc: Document) -> None:
    """Every ``#_<id>`` target names an ``<invoke>`` of the document (another session could
    be meant otherwise: refused as the reader refuses sends to other sessions)."""
    for invokeid, line in doc.session_targets:
        if invokeid not in doc.invocations:
            raise UnsupportedError(
                f"unsupported: <send> to target '#_{invokeid}' (another session: no <invoke> "
                f"of this document has that id), line {line}",
                location=doc.ctx.location(line),
                element="<send>",
            )


def sent_names(actions: list[Any], kinds: tuple[str, ...]) -> list[str]:
    """Names of the events ``actions`` may raise or send with a kind starting with one of
    ``kinds`` (every ``<if>`` branch)."""
    out: list[str] = []
    stack = list(actions)
    while stack:
        action = stack.pop()
        if hasattr(action, "branches"):
            for _guard, inner in action.branches:
                stack.extend(inner)
        elif any(action[0].startswith(kind) for kind in kinds):
            out.append(action[1])
    return out


def session_events(doc: Document) -> tuple[set[str], set[str]]:
    """(events the environment may send that an autoforwarded child reads, events children may
    send to ``doc``'s session) - for the input symbols of ``doc``."""
    forwarded: set[str] = set()
    from_children: set[str] = set()
    stack = [(inv, True, True) for inv in doc.invocations.values()]
    while stack:
        inv, reaches, direct = stack.pop()
        child = inv.doc
        reaches = reaches and inv.autoforward
        for node in child.states:
            actions = [*node.onentry, *node.onexit, *node.initial_actions]
            for t in node.transitions:
                actions.extend(t.actions)
                if reaches:
                    forwarded.update(d for d in t.events if d != "*" and not d.startswith("done."))
            if direct:
                from_children.update(sent_names(actions, ("parent",)))
        stack.extend((grand, reaches, False) for grand in child.invocations.values())
    return forwarded, from_children


# -- running -------------------------------------------------------------------------------------
def on_enter(run: Run, node: StateNode) -> None:
    """W3C ``enterStates``: a state with invocations is to be invoked."""
    if node.invokes:
        run.to_invoke.append(node.index)


def on_exit(run: Run, node: StateNode) -> None:
    """W3C ``exitStates``: not invoked if still pending; its sessions are cancelled."""
    if node.index in run.to_invoke:
        run.to_invoke.remove(node.index)
    for inv in node.invokes:
        run.sessions.pop(inv.invokeid, None)


def start_pending(interp: Interpreter, run: Run) -> None:
    """End of a macro step: start the invocations of the states entered in it, in entry order."""
    pending, run.to_invoke = run.to_invoke, []
    if not run.running:
        return
    for index in pending:
        for inv in interp.s[index].invokes:
            child_run = run.spawn(set(), {}, dict(inv.doc.plan.initial))
            run.serial += 1
            child = Child(inv, child_run, run.serial)
            run.sessions[inv.invokeid] = child
            inv.interp.process(child_run, None, {}, set())
            run.moved = True
            _flush(run, child)


def route(run: Run, invoked: bool, kind: str, name: str) -> None:
    """``<send>`` to ``#_parent`` or ``#_<invokeid>`` (``error.communication`` if unreachable)."""
    if kind == "parent":
        if invoked:
            run.outbox.append(name)
        else:
            run.internal.append("error.communication")
        return
    child = run.sessions.get(kind[len("session:") :])
    if child is None or not child.run.running:
        run.internal.append("error.communication")
        return
    _deliver(run, child, name)


def before_external(interp: Interpreter, run: Run, item: str) -> str | None:
    """W3C main loop, an external event taken off the queue: ``<finalize>`` of the child it
    came from, then a copy to each autoforwarding child. ``None``: an event of a cancelled
    session, ignored."""
    event = item
    if item.startswith(_TAG):
        _empty, invokeid, serial, event = item.split(_TAG, 3)
        child = run.sessions.get(invokeid)
        if child is None or str(child.serial) != serial:
            return None
        interp.perform(child.invocation.finalize, run)
    for child in list(run.sessions.values()):
        if child.invocation.autoforward and child.run.running:
            _deliver(run, child, event)
    return event


def finish(interp: Interpreter, run: Run) -> None:
    """W3C ``exitInterpreter`` of an invoked session that reached a top-level final state:
    ``onexit`` in exit order (their ``#_parent`` sends go out), its own sessions cancelled,
    then ``done.invoke`` for the parent. The configuration is dropped (a finished child is one
    state). A top-level document that ends just cancels its sessions (nothing it does after
    is observable)."""
    if run.running:
        return
    if not interp.doc.session.invoked:
        run.sessions.clear()
        return
    if not run.config:
        return
    for s in sorted(run.config, key=interp.order.__getitem__, reverse=True):
        interp.perform(interp.s[s].onexit, run)
        on_exit(run, interp.s[s])
    run.config.clear()
    run.history.clear()
    run.data.clear()
    run.sessions.clear()
    run.outbox.append(DONE)


def _deliver(run: Run, child: Child, event: str) -> None:
    child.run.moved = False
    child.invocation.interp.process(child.run, event, {}, set())
    if child.run.moved:
        run.moved = True
    _flush(run, child)


def _flush(run: Run, child: Child) -> None:
    """The child's events for its parent, onto the parent's external queue (tagged)."""
    invokeid = child.invocation.invokeid
    for event in child.run.outbox:
        name = f"done.invoke.{invokeid}" if event == DONE else event
        run.external.append(f"{_TAG}{invokeid}{_TAG}{child.serial}{_TAG}{name}")
    child.run.outbox.clear()


# -- the explored state --------------------------------------------------------------------------
def sessions_key(run: Run) -> tuple[Any, ...]:
    """The running children of ``run`` (start order), each with its configuration, history,
    status, data and own children: part of the explored state."""
    out = []
    for invokeid, child in run.sessions.items():
        crun = child.run
        out.append(
            (
                invokeid,
                (
                    frozenset(crun.config),
                    tuple(sorted(crun.history.items())),
                    crun.running,
                    tuple(sorted(crun.data.items())),
                    sessions_key(crun),
                ),
            )
        )
    return tuple(out)


def restore(doc: Document, run: Run, key: tuple[Any, ...]) -> None:
    """Rebuild ``run``'s children (``doc``'s sessions) from ``sessions_key`` output."""
    for invokeid, (config, history, running, data, inner) in key:
        inv = doc.invocations[invokeid]
        crun = run.spawn(set(config), dict(history), dict(data))
        crun.running = running
        restore(inv.doc, crun, inner)
        run.serial += 1
        run.sessions[invokeid] = Child(inv, crun, run.serial)


def describe(doc: Document, key: tuple[Any, ...]) -> tuple[str, list[str]]:
    """The name suffix ``{id=child configuration}`` of the children in ``key`` and their
    actions (``(done)`` for a finished child)."""
    parts: list[str] = []
    actions: list[str] = []
    for invokeid, (config, history, running, data, inner) in key:
        inv = doc.invocations[invokeid]
        if not running:
            parts.append(f"{{{invokeid}=(done)}}")
            continue
        inner_name, inner_actions = describe(inv.doc, inner)
        name = inv.interp.name(config, history, data)
        parts.append(f"{{{invokeid}={name}{inner_name}}}")
        action = inv.interp.action(config)
        if action:
            actions.append(action)
        actions.extend(inner_actions)
    return "".join(parts), actions
