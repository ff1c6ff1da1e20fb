"""Run a converted behavior tree with your own actions: an LEBT on py_trees or BehaviorTree.CPP,
a dispatch tree on fsmbt's interpreter.

fsmbt's FSM -> BT conversion writes a BehaviorTree.CPP v4 tree whose leaves are ``LebtGuard``
and ``LebtState`` (``--style lebt``; docs/semantics.md, "loop-execution BT"), or, by default for
an event-driven machine, the dispatch form whose one leaf is ``DispatchEntry`` (docs/semantics.md
section 12). This module runs either and calls *your* code when a state is entered:

    runner = load_tree(Path("door_bt.xml"), {"Open": open_door, "Closed": stop_motor})
    runner.start()            # the initial state's action runs (FSMs without initial event)
    runner.post("open_cmd")   # one macro step; returns the action names run, in order
    runner.state, runner.terminated

Rules:

- Engines of an LEBT: ``"py_trees"`` (py_trees 2.6, the default) and ``"btcpp"``
  (BehaviorTree.CPP 4.8.2 through ``behaviortreepy``); both run the same leaf behaviours
  (``fsmbt.semantics.lebt.leaves``) and the macro step of docs/semantics.md: post the event,
  tick, tick once more when the root succeeded with the event still pending, drop an event no
  state takes.
- A dispatch tree runs on ``"fsmbt"`` (its only engine, the default for it): the checker's own
  macro steps (``fsmbt.runtime.dispatch_run``, over ``semantics.dispatch_runtime``): write
  ``event``, tick the root once, unset ``event``. Its entries are its ``DispatchEntry`` leaves
  (ports ``state``, ``action``, optional ``params``), called as below. py_trees has no
  ``Switch``/``Script``, and behaviortreepy cannot declare ``DispatchEntry``'s ports, so
  neither engine runs it (asking for one is a load error).
- An action is a callable looked up by the action name the ``LebtState`` leaf carries (its
  ``action`` port; by default the FSM state's name, for SMACH/FlexBE states their class, so
  several states share one). It is called ``action(state, params)``: the label of the state
  entered and its parameters (the leaf's optional ``params`` port, ``name=value;...``, decoded
  into a ``dict``; empty when none) - so one callable serves every ``TimedCmdVelState`` with
  its own velocity. A callable that takes no argument is called without (the earlier
  contract). It runs once per entry into the state, as the FSM's entry action does, in entry
  order, after the engine's ticks of that macro step (the tree's control flow never depends on
  an action). An exception raised by an action propagates to the caller of ``start``/``post``.
- Checked when loading, never at tick time (``InputError`` naming the place): the file is a
  v4 tree fsmbt can read; a dispatch tree: ``DispatchRun``'s checks; an LEBT: every node is ``LebtGuard``, ``LebtState``, ``SubTree`` or the
  control nodes the LEBT uses (``Sequence``, ``Fallback``) - any other node is named with its
  line; the LEBT annotations agree with each other (``check_lebt_annotations``: a guard pair
  naming an event its source state does not list as an exit, an exit no guard takes, a guard
  whose ``target`` is not the state it enters, a pair whose source is no state besides the one
  start pseudo-state, a malformed ``params`` port - hand edits that would otherwise stop the
  machine silently at tick time); every action name the tree uses has a callable, and (unless
  ``allow_unused=True``) every callable names an action of the tree (a typo is caught).
- ``write_files`` writes a runnable example (a converted tree and a script) into a folder.

Costs: loading is O(n) in the tree's nodes plus the engine's own build; an LEBT's macro step
costs one or two root ticks, each O(root-level selectors + depth of the active state's leaf) in
both engines (the root Sequence asks every root-level guard before the running branch); a
dispatch tree's one tick O(log7 states + events of the current state / 6). User code is never
imported or executed by fsmbt itself: only the callables you pass are called.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from pathlib import Path

from fsmbt import api
from fsmbt.formats import loads
from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import InputError
from fsmbt.runtime.dispatch_run import DispatchRun, Entry
from fsmbt.semantics.execution import Flavour, flavour_of, lebt_engine_run
from fsmbt.semantics.lebt.ports import lebt_port_issues
from fsmbt.semantics.lebt.spec import (
    GUARD_TYPE,
    PARAMS_PORT,
    STATE_TYPE,
    GuardSpec,
    StateSpec,
    decode_params,
)
from fsmbt.semantics.nodes import PLAIN_CONTROLS

#: The engines an LEBT can run on (the first is the default).
ENGINES = ("py_trees", "btcpp")
#: The engines a dispatch tree can run on: fsmbt's interpreter (docs/semantics.md section 12).
DISPATCH_ENGINES = ("fsmbt",)
#: The non-leaf nodes an LEBT is built from (fsmbt.convert.lebt, hfsm_to_bt): the plain,
#: memoryless Sequence and Fallback of the node registry.
LEBT_CONTROLS = PLAIN_CONTROLS
LEBT_LEAVES = frozenset({GUARD_TYPE, STATE_TYPE})

#: ``action(state, params)`` (or ``action()``): see the module doc.
Action = Callable[..., object]
#: The action key the engines run instead of each state's action name (one per state leaf).
_ENTRY_KEY = "fsmbt-entry-{}"

__all__ = [
    "DISPATCH_ENGINES",
    "ENGINES",
    "Entry",
    "TreeRunner",
    "check_lebt_annotations",
    "load_tree",
    "write_files",
]


class _LebtRun:
    """An LEBT engine run seen through ``DispatchRun``'s interface."""

    def __init__(self, doc: BTDocument, engine: str) -> None:
        self._run = lebt_engine_run(doc, engine)
        self.start: str = self._run.leaves.start

    @property
    def state(self) -> str:
        return str(self._run.bb.state)

    @property
    def terminated(self) -> bool:
        return bool(self._run.terminated)

    def initial(self) -> tuple[str, ...]:
        return tuple(self._run.initial())

    def macro_step(self, event: str) -> tuple[str, ...]:
        return tuple(self._run.macro_step(event))


