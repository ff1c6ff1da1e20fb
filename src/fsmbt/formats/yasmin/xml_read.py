"""YASMIN factory XML -> container records (docs/formats/yasmin.md).

``yasmin_factory`` (YASMIN 6.x) builds a state machine from XML; this module reads the same
elements into the container records the SMACH reader builds (``pysm.analyze``), so that one
construction (``pysm.build``) makes the FSM. What the factory does, and so what is read:

- ``<StateMachine outcomes start_state>`` and ``<Region>`` (inside ``<OrthogonalState>``): a
  machine; its states are the ``State``, ``StateMachine``, ``Concurrence``, ``OrthogonalState``
  and ``JoinState`` children in document order; the start state is ``start_state`` or the first
  state added (``StateMachine::add_state``).
- ``<State class type module>``: a leaf (``type`` ``py`` - the default - or ``cpp``); its
  ``<Transition from to>`` children map its outcomes. The file does not list a state's outcomes:
  the ones its transitions name are kept, and an outcome left unmapped falls through to the
  container outcome of the same name (``StateMachine::execute_step``).
- ``<StateMachine file_path=...>`` or ``<StateMachine package file_name>`` (a ``<Region>`` too):
  the machine of another file. ``file_path`` is resolved relative to the including file and must stay in its folder (the
  factory refuses a path that leaves it); ``package`` is looked up as the factory does (the
  package's share folder, under ``AMENT_PREFIX_PATH``), then in an enclosing source folder of
  that name holding a ``package.xml``, then beside the including file (a warning names the file
  taken); when none has ``file_name`` the error says the package cannot be resolved.
- ``<Concurrence default_outcome>`` with ``<OutcomeMap outcome><Item state outcome/>``: its
  outcomes are the map's keys and the default (``generate_possible_outcomes``); every child runs
  to its end, then the map decides (no entry satisfied: the default; several: YASMIN raises, a
  warning here). ``<OrthogonalState>`` is the same over its ``<Region>`` machines, and its
  ``<JoinState sync_id>`` states (directly in a region) are barriers: every region with a join
  of that ``sync_id`` waits there until all have arrived (``RegionBarrier``).
- ``Param`` (with ``default_value``), ``Key``, ``Remap`` and ``ParamRemap`` are annotations
  (``model.state_info``: parameters, userdata keys, remapping); ``x``/``y`` and ``description``
  are kept as ``yasmin.*`` attributes; ``fsmbt_action`` on a ``FinalOutcome`` (written by fsmbt,
  ignored by YASMIN) is the action of that final state; ``<Text>`` blocks (editor notes) and the editor's
  ``<Transition>`` under a ``<FinalOutcome>`` or the root, which the factory ignores, are
  ignored. Any other element is an ``InputError`` at its line, as is a missing required
  attribute.

Everything is read with an explicit work list (no recursion on the document); included files
go through ``read_located`` (bounded) and ``parse_xml`` (no entities, bounded depth).
Costs: O(size of the files read).
"""

from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from fsmbt.formats.pysm.analyze import Child, Container, StateRef
from fsmbt.formats.registry import ReadContext, decode
from fsmbt.formats.xml_safe import local_name, parse_xml
from fsmbt.model import state_info
from fsmbt.model.errors import InputError, SourceLocation
from fsmbt.model.files import note_read, read_located

