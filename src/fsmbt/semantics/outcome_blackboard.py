"""The exact, finite blackboard model of structured trees, and their leaf machine over outcomes
(docs/semantics.md, "11. Outcome-driven machines", "The blackboard entries modelled").

Everywhere else fsmbt refuses control flow that reads the blackboard. A structured tree reads it
in exactly three ways, and this module models exactly those, refusing any other use of the
entries they touch:

- a leaf with an output port ``outcome="{K}"`` writes its outcome's name to entry ``K`` (the
  leaf-execution machine is told which outcome: ``OutcomeLeafMachine``);
- ``Script`` with code ``K:='value'`` (or ``K='value'``), or several such assignments joined by
  ``;``, writes each literal ``value`` to its ``K`` in order and returns SUCCESS;
- ``Switch2`` .. ``Switch6`` with ``variable="{K}"`` and literal ``case_i`` ticks the first
  child whose case equals ``K``'s value, else the last (default) child; it remembers the
  running child and halts it when the match changes, as ``switch_node.h`` does.

The entries are global: every ``SubTree`` of such a tree must have ``_autoremap="true"``
(BehaviorTree.CPP then creates and finds every non-private entry in the root's blackboard), and
no other port of any node may name a modelled entry. Values are the literals the tree writes,
so the model is finite. Unset entries match no case (BehaviorTree.CPP: no variable, default).
A case value that reads as a number is refused (BehaviorTree.CPP would compare numerically).

Where the values live: in the interpreter snapshot's memory map under node id ``-1`` (no node
has it), as sorted ``(key, value)`` pairs, so snapshots stay hashable and equal states equal.

Cost: a Switch tick is O(cases); a write is O(entries).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any, cast

from fsmbt.model.bt import BTDocument, BTNode
from fsmbt.model.errors import InputError, UnsupportedError
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.bt_interpreter import (
    FAILURE,
    IDLE,
    RUNNING,
    SKIPPED,
    SUCCESS,
    BTInterpreter,
    CompiledNode,
    CompiledTree,
    Frame,
    HaltHook,
    Snapshot,
    TickAction,
)
from fsmbt.semantics.leaf_machine import LeafMachine, LeafState
from fsmbt.semantics.nodes import Family, node_semantics
from fsmbt.semantics.outcome_view import RUNNING_INPUT, OutcomeView

#: The memory slot holding the blackboard (no node has this id).
BLACKBOARD_SLOT = -1
SWITCH = "bb.Switch"
SCRIPT = "bb.Script"
#: The output port an outcome leaf writes its outcome to.
OUTCOME_PORT = "outcome"
_ENTRY = re.compile(r"\{([A-Za-z_][A-Za-z0-9_]*)\}")
_ASSIGN = re.compile(r"\s*([A-Za-z_][A-Za-z0-9_]*)\s*:?=\s*'([^']*)'\s*;?\s*")
_ASSIGNS = re.compile(r"(?:\s*[A-Za-z_][A-Za-z0-9_]*\s*:?=\s*'[^']*'\s*;?\s*)+")
_NUMBER = re.compile(r"\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?\s*")


def _where(node: BTNode) -> dict[str, Any]:
    return {"location": node.location, "element": f"<{node.type}> '{node.label}'"}


class OutcomeTree(CompiledTree):
    """A ``CompiledTree`` that also compiles the modelled Switch and Script forms."""

    def __init__(self, doc: BTDocument) -> None:
        self.switches: list[BTNode] = []
        super().__init__(doc)
        self.modelled: set[str] = set()
        self.outcome_keys: dict[int, str] = {}
        for node in self.nodes:
            if node.type == SWITCH:
                self.modelled.add(node.params[0])
            elif node.type == SCRIPT:
                self.modelled.update(key for key, _value in node.params)
        for node in self.nodes:
            key = _entry(node.source.attrs.get(OUTCOME_PORT, ""))
            if node.is_env_leaf and key is not None:
                self.outcome_keys[node.id] = key
                self.modelled.add(key)
        if self.modelled:
            self._check_exclusive()

    @property
    def uses_blackboard(self) -> bool:
        return bool(self.modelled)

    def _check(
        self, node: BTNode, chain: tuple[str, ...]
    ) -> tuple[str, NodeKind, tuple[Any, ...], int | None, list[BTNode]]:
        spec = node_semantics(node.type)
        if spec is not None and spec.family is Family.SWITCH and node.kind is NodeKind.CONTROL:
            # the arity the kind declares (fsmbt.model.nodes), as the validator reads it
            if not spec.allows_children(len(node.children)) or spec.children is None:
                raise InputError(
                    f"{node.type} needs {spec.children} children (the cases and a default), "
                    f"has {len(node.children)}",
                    **_where(node),
                )
            n = spec.children - 1
            key = _entry(node.attrs.get("variable", ""))
            if key is None:
                raise UnsupportedError(
                    f"{node.type}: 'variable' must name one blackboard entry ({{key}})",
                    **_where(node),
                )
            cases = []
            for i in range(1, n + 1):
                value = node.attrs.get(f"case_{i}")
                if value is None or "{" in value or _NUMBER.fullmatch(value):
                    raise UnsupportedError(
                        f"{node.type}: case_{i} must be a literal that is not a number "
                        f"(got {value!r})",
                        **_where(node),
                    )
                cases.append(value)
            return SWITCH, NodeKind.CONTROL, (key, tuple(cases)), None, list(node.children)
        if node.type == "Script" and not node.children:
            code = node.attrs.get("code", "")
            pairs = script_assignments(code)
            if pairs is not None:
                return SCRIPT, NodeKind.CONTROL, pairs, None, []
        return super()._check(node, chain)

    def _check_exclusive(self) -> None:
        """Refuse every use of a modelled entry the model does not cover (soundness)."""
        for node in self.nodes:
            src = node.source
            if node.kind is NodeKind.SUBTREE and src.attrs.get("_autoremap") != "true":
                raise UnsupportedError(
                    'a tree whose control flow reads the blackboard needs _autoremap="true" on '
                    "every SubTree (its entries are then the root's)",
                    **_where(src),
                )
            if src.type == "Script" and node.type != SCRIPT:
                code = src.attrs.get("code", "")
                if any(re.search(rf"\b{re.escape(k)}\b", code) for k in self.modelled):
                    raise UnsupportedError(
                        "a Script touches a modelled blackboard entry in a form the model does "
                        "not cover (only KEY:='literal')",
                        **_where(src),
                    )
            for port, value in src.attrs.items():
                key = _entry(value)
                if key is None or key not in self.modelled:
                    continue
                allowed = (node.type == SWITCH and port == "variable") or (
                    node.id in self.outcome_keys and port == OUTCOME_PORT
                )
                if not allowed:
                    raise UnsupportedError(
                        f"port '{port}' uses the blackboard entry '{key}' that a Switch reads "
                        "(only an outcome port, a Script and a Switch may)",
                        **_where(src),
                    )


def script_assignments(code: str) -> tuple[tuple[str, str], ...] | None:
    """The ``(key, literal)`` pairs of ``KEY:='literal'`` assignments joined by ``;`` (the one
    script form modelled), in order; ``None`` for any other code. O(len(code))."""
    if _ASSIGNS.fullmatch(code) is None:
        return None
    return tuple((m.group(1), m.group(2)) for m in _ASSIGN.finditer(code))


def _entry(value: str) -> str | None:
    match = _ENTRY.fullmatch(value.strip())
    return match.group(1) if match else None


def _blackboard(w: Any) -> dict[str, str]:
    return dict(w.mem.get(BLACKBOARD_SLOT, ()))


def with_entry(snap: Snapshot, key: str, value: str) -> Snapshot:
    """``snap`` with blackboard entry ``key`` set to ``value``."""
    mem = dict(snap[1])
    entries = dict(mem.get(BLACKBOARD_SLOT, ()))
    entries[key] = value
    mem[BLACKBOARD_SLOT] = tuple(sorted(entries.items()))
    return (snap[0], tuple(sorted(mem.items())), snap[2], snap[3])


class OutcomeInterpreter(BTInterpreter):
    """``BTInterpreter`` plus the Switch and Script rules of the module docstring."""

    def __init__(self, tree: OutcomeTree) -> None:
        super().__init__(tree)
        self._tick = {**self._tick, SWITCH: self._t_bb_switch, SCRIPT: self._t_bb_script}
        self._default_mem = {**self._default_mem, SWITCH: (-1,), SCRIPT: ()}
        self._halt_resets = frozenset(self._halt_resets) | {SWITCH}

    def _t_bb_switch(
        self, w: Any, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        key, cases = node.params
        if frame[1] == 0:
            value = _blackboard(w).get(key)
            match = cases.index(value) if value in cases else len(cases)
            (running,) = self.mem(w, node)
            if running != -1 and running != match:
                self.reset_child(w, node.children[running], hook)
            return ("call", node.children[match], (node.id, 1, match))
        match = frame[2]
        if result == SKIPPED:
            self.set_mem(w, node, (-1,))
            return ("ret", SKIPPED)
        if result == RUNNING:
            self.set_mem(w, node, (match,))
            return ("ret", RUNNING)
        self.reset_children(w, node, hook)
        self.set_mem(w, node, (-1,))
        return ("ret", result)

    def _t_bb_script(
        self, w: Any, node: CompiledNode, frame: Frame, result: int | None, hook: HaltHook | None
    ) -> TickAction:
        entries = _blackboard(w)
        for key, value in node.params:
            entries[key] = value
        w.mem[BLACKBOARD_SLOT] = tuple(sorted(entries.items()))
        return ("ret", SUCCESS)


class OutcomeLeafMachine(LeafMachine):
    """The leaf-execution machine of a structured tree over the source states' outcomes.

    Inputs at a leaf are the outcomes of the source unit with the leaf's label (plus
    ``running`` for an action). A dispatch unit's outcome is written to the leaf's ``outcome``
    entry (when it has the port) and the leaf returns SUCCESS; a binary unit's outcome becomes
    its status (``OutcomeView``). A leaf that is no unit of the source keeps the plain inputs
    (its label alone already differs from anything the source outputs).
    """

    def __init__(self, doc: BTDocument, view: OutcomeView, *, generic: bool = False) -> None:
        tree = OutcomeTree(doc)
        super().__init__(tree, generic=generic or tree.uses_blackboard)
        if tree.uses_blackboard:
            self.interp = OutcomeInterpreter(tree)
        self.outcome_tree = tree
        self.view = view

    def inputs(self, state: LeafState) -> Sequence[str]:
        node = self.leaf(state)
        if node is None:
            return ()
        unit = self.view.by_label.get(node.label)
        if unit is None or unit.container:
            return super().inputs(state)
        if node.is_condition:
            return unit.outcomes
        return (*unit.outcomes, RUNNING_INPUT)

    def step(self, state: LeafState, symbol: str) -> tuple[LeafState, tuple[str, ...]]:
        node = self.leaf(state)
        unit = self.view.by_label.get(node.label) if node is not None else None
        if node is None or unit is None or unit.container or symbol == RUNNING_INPUT:
            return super().step(state, symbol)
        if symbol not in unit.targets:
            raise ValueError(f"input {symbol!r} is no outcome of {unit.label}")
        if unit.dispatch:
            key = self.outcome_tree.outcome_keys.get(node.id)
            if key is not None and not isinstance(state, int):
                state = with_entry(cast(Snapshot, state), key, symbol)
            return super().step(state, "success")
        status = unit.status[symbol]
        assert status is not None, "a binary unit has a status for every outcome"
        return super().step(state, status)


__all__ = [
    "BLACKBOARD_SLOT",
    "FAILURE",
    "IDLE",
    "OUTCOME_PORT",
    "OutcomeInterpreter",
    "OutcomeLeafMachine",
    "OutcomeTree",
    "script_assignments",
    "with_entry",
]