class TreeRunner:
    """A loaded converted tree on one engine, with the user's actions (build it with
    ``load_tree``)."""

    def __init__(
        self,
        doc: BTDocument,
        actions: Mapping[str, Action],
        *,
        engine: str | None = None,
        allow_unused: bool = False,
    ) -> None:
        """Check ``doc`` and ``actions`` and build the engine's tree (not started).

        Args:
            doc: the converted tree, as fsmbt read it.
            actions: action name -> ``callable(state, params)`` (or without arguments).
            engine: ``"py_trees"`` or ``"btcpp"`` for an LEBT, ``"fsmbt"`` for a dispatch
                tree; ``None``: the first of the tree's engines (``ENGINES``,
                ``DISPATCH_ENGINES``).
            allow_unused: accept callables whose name no state of the tree uses.
        Raises:
            InputError: a node the tree's form does not use (with its line), contradicting
                LEBT annotations (``check_lebt_annotations``), a malformed ``DispatchEntry``
                (``DispatchRun``), an action without callable, a callable without action, an
                unknown engine or one that cannot run the tree.
        """
        dispatch = flavour_of(doc) is Flavour.DISPATCH
        runs_on = DISPATCH_ENGINES if dispatch else ENGINES
        if engine is None:
            engine = runs_on[0]
        if engine not in (*ENGINES, *DISPATCH_ENGINES):
            raise InputError(
                f"unknown engine '{engine}' (known: {', '.join((*ENGINES, *DISPATCH_ENGINES))})"
            )
        if engine not in runs_on:
            form = (
                "a dispatch tree (DispatchEntry leaves, docs/semantics.md section 12)"
                if dispatch
                else "a loop-execution BT"
            )
            raise InputError(f"{form} runs on {', '.join(runs_on)}, not on '{engine}'")
        self.engine = engine
        self._run: DispatchRun | _LebtRun
        if dispatch:
            self._run = DispatchRun(doc)
            self._entries = dict(self._run.entries)
        else:
            check_lebt_nodes(doc)
            check_lebt_annotations(doc)
            self._entries = _keyed_entries(doc)
            try:  # the engines run one key per state leaf, so each call knows its state
                self._run = _LebtRun(doc, engine)
            finally:
                _restore_actions(doc, self._entries)
        self.used_actions = _check_actions(self._entries, actions, allow_unused=allow_unused)
        self._actions = dict(actions)
        self._with_entry = {name: _takes_entry(name, action) for name, action in actions.items()}
        self._started = False

    @property
    def state(self) -> str:
        """The FSM state the tree is in (the start pseudo-state before the initial event; in
        a dispatch tree ``start``)."""
        return self._run.state

    @property
    def start_state(self) -> str:
        """The start pseudo-state's name."""
        return self._run.start

    @property
    def terminated(self) -> bool:
        """The tree has reached a final state of the FSM (the root returned SUCCESS)."""
        return self._run.terminated

    @property
    def started(self) -> bool:
        return self._started

    def start(self) -> tuple[str, ...]:
        """Start the tree: with no initial event the initial state is entered (one tick).

        Returns:
            The action names run (the initial state's, or none).
        Raises:
            RuntimeError: when called twice.
        """
        if self._started:
            raise RuntimeError("the tree is already started")
        self._started = True
        return self._call(self._run.initial())

    def post(self, event: str) -> tuple[str, ...]:
        """One macro step: post ``event`` and tick (twice when the rule says so).

        Args:
            event: the event name (an event no state takes is dropped).
        Returns:
            The action names run, in entry order (empty when the event was ignored).
        Raises:
            RuntimeError: before ``start``.
        """
        if not self._started:
            raise RuntimeError("call start() before posting events")
        return self._call(self._run.macro_step(event))

    def _call(self, keys: tuple[str, ...]) -> tuple[str, ...]:
        names: list[str] = []
        for key in keys:
            entry = self._entries[key]
            names.append(entry.action)
            if self._with_entry[entry.action]:
                self._actions[entry.action](entry.state, dict(entry.params))
            else:
                self._actions[entry.action]()
        return tuple(names)