#: Elements a state may be (``create_sm`` / ``create_concurrence``).
STATE_TAGS = frozenset({"State", "StateMachine", "Concurrence", "OrthogonalState", "JoinState"})
#: Annotation elements of a state or container.
DATA_TAGS = frozenset({"Param", "Key", "Remap", "ParamRemap", "Default"})
#: Elements allowed directly in each kind of element.
ALLOWED: dict[str, frozenset[str]] = {
    "StateMachine": STATE_TAGS | DATA_TAGS | {"FinalOutcome", "Transition", "Text"},
    "Region": STATE_TAGS | DATA_TAGS | {"FinalOutcome", "Transition", "Text"},
    "Concurrence": STATE_TAGS | DATA_TAGS | {"FinalOutcome", "OutcomeMap", "Transition", "Text"},
    "OrthogonalState": DATA_TAGS | {"Region", "FinalOutcome", "OutcomeMap", "Transition", "Text"},
    "State": DATA_TAGS | {"Transition"},
    "JoinState": DATA_TAGS | {"Transition"},
    "FinalOutcome": frozenset({"Transition"}),
    "Item": frozenset(),
    "OutcomeMap": frozenset({"Item"}),
}
#: A ROS package name (REP 144, with upper case and dashes as older packages have them).
_PACKAGE_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_-]*")
#: The deepest chain of included files followed.
MAX_INCLUDE_DEPTH = 32
#: Files looked at while searching a package folder for an included file.
MAX_PACKAGE_FILES = 20_000
#: ``State.attrs`` keys of YASMIN-only facts (the writer reads them back).
A_TYPE = "yasmin.type"
A_MODULE = "yasmin.module"
A_TAG = "yasmin.tag"
A_POSITION = "yasmin.position"
A_DESCRIPTION = "yasmin.description"
A_PARAM_DECLS = "yasmin.params"
A_PARAM_REMAP = "yasmin.param_remap"
A_KEYS = "yasmin.keys"
A_INCLUDE = "yasmin.include"
A_SYNC = "yasmin.sync_id"
A_CHILD_INFO = "yasmin.children"
#: The class fsmbt writes for a state that runs no action (read back as no action).
NO_ACTION_CLASS = "fsmbt_states/NoAction"
#: The class fsmbt writes for a start pseudo-state left on its initial event (read back as one).
START_CLASS = "fsmbt_states/Start"
#: The ``FinalOutcome`` attribute fsmbt writes for the action of a final state (YASMIN runs no
#: action on an outcome and ignores the attribute; fsmbt reads it back).
A_FINAL_ACTION = "fsmbt_action"


@dataclass
class Records:
    """What one YASMIN XML file (with its includes) holds."""

    root: Container
    name: str
    #: id(Child) -> the attrs of the state it becomes (state_info and ``yasmin.*``)
    info: dict[int, dict[str, str]] = field(default_factory=dict)
    #: the root machine's own annotations
    root_info: dict[str, str] = field(default_factory=dict)
    #: id(Container) -> {outcome: action} that fsmbt wrote on a ``FinalOutcome``
    final_actions: dict[int, dict[str, str]] = field(default_factory=dict)
    warnings: list[tuple[int | None, str]] = field(default_factory=list)


@dataclass
class _File:
    path: Path | None
    name: str
    chain: tuple[str, ...]


@dataclass
class _Job:
    element: etree._Element
    container: Container
    source: _File


