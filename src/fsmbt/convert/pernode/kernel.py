"""What the per-node families share: continuations, the writer's contract, and the rule a
family declares (``fsmbt.convert.pernode``; docs/conversion.md, "Per-node conversion").

A family's rule is three functions over one node (``NodeRule``), each O(children) apart from the
halt chains (O(subtree) assignments per halted child, written once per chain):

- ``can_run(writer, node, kids)``: whether the node may return RUNNING, given whether each child
  may (the writer calls it bottom-up);
- ``declare(writer, node)``: the node's variables (memory at rest ``0``, each recorded in one of
  the writer's tables), returning those a halt of the node resets (``halt_resets_memory``);
- ``write(writer, node, returns)``: given where the node's SUCCESS, FAILURE and RUNNING lead,
  write the node's transient states and return, per child, where the child's results lead;
- ``refuse(node)``: why the node cannot be written per node (``None``: it can).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

from fsmbt.model.fsm import FSM
from fsmbt.semantics.compiled import FAILURE, SUCCESS, CompiledNode
from fsmbt.semantics.nodes import RuntimeTables

#: State attribute naming the node a state belongs to (its ``CompiledNode.path`` in the region).
NODE_ATTR = "{https://fsmbt.dev/ns/scxml}node"
#: State attribute naming the part of the node's rule a transient state is (entry, a return).
ROLE_ATTR = "{https://fsmbt.dev/ns/scxml}role"
EV_SUCCESS, EV_FAILURE, EV_RUNNING = "success", "failure", "running"
EVENTS_BY_STATUS = {SUCCESS: "S", FAILURE: "F"}
END_SUCCESS, END_FAILURE = "SUCCESS", "FAILURE"
#: Handlers of the loop family and the result they repeat on (``loops.loop_decorator``).
LOOP_AGAIN_ON = {"repeat": SUCCESS, "retry": FAILURE}
#: Handlers of the counting parallels (``families.parallel``): Parallel, ParallelAll.
PARALLEL_HANDLERS = frozenset({"parallel", "parallel_all"})

Assign = tuple[str, str]


@dataclass(frozen=True)
class Cont:
    """Where a result leads: a state, and the assignments run on the way (in order)."""

    target: str
    assigns: tuple[Assign, ...] = ()

    def after(self, assigns: list[Assign] | tuple[Assign, ...]) -> Cont:
        """This continuation with ``assigns`` run first."""
        return Cont(self.target, tuple(assigns) + self.assigns) if assigns else self


@dataclass
class PerNodeRegion:
    """A region written per node.

    Attributes:
        fsm: the sub-machine (leaf states, transient states, ``SUCCESS``/``FAILURE`` finals).
        ends: the final states some transition enters.
        variables: ``(name, initial)`` of every variable (the memory at rest).
        nodes: nodes of the region; ``guarded``: transitions with a guard.
        node_of: state name -> the node path it belongs to.
    """

    fsm: FSM
    ends: set[str]
    variables: list[tuple[str, str]]
    nodes: int
    guarded: int = 0
    node_of: dict[str, str] = field(default_factory=dict)


class RegionWriter(Protocol):
    """The writer a family's rule writes through (``writer.Writer``): the region's nodes, the
    runtime tables, each node's entry state and variables, and the ways to add states."""

    nodes: list[CompiledNode]
    tables: RuntimeTables
    can_run: list[bool]
    entry: dict[int, str]
    idx: dict[int, str]
    cr: dict[int, str]
    count: dict[int, str]
    done: dict[int, dict[int, str]]
    successes: dict[int, str]
    failures: dict[int, str]

    def variable(
        self, node: CompiledNode, field_name: str, table: dict[int, str], key: int | None = None
    ) -> str:
        """A new variable of ``node`` (at rest ``0``), recorded in ``table``."""
        ...

    def go(self, source: str, event: str | None, cont: Cont, cond: str | None = None) -> None:
        """A transition from ``source`` on ``event`` (``None``: eventless) to ``cont``."""
        ...

    def transient(self, node: CompiledNode, role: str, arms: list[tuple[str | None, Cont]]) -> Cont:
        """A transient state taking the first arm whose guard holds."""
        ...

    def chain(self, node: CompiledNode, tag: str, end: Cont, first: int = 1) -> list[Cont]:
        """``chain[k]``: halt children k.. of ``node``, then ``end``."""
        ...


Returns = dict[int, Cont]


@dataclass(frozen=True)
class NodeRule:
    """A family's per-node rule (module docstring), keyed in ``registry.RULES`` by the
    ``handler`` names of ``fsmbt.semantics.nodes.runtime_tables`` it serves."""

    handlers: frozenset[str]
    can_run: Callable[[RegionWriter, CompiledNode, list[bool]], bool]
    declare: Callable[[RegionWriter, CompiledNode], list[Assign]]
    write: Callable[[RegionWriter, CompiledNode, Returns], list[Returns]]
    refuse: Callable[[CompiledNode], str | None] = lambda _node: None