def load_tree(
    source: Path | str,
    actions: Mapping[str, Action],
    *,
    engine: str | None = None,
    allow_unused: bool = False,
) -> TreeRunner:
    """Load a converted tree and bind the user's actions.

    Args:
        source: the BehaviorTree.CPP XML text (a string starting with ``<``), or the path of
            the file (a ``Path``, or any other string).
        actions: action name -> ``callable(state, params)`` (or without arguments).
        engine: ``"py_trees"`` or ``"btcpp"`` (an LEBT), ``"fsmbt"`` (a dispatch tree);
            ``None``: the tree's default (``py_trees``, ``fsmbt``).
        allow_unused: accept callables whose name no state of the tree uses.
    Returns:
        A ``TreeRunner``, not started.
    Raises:
        InputError: unreadable file, not a behavior tree, or one of ``TreeRunner``'s checks.
    """
    if isinstance(source, str) and source.lstrip("\ufeff \t\r\n").startswith("<"):
        model = loads(source, "btcpp")
    else:
        model = api.load(Path(source)).model
    if not isinstance(model, BTDocument):
        raise InputError(
            "not a behavior tree: the runtime runs converted trees "
            "(fsmbt convert model -o tree.xml)"
        )
    return TreeRunner(model, actions, engine=engine, allow_unused=allow_unused)


def check_lebt_nodes(doc: BTDocument) -> None:
    """Refuse any node an LEBT does not have, naming it and its line.

    Raises:
        InputError: the first such node in document order (a ``DispatchEntry`` among LEBT
        leaves too: a tree is one form or the other).
    """
    for tree in doc.trees.values():
        stack: list[BTNode] = [tree.root] if tree.root is not None else []
        while stack:
            node = stack.pop()
            allowed = (
                node.type in LEBT_LEAVES
                if node.is_leaf
                else node.kind is NodeKind.SUBTREE or node.type in LEBT_CONTROLS
            )
            if not allowed:
                raise InputError(
                    f"<{node.type}> is not a node of a converted tree (loop-execution BT: "
                    f"leaves {GUARD_TYPE} and {STATE_TYPE}, controls "
                    f"{', '.join(sorted(LEBT_CONTROLS))}, SubTree)",
                    location=node.location,
                    element=f"<{node.type}> '{node.label}'",
                )
            stack.extend(reversed(node.children))