class XmlReader:
    """Reads one YASMIN XML document (and the files it includes) into records."""

    def __init__(self, ctx: ReadContext) -> None:
        self.ctx = ctx
        self.info: dict[int, dict[str, str]] = {}
        self.final_actions: dict[int, dict[str, str]] = {}

    # -- errors ---------------------------------------------------------------------------------
    def where(self, source: _File, element: etree._Element | None) -> SourceLocation:
        line = element.sourceline if element is not None else None
        return SourceLocation(source.name, line)

    def error(self, source: _File, element: etree._Element | None, message: str) -> InputError:
        return InputError(message, location=self.where(source, element))

    def confinement_root(self) -> Path:
        """The folder an absolute ``file_path`` must lie in: the reader option
        ``include_root``, else the folder of the file read (docs/security.md, rule 4)."""
        option = self.ctx.options.get("include_root")
        if option:
            return Path(str(option)).resolve()
        assert self.ctx.path is not None  # ``included`` refuses includes of a text
        return self.ctx.path.resolve().parent

    def warn(self, source: _File, element: etree._Element | None, message: str) -> None:
        self.ctx.warnings.append(f"{self.where(source, element)}: {message}")

    def attr(self, source: _File, element: etree._Element, name: str) -> str:
        value = element.get(name)
        if value is None or not value.strip():
            raise self.error(source, element, f"<{local_name(element)}> needs a '{name}' attribute")
        return value.strip()

    # -- entry ----------------------------------------------------------------------------------
    def read(self, text: str) -> Records:
        path = self.ctx.path.resolve() if self.ctx.path is not None else None
        source = _File(path, self.ctx.display_name, (str(path),) if path else ())
        root = parse_xml(text, self.ctx.display_name)
        if local_name(root) != "StateMachine":
            raise self.error(
                source, root, f"the root element is <{local_name(root)}>, not <StateMachine>"
            )
        self.check_children(source, root)
        container = self.machine_record(source, root, root.get("name") or "StateMachine")
        self.fill(_Job(root, container, source))
        records = Records(container, root.get("name") or "StateMachine", self.info)
        records.final_actions = self.final_actions
        records.root_info = self.annotations(source, root, "StateMachine")
        return records

    def fill(self, first: _Job) -> None:
        """Fill every container's children, with an explicit work list."""
        jobs = [first]
        while jobs:
            job = jobs.pop()
            tag = local_name(job.element)
            if tag == "OrthogonalState":
                jobs.extend(self.orthogonal(job))
            elif tag == "Concurrence":
                jobs.extend(self.concurrence(job))
            else:
                jobs.extend(self.machine(job))

    # -- structure checks -----------------------------------------------------------------------
    def check_children(self, source: _File, element: etree._Element) -> None:
        """Every element under ``element`` is one YASMIN knows where it is (explicit stack)."""
        stack = [element]
        while stack:
            parent = stack.pop()
            tag = local_name(parent)
            allowed = ALLOWED.get(tag, frozenset())
            for child in parent:
                if not isinstance(child.tag, str):
                    continue
                name = local_name(child)
                if name not in allowed:
                    inside = f"inside <{tag}>"
                    raise self.error(
                        source,
                        child,
                        f"unknown YASMIN element <{name}> {inside} (yasmin_factory reads "
                        f"{', '.join(sorted(allowed)) or 'nothing'} there)",
                    )
                stack.append(child)

    # -- records --------------------------------------------------------------------------------
    def machine_record(self, source: _File, element: etree._Element, name: str) -> Container:
        outcomes = list(dict.fromkeys((element.get("outcomes") or "").split()))
        finals = [self.attr(source, f, "name") for f in element if _is(f, "FinalOutcome")]
        for outcome in finals:
            if outcome not in outcomes:
                raise self.error(
                    source,
                    element,
                    f'<FinalOutcome name="{outcome}"> is not one of the outcomes of '
                    f"'{name}' ({' '.join(outcomes) or 'none'}); yasmin_factory refuses it",
                )
        if not outcomes:
            raise self.error(source, element, f"state machine '{name}' declares no outcomes")
        actions = {
            f.get("name", ""): f.get(A_FINAL_ACTION, "")
            for f in element
            if _is(f, "FinalOutcome") and f.get(A_FINAL_ACTION)
        }
        container = Container(
            cls="StateMachine", kind="sm", outcomes=outcomes, line=element.sourceline or 0
        )
        container.var = name
        if actions:
            self.final_actions[id(container)] = actions
        start = element.get("start_state")
        if start:
            container.initial = start
            container.initial_line = element.sourceline
        return container

    def child_of(
        self, source: _File, element: etree._Element, state: StateRef | Container
    ) -> Child:
        name = self.attr(source, element, "name")
        transitions: dict[str, str | None] = {}
        for t in element:
            if _is(t, "Transition"):
                outcome = self.attr(source, t, "from")
                if outcome in transitions:
                    raise self.error(source, t, f"state '{name}' maps outcome '{outcome}' twice")
                transitions[outcome] = self.attr(source, t, "to")
        return Child(name, state, transitions, element.sourceline or 0)

    def state_children(
        self, job: _Job, allowed_joins: bool = True
    ) -> tuple[list[Child], list[_Job]]:
        """The states of a machine or concurrence element, and the containers to fill."""
        children: list[Child] = []
        pending: list[_Job] = []
        seen: dict[str, etree._Element] = {}
        for element in job.element:
            if not isinstance(element.tag, str):
                continue
            tag = local_name(element)
            if tag not in STATE_TAGS:
                continue
            name = self.attr(job.source, element, "name")
            if name in seen:
                raise self.error(
                    job.source,
                    element,
                    f"state '{name}' is already registered in this machine (line "
                    f"{seen[name].sourceline}); YASMIN refuses a second one",
                )
            seen[name] = element
            info = self.annotations(job.source, element, tag)
            if tag == "State":
                cls = self.attr(job.source, element, "class")
                kind = element.get("type", "py")
                if kind not in ("py", "cpp"):
                    raise self.error(
                        job.source,
                        element,
                        f"state '{name}' has type '{kind}'; yasmin_factory knows 'py' and 'cpp'",
                    )
                if kind == "py":
                    info[A_MODULE] = self.attr(job.source, element, "module")
                info[A_TYPE] = kind
                info[state_info.CLASS] = cls
                child = self.child_of(
                    job.source, element, StateRef(cls, None, element.sourceline or 0)
                )
                mapped = list(child.transitions)
                if mapped:
                    info[state_info.OUTCOMES] = json.dumps(mapped)
            elif tag == "JoinState":
                outcome = element.get("outcome") or "joined"
                info[state_info.CLASS] = "JoinState"
                info[state_info.OUTCOMES] = json.dumps([outcome])
                info[A_SYNC] = element.get("sync_id", "")
                ref = StateRef("JoinState", [outcome], element.sourceline or 0)
                child = self.child_of(job.source, element, ref)
            elif tag == "StateMachine":
                target, sub_source, root = self.included(job.source, element)
                if root is not None and target is not None:
                    info[A_INCLUDE] = json.dumps(
                        {
                            k: element.get(k)
                            for k in ("file_path", "package", "file_name")
                            if element.get(k)
                        }
                    )
                    container = self.machine_record(sub_source, root, name)
                    child = self.child_of(job.source, element, container)
                    pending.append(_Job(root, container, sub_source))
                else:
                    container = self.machine_record(job.source, element, name)
                    child = self.child_of(job.source, element, container)
                    pending.append(_Job(element, container, job.source))
                info[state_info.CLASS] = "StateMachine"
                info[state_info.OUTCOMES] = json.dumps(container.outcomes)
            elif tag == "Concurrence":
                states = [
                    e for e in element if isinstance(e.tag, str) and local_name(e) in STATE_TAGS
                ]
                default = self.attr(job.source, element, "default_outcome")
                if not states:
                    self.warn(
                        job.source,
                        element,
                        f"Concurrence '{name}' has no states: YASMIN's Concurrence refuses "
                        "an empty state map when it is built; read as a state that returns "
                        f"its default outcome '{default}'",
                    )
                    info[state_info.CLASS] = "Concurrence"
                    info[state_info.OUTCOMES] = json.dumps([default])
                    child = self.child_of(
                        job.source,
                        element,
                        StateRef("Concurrence", [default], element.sourceline or 0),
                    )
                else:
                    container = self.concurrence_record(job.source, element, name, "Concurrence")
                    child = self.child_of(job.source, element, container)
                    pending.append(_Job(element, container, job.source))
                    info[state_info.CLASS] = "Concurrence"
                    info[state_info.OUTCOMES] = json.dumps(container.outcomes)
            else:  # OrthogonalState
                container = self.concurrence_record(job.source, element, name, "OrthogonalState")
                child = self.child_of(job.source, element, container)
                pending.append(_Job(element, container, job.source))
                info[state_info.CLASS] = "OrthogonalState"
                info[state_info.OUTCOMES] = json.dumps(container.outcomes)
            info[A_TAG] = tag
            self.info[id(child)] = info
            children.append(child)
        return children, pending

    def machine(self, job: _Job) -> list[_Job]:
        children, pending = self.state_children(job)
        container = job.container
        if not children:
            raise self.error(
                job.source, job.element, f"state machine '{container.name}' has no states"
            )
        container.children = children
        container.labels = {c.label for c in children}
        if local_name(job.element) == "StateMachine" and job.element.getparent() is None:
            for t in job.element:
                if _is(t, "Transition"):
                    self.warn(
                        job.source,
                        t,
                        "a <Transition> of the root machine itself: yasmin_factory ignores it",
                    )
        self.unreachable(job, children)
        return pending

    def unreachable(self, job: _Job, children: list[Child]) -> None:
        """YASMIN's ``validate`` refuses states the start state cannot reach: a warning here."""
        labels = {c.label: c for c in children}
        start = job.container.initial or children[0].label
        seen = {start}
        todo = [start]
        while todo:
            child = labels.get(todo.pop())
            if child is None:
                continue
            for target in child.transitions.values():
                if target in labels and target not in seen:
                    seen.add(target)
                    todo.append(target)
        lost = [c.label for c in children if c.label not in seen]
        if lost:
            self.warn(
                job.source,
                job.element,
                f"state machine '{job.container.name}': {', '.join(lost)} cannot be reached "
                f"from its start state '{start}' (YASMIN's validate() refuses this machine "
                "when it runs it)",
            )

    def concurrence_record(
        self, source: _File, element: etree._Element, name: str, cls: str
    ) -> Container:
        default = self.attr(source, element, "default_outcome")
        outcome_map: list[tuple[str, dict[str, str]]] = []
        for entry in element:
            if not _is(entry, "OutcomeMap"):
                continue
            outcome = self.attr(source, entry, "outcome")
            required: dict[str, str] = {}
            for item in entry:
                if _is(item, "Item"):
                    required[self.attr(source, item, "state")] = self.attr(source, item, "outcome")
            if not required:
                raise self.error(
                    source,
                    entry,
                    f"outcome '{outcome}' in the outcome map of '{name}' has no <Item>; "
                    "YASMIN requires at least one",
                )
            outcome_map.append((outcome, required))
        outcomes = list(dict.fromkeys([default, *(o for o, _ in outcome_map)]))
        declared = (element.get("outcomes") or "").split()
        extra = [o for o in declared if o not in outcomes]
        if extra:
            self.warn(
                source,
                element,
                f"{cls} '{name}' lists outcomes {', '.join(extra)} that neither its outcome "
                "map nor its default gives: YASMIN's outcomes are the map's and the default",
            )
        for index, (first, need1) in enumerate(outcome_map):
            for second, need2 in outcome_map[index + 1 :]:
                if all(need2.get(k, v) == v for k, v in need1.items()):
                    self.warn(
                        source,
                        element,
                        f"{cls} '{name}': outcomes '{first}' and '{second}' can both be "
                        "satisfied; YASMIN raises 'More than one satisfied outcomes' then "
                        f"(read as '{second}')",
                    )
        container = Container(
            cls=cls, kind="concurrence", outcomes=outcomes, line=element.sourceline or 0
        )
        container.var = name
        container.default_outcome = default
        container.outcome_map = outcome_map
        return container

    def concurrence(self, job: _Job) -> list[_Job]:
        children, pending = self.state_children(job)
        for child in children:
            if child.transitions:
                raise InputError(
                    f"state '{child.label}' of Concurrence '{job.container.name}' has "
                    "transitions; a concurrent state ends through the outcome map",
                    location=SourceLocation(job.source.name, child.line),
                )
            remaps = self.info[id(child)].get(state_info.REMAPPING)
            if remaps:
                self.warn(
                    job.source,
                    job.element,
                    f"<Remap> of '{child.label}' inside Concurrence '{job.container.name}': "
                    "yasmin_factory does not apply key remappings to concurrent states "
                    "(kept as an annotation)",
                )
        job.container.children = children
        job.container.labels = {c.label for c in children}
        self.check_map(job)
        return pending

    def orthogonal(self, job: _Job) -> list[_Job]:
        children: list[Child] = []
        pending: list[_Job] = []
        joins: dict[str, list[tuple[str, str]]] = {}
        for element in job.element:
            if not _is(element, "Region"):
                continue
            name = self.attr(job.source, element, "name")
            if any(c.label == name for c in children):
                raise self.error(job.source, element, f"region '{name}' already exists")
            target, sub_source, root = self.included(job.source, element)
            body, body_source = (root, sub_source) if root is not None else (element, job.source)
            container = self.machine_record(body_source, body, name)
            container.cls = "Region"
            child = Child(name, container, {}, element.sourceline or 0)
            info = self.annotations(job.source, element, "Region")
            info[state_info.CLASS] = "Region"
            info[A_TAG] = "Region"
            if target is not None:
                info[A_INCLUDE] = json.dumps(
                    {k: v for k in ("file_path", "package", "file_name") if (v := element.get(k))}
                )
            self.info[id(child)] = info
            children.append(child)
            pending.append(_Job(body, container, body_source))
            for state in body:
                if _is(state, "JoinState"):
                    joins.setdefault(state.get("sync_id", ""), []).append(
                        (name, self.attr(body_source, state, "name"))
                    )
        if not children:
            raise self.error(
                job.source,
                job.element,
                f"OrthogonalState '{job.container.name}' has no <Region>",
            )
        for sync_id, members in joins.items():
            if len(members) < 2:
                raise self.error(
                    job.source,
                    job.element,
                    f"JoinState sync_id '{sync_id}' of OrthogonalState "
                    f"'{job.container.name}' has fewer than 2 participants (YASMIN refuses "
                    "it when it configures the state)",
                )
            job.container.sync_groups.append(members)
        job.container.children = children
        job.container.labels = {c.label for c in children}
        self.check_map(job)
        return pending

    def check_map(self, job: _Job) -> None:
        labels = {c.label for c in job.container.children}
        for outcome, required in job.container.outcome_map:
            for label in required:
                if label not in labels:
                    raise self.error(
                        job.source,
                        job.element,
                        f"the outcome map of '{job.container.name}' names '{label}' under "
                        f"'{outcome}', which is not one of its states "
                        f"({', '.join(sorted(labels))})",
                    )

    # -- annotations ----------------------------------------------------------------------------
    def annotations(self, source: _File, element: etree._Element, tag: str) -> dict[str, str]:
        """``state_info`` entries and ``yasmin.*`` attributes of one element."""
        params: dict[str, str] = {}
        expression: list[str] = []
        declarations: list[dict[str, str]] = []
        param_remap: dict[str, str] = {}
        remap: dict[str, str] = {}
        inputs: list[str] = []
        outputs: list[str] = []
        keys: list[dict[str, str]] = []
        for item in element:
            if not isinstance(item.tag, str):
                continue
            name = local_name(item)
            if name == "Param":
                pname = self.attr(source, item, "name")
                declarations.append(dict(item.attrib))
                if item.get("default_value") is not None:
                    params[pname] = item.get("default_value", "")
            elif name == "ParamRemap":
                old, new = self.attr(source, item, "old"), self.attr(source, item, "new")
                param_remap[old] = new
                params[old] = new
                expression.append(old)
            elif name == "Remap":
                remap[self.attr(source, item, "old")] = self.attr(source, item, "new")
            elif name == "Key":
                kname = self.attr(source, item, "name")
                usage = item.get("type", "in").lower()
                if usage not in ("in", "out", "in/out"):
                    raise self.error(
                        source,
                        item,
                        f"key '{kname}' has type '{usage}'; YASMIN knows in, out, in/out",
                    )
                if usage in ("in", "in/out"):
                    inputs.append(kname)
                if usage in ("out", "in/out"):
                    outputs.append(kname)
                keys.append(dict(item.attrib))
            elif name == "Default":
                kname = self.attr(source, item, "key")
                inputs.append(kname)
                keys.append(
                    {
                        "name": kname,
                        "type": "in",
                        "default_value": item.get("value", ""),
                        "default_type": item.get("type", "str"),
                    }
                )
        info = state_info.encode(
            params=params,
            expression_params=expression,
            inputs=list(dict.fromkeys(inputs)),
            outputs=list(dict.fromkeys(outputs)),
            remap=remap,
        )
        if declarations:
            info[A_PARAM_DECLS] = json.dumps(declarations)
        if param_remap:
            info[A_PARAM_REMAP] = json.dumps(param_remap)
        if keys:
            info[A_KEYS] = json.dumps(keys)
        if element.get("x") is not None and element.get("y") is not None:
            info[A_POSITION] = f"{element.get('x')} {element.get('y')}"
        if element.get("description"):
            info[A_DESCRIPTION] = element.get("description", "")
        return info

    # -- includes -------------------------------------------------------------------------------
    def included(
        self, source: _File, element: etree._Element
    ) -> tuple[Path | None, _File, etree._Element | None]:
        """The root element of the file a ``<StateMachine>`` includes, or ``None``."""
        file_path = element.get("file_path", "")
        file_name = element.get("file_name", "")
        package = element.get("package", "")
        if not file_path and not (file_name and package):
            if file_name or package:
                raise self.error(
                    source,
                    element,
                    "an included machine needs both 'package' and 'file_name' (or 'file_path')",
                )
            return None, source, None
        for child in element:
            if isinstance(child.tag, str) and local_name(child) in STATE_TAGS:
                raise self.error(
                    source,
                    child,
                    "an included machine (file_path / package) has no states of its own",
                )
        if source.path is None:  # a text (a paste, a web upload): no file of the host is read
            raise self.error(
                source,
                element,
                f"included machine '{element.get('name')}' needs the including file's path to "
                "resolve (read the file, not text)",
            )
        if file_path:
            target = self.resolve_path(source, element, file_path)
        else:
            target = self.resolve_package(source, element, package, file_name)
        if str(target) in source.chain:
            raise self.error(
                source, element, f"{target.name} includes itself (directly or through others)"
            )
        if len(source.chain) >= MAX_INCLUDE_DEPTH:
            raise self.error(
                source, element, f"more than {MAX_INCLUDE_DEPTH} nested included files"
            )
        text = decode(
            read_located(
                target, f"included machine {target}", location=self.where(source, element)
            ),
            str(target),
        )
        sub = _File(target, str(target), (*source.chain, str(target)))
        root = parse_xml(text, str(target))
        if local_name(root) != "StateMachine":
            raise self.error(
                sub, root, f"an included file's root is <{local_name(root)}>, not <StateMachine>"
            )
        self.check_children(sub, root)
        return target, sub, root

    def resolve_path(self, source: _File, element: etree._Element, file_path: str) -> Path:
        path = Path(file_path)
        if path.is_absolute():  # the factory takes it as is; fsmbt confines it (security.md, 4)
            target = path.resolve()
            top = self.confinement_root()
            if not target.is_relative_to(top):
                raise self.error(
                    source,
                    element,
                    f"file_path '{file_path}' resolves to {target}, outside the folder of the "
                    f"file read ({top}); refused (allow a wider folder with --include-root DIR, "
                    "reader option include_root)",
                )
            return target
        assert source.path is not None  # ``included`` refuses includes of a text
        folder = source.path.parent.resolve()
        target = (folder / path).resolve()
        if folder not in target.parents:
            raise self.error(
                source,
                element,
                f"file_path '{file_path}' resolves outside the including file's folder "
                "(yasmin_factory refuses it)",
            )
        return target

    def resolve_package(
        self, source: _File, element: etree._Element, package: str, file_name: str
    ) -> Path:
        """As ``get_package_share_path`` + a walk, then a source folder, then beside the file.

        ``package`` must be a package name and ``file_name`` a file name (no folder, no
        ``..``): neither can lead the lookup out of the folders named above."""
        if not _PACKAGE_NAME.fullmatch(package):
            raise self.error(source, element, f"package '{package}' is not a ROS package name")
        if not _plain_file_name(file_name):
            raise self.error(
                source, element, f"file_name '{file_name}' is not a file name (no folders)"
            )
        roots: list[Path] = []
        for prefix in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
            if prefix:
                roots.append(Path(prefix) / "share" / package)
        if source.path is not None:
            for folder in source.path.parents:
                if folder.name == package and (folder / "package.xml").is_file():
                    roots.append(folder)
                    break
        for root in roots:
            found = _find_file(root, file_name)
            if found is not None:
                return found.resolve()
        if source.path is not None:
            beside = source.path.parent / file_name
            note_read(beside)
            if beside.is_file():
                self.warn(
                    source,
                    element,
                    f"package '{package}' cannot be resolved here (no share/{package} under "
                    f"AMENT_PREFIX_PATH, no enclosing source folder '{package}'); read "
                    f"{file_name} beside this file",
                )
                return beside.resolve()
        raise self.error(
            source,
            element,
            f"included machine '{element.get('name')}': package '{package}' cannot be "
            f"resolved (no share/{package} under AMENT_PREFIX_PATH, no enclosing source "
            f"folder '{package}' with a package.xml) and there is no {file_name} beside "
            "this file; source the workspace's setup or give file_path",
        )


def _plain_file_name(name: str) -> bool:
    """A file name with no folder part: no separator, not ``.`` or ``..``."""
    return bool(name) and "/" not in name and "\\" not in name and name not in (".", "..")


def _find_file(root: Path, file_name: str) -> Path | None:
    """The first ``file_name`` under ``root`` (sorted walk, bounded), as the factory walks."""
    if not root.is_dir():
        return None
    note_read(root)
    seen = 0
    for dirpath, dirnames, files in os.walk(root):
        dirnames.sort()
        seen += len(files)
        if file_name in files:
            return Path(dirpath) / file_name
        if seen > MAX_PACKAGE_FILES:
            return None
    return None


def _is(element: object, tag: str) -> bool:
    return (
        isinstance(element, etree._Element)
        and isinstance(element.tag, str)
        and local_name(element) == tag
    )