def check_lebt_annotations(doc: BTDocument) -> None:
    """Refuse an LEBT whose annotations contradict each other (docs/semantics.md section 5).

    The checks of ``fsmbt.semantics.lebt.ports.lebt_port_issues`` (a guard pair whose event
    is not among its source state's ``exits``, an exit no guard pair takes, a ``target`` that
    is not the state the guard enters), plus: a pair whose source is neither a state nor the
    start pseudo-state (an LEBT has one start; a second unknown source is a misspelt state),
    and a malformed ``params`` port. Each would make the machine stop or ignore an event at
    tick time without a word.

    Raises:
        InputError: the first problem in document order, naming the leaf and its line.
    """
    issues = [issue for issue in lebt_port_issues(doc) if issue.severity == "error"]
    if issues:
        first = issues[0]
        more = f" (and {len(issues) - 1} more)" if len(issues) > 1 else ""
        raise InputError(
            f"LEBT annotations disagree: {first.message}{more}",
            location=first.location,
            element=first.element,
        )
    states: set[str] = set()
    guards: list[BTNode] = []
    for tree in doc.trees.values():
        for node in tree.root.walk() if tree.root is not None else ():
            if node.type == STATE_TYPE:
                states.add(StateSpec.from_attrs(node.attrs).state)
                try:
                    decode_params(node.attrs.get(PARAMS_PORT, ""))
                except ValueError as exc:
                    raise InputError(
                        f"port '{PARAMS_PORT}': {exc}",
                        location=node.location,
                        element=f"<{STATE_TYPE}> '{node.label}'",
                    ) from None
            elif node.type == GUARD_TYPE:
                guards.append(node)
    starts: dict[str, BTNode] = {}
    for guard in guards:
        for source, _event in GuardSpec.from_attrs(guard.attrs).pairs:
            if source not in states:
                starts.setdefault(source, guard)
    if len(starts) > 1:
        # the start pseudo-state is the source of the initialisation pair (empty event) when
        # there is one; every other unknown source names no state
        initial = [
            s
            for s, g in starts.items()
            if any(p == (s, "") for p in GuardSpec.from_attrs(g.attrs).pairs)
        ]
        start = initial[0] if initial else next(iter(starts))
        source, guard = next((s, g) for s, g in starts.items() if s != start)
        raise InputError(
            f"LEBT annotations disagree: pair source '{source}' is no state of the tree (its "
            f"states: {', '.join(sorted(states))}; the start pseudo-state is '{start}'), so "
            "the transition never fires",
            location=guard.location,
            element=f"<{GUARD_TYPE}> '{guard.label}'",
        )


def _keyed_entries(doc: BTDocument) -> dict[str, Entry]:
    """Give every state leaf with an action its own key in its ``action`` port (restored by
    ``_restore_actions``); the key -> the entry it stands for."""
    entries: dict[str, Entry] = {}
    for tree in doc.trees.values():
        for node in tree.root.walk() if tree.root is not None else ():
            if node.type != STATE_TYPE:
                continue
            spec = StateSpec.from_attrs(node.attrs)
            if spec.action is None:
                continue
            key = _ENTRY_KEY.format(len(entries))
            params = decode_params(node.attrs.get(PARAMS_PORT, ""))
            entries[key] = Entry(spec.action, spec.state, params)
            node.attrs["action"] = key
    return entries


def _restore_actions(doc: BTDocument, entries: Mapping[str, Entry]) -> None:
    for tree in doc.trees.values():
        for node in tree.root.walk() if tree.root is not None else ():
            entry = entries.get(node.attrs.get("action", "")) if node.type == STATE_TYPE else None
            if entry is not None:
                node.attrs["action"] = entry.action


def _takes_entry(name: str, action: Action) -> bool:
    """Whether ``action`` is called with (state, params) (True) or without arguments.

    Raises:
        InputError: it can be called neither way (e.g. it requires one argument).
    """
    try:
        signature = inspect.signature(action)
    except (TypeError, ValueError):  # a builtin without a signature: the documented contract
        return True
    for arguments, with_entry in ((("state", {}), True), ((), False)):
        try:
            signature.bind(*arguments)
        except TypeError:
            continue
        return with_entry
    raise InputError(
        f"the callable for action '{name}' takes {signature}: it must take (state, params) "
        "or no argument"
    )


def _check_actions(
    entries: Mapping[str, Entry], actions: Mapping[str, Action], *, allow_unused: bool
) -> frozenset[str]:
    """Every action of the tree has a callable (and every callable an action)."""
    used: dict[str, str] = {}  # action -> a state that runs it
    for entry in entries.values():
        used.setdefault(entry.action, entry.state)
    missing = [name for name in used if name not in actions]
    if missing:
        shown = ", ".join(f"'{name}' (state '{used[name]}')" for name in missing)
        raise InputError(
            f"no callable for the action(s) {shown}; pass one per action name "
            f"(the tree's actions: {', '.join(sorted(used))})"
        )
    not_callable = [name for name, action in actions.items() if not callable(action)]
    if not_callable:
        raise InputError(f"the action(s) {', '.join(map(repr, not_callable))} are not callable")
    unused = [name for name in actions if name not in used]
    if unused and not allow_unused:
        raise InputError(
            f"no state of the tree runs the action(s) "
            f"{', '.join(map(repr, unused))} (a typo? pass allow_unused=True to "
            f"accept them); the tree's actions: {', '.join(sorted(used))}"
        )
    return frozenset(used)


# -- the example folder -------------------------------------------------------------------------
EXAMPLE_TREE = "lebt_tree.xml"
EXAMPLE_SCRIPT = "run_lebt.py"


def write_files(directory: Path, *, overwrite: bool) -> list[Path]:
    """Write a self-contained runnable example: a converted tree and a script that runs it.

    The tree is the LEBT of a small door controller (converted by fsmbt here, so it is always
    what this fsmbt writes); the script binds one printing callable per action and runs a few
    events on both engines (``python run_lebt.py`` in the folder, with fsmbt installed).

    Args:
        directory: the folder (created when missing).
        overwrite: replace files that exist; without it an existing file is an error.
    Returns:
        The paths written.
    Raises:
        InputError: a file exists and ``overwrite`` is False, or the folder is a file.
    """
    if directory.exists() and not directory.is_dir():
        raise InputError(f"{directory} exists and is not a folder")
    paths = [directory / EXAMPLE_TREE, directory / EXAMPLE_SCRIPT]
    existing = [p for p in paths if p.exists()]
    if existing and not overwrite:
        raise InputError(
            f"{', '.join(map(str, existing))} already exist(s); nothing written "
            "(overwrite=True / --force replaces them)"
        )
    directory.mkdir(parents=True, exist_ok=True)
    paths[0].write_text(_example_tree(), encoding="utf-8")
    paths[1].write_text(_EXAMPLE_SCRIPT_TEXT, encoding="utf-8")
    return paths


_EXAMPLE_FSM = """\
<?xml version="1.0" encoding="UTF-8"?>
<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" name="door" initial="Closed">
  <state id="Closed"><transition event="open_cmd" target="Opening"/></state>
  <state id="Opening"><transition event="fully_open" target="Open"/>
    <transition event="fault" target="Stopped"/></state>
  <state id="Open"><transition event="close_cmd" target="Closing"/></state>
  <state id="Closing"><transition event="fully_closed" target="Closed"/>
    <transition event="obstacle" target="Opening"/></state>
  <final id="Stopped"/>
</scxml>
"""


def _example_tree() -> str:
    """The example FSM converted as ``fsmbt convert --style lebt`` does (the library pipeline,
    rules; this runtime runs LEBTs, not the dispatch form ``auto`` writes for such a machine)."""
    from fsmbt import api

    return api.convert_loaded(api.load_text(_EXAMPLE_FSM, "scxml"), to="btcpp", style="lebt").text


_EXAMPLE_SCRIPT_TEXT = '''\
"""Run the converted tree lebt_tree.xml with your own actions, on py_trees and BehaviorTree.CPP.

Written by fsmbt (fsmbt.runtime.python_runtime.write_files). Run: python run_lebt.py
Replace the callables in ACTIONS with your robot's code; docs: docs/runtime-python.md.
"""

from pathlib import Path

from fsmbt.runtime.python_runtime import ENGINES, load_tree

TREE = Path(__file__).with_name("lebt_tree.xml")
EVENTS = ["open_cmd", "fully_open", "close_cmd", "obstacle", "fully_open", "close_cmd",
          "fully_closed", "open_cmd", "fault"]


def say(text):
    return lambda: print(f"    action: {text}")


ACTIONS = {
    "Closed": say("door closed, motor off"),
    "Opening": say("motor forward"),
    "Open": say("door open, motor off"),
    "Closing": say("motor backward"),
    "Stopped": say("fault: motor off, door stopped"),
}

for engine in ENGINES:
    print(f"engine {engine}")
    runner = load_tree(TREE, ACTIONS, engine=engine)
    runner.start()
    for event in EVENTS:
        print(f"  event {event}")
        runner.post(event)
        print(f"    state {runner.state}, terminated {runner.terminated}")
'''
