"""A behavior tree as an SMV module, written from the tree's structure (docs/semantics.md,
"The leaf-execution machine"; docs/nusmv.md).

The tick rules of BehaviorTree.CPP v4 are transition relations over per-node variables, one
*micro-step* per node visit, exactly as the interpreter walks the tree (docs/nusmv.md):

- ``cur`` is the node on top of the call stack (``TOP`` when the root has returned, ``DONE_*``
  after the root's result with ``loop`` off); ``res`` is the status the child just returned to
  ``cur`` (``NONE``: ``cur`` was just called); ``lidx`` is that child's index. The rest of the
  stack is the path from the root to ``cur``, so it needs no variable.
- ``st_n`` is node ``n``'s status (IDLE/RUNNING/SUCCESS/FAILURE), ``idx_n`` the running-child
  index of Sequence/Fallback/SequenceWithMemory/Async*, ``prev_n`` their child's status when it
  was called (the stack frame's local), ``wake`` the tree's wake-up signal (``tickOnce``).
- Halting is a combinational closure: ``clr_n`` (status reset to IDLE) holds when ``n``'s parent
  resets it now or the parent is being halted; ``hlt_n := clr_n & st_n = RUNNING`` (a RUNNING
  node is halted, which resets its memory and clears its children).

Which kinds are encoded and by which rule is the node registry's ``nusmv`` field, and why a
kind is refused its ``nusmv_refusal`` (``fsmbt.semantics.nodes``, docs/semantics.md "Node
registry"); each rule lives in its family's module of ``fsmbt.verify.nusmv.families`` (named
as the interpreter's family modules, merged by ``families.registry``), which this encoder
dispatches on. Leaf requests are where the environment answers: in a leaf-execution machine
they are the stable states that take an input (success/failure/running); the LEBT encoding
(``encode_lebt``) answers them from its blackboard instead. Supported node types are listed in
``SUPPORTED`` (derived from the registry); anything else raises ``UnsupportedError`` (docs/nusmv.md says why).
Size: O(N · d) SMV text for N nodes of depth d.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import Hint, UnsupportedError
from fsmbt.semantics.bt_interpreter import CompiledNode, CompiledTree
from fsmbt.semantics.nodes import NUSMV_ENCODED, all_nodes, node_semantics
from fsmbt.semantics.status import LeafOutcome, NodeStatus, RootResult
from fsmbt.verify.nusmv.families.contract import NusmvRule, Resets
from fsmbt.verify.nusmv.families.loops import LOOP_KINDS
from fsmbt.verify.nusmv.families.once import ONCE_KINDS
from fsmbt.verify.nusmv.families.registry import nusmv_rules
from fsmbt.verify.nusmv.families.sequence import SEQ_LIKE
from fsmbt.verify.nusmv.families.status_map import SIMPLE_DECORATORS
from fsmbt.verify.nusmv.smv import Symbols, any_of, case

if TYPE_CHECKING:
    from fsmbt.verify.nusmv.encode_fsm import Encoding

# The encoding rules by node kind, from the registry's ``nusmv`` field.
#: Project kinds with an index or counter (docs/semantics.md §10): rule name.
MEMORY_RULES = {
    n.name: n.nusmv
    for n in all_nodes()
    if n.nusmv
    in ("pipeline", "recovery", "round_robin", "repeat_each_tick", "if_then_else", "while_do_else")
}
#: Abstractions and wrappers whose only state is statuses (docs/semantics.md §10): rule name.
GATE_RULES = {
    n.name: n.nusmv
    for n in all_nodes()
    if n.nusmv in ("gated", "timeout", "sleep", "for_each", "pass_through", "pass_through_keep")
}
#: The Loop family (docs/semantics.md, "LoopInt, LoopBool, LoopDouble, LoopString").
LOOP_RULES = frozenset(n.name for n in all_nodes() if n.nusmv == "loop_queue")
#: julienbayle/stardust RealParallel (docs/semantics.md, "Project nodes").
REAL_PARALLEL_RULES = frozenset(n.name for n in all_nodes() if n.nusmv == "real_parallel")
#: Kinds whose pick is an environment input asked through choice conditions (ManualSelector).
MANUAL_RULES = frozenset(n.name for n in all_nodes() if n.nusmv == "manual_selector")
SUPPORTED = NUSMV_ENCODED
#: type -> why the encoding refuses it
NOT_ENCODED = {n.name: n.nusmv_refusal for n in all_nodes() if n.nusmv_refusal is not None}
#: The SMV constants of the four stored statuses (``NodeStatus`` names' initials).
ST = {s.name: s.name[0] for s in NodeStatus if s is not NodeStatus.SKIPPED}
_S, _F = ST[NodeStatus.SUCCESS.name], ST[NodeStatus.FAILURE.name]
STATUS_ENUM = "{I, R, S, F}"
#: SKIPPED, a returned status only (``res``; never stored in ``st_n``, docs/semantics.md §2).
_K = "K"
#: Rules whose SMV rules handle a child that returns SKIPPED (docs/nusmv.md, "SKIPPED"): the
#: sequences (skipped counter ``sk_n``), the reactive ones (frame flag ``rk_n``), the status
#: maps and SubTree (passed on). Any other parent of a child that may skip is refused.
SKIP_AWARE = frozenset({"sequence", "reactive", "simple_decorator", "subtree"})


@dataclass
class NodeInfo:
    node: CompiledNode
    env_leaf: bool
    internal: str | None  # "S"/"F" for AlwaysSuccess & co
    rule: str | None = None  # the kind's NuSMV rule name (the registry's ``nusmv`` field)


class BTCore:
    """The tick rules of one compiled tree as SMV (shared by the leaf and LEBT encodings).

    ``rules`` collects ``(condition, value)`` pairs per variable in priority order; the caller
    adds its own rules (leaf answers, what happens when the root returns) and emits the module.
    """

    def __init__(self, doc: BTDocument | CompiledTree, *, loop: bool) -> None:
        self.tree = doc if isinstance(doc, CompiledTree) else CompiledTree(doc)
        self.nodes = self.tree.nodes
        self.loop = loop
        # One table from NuSMV rule name to the rule (docs/semantics.md "Node families"): the
        # families' rules registered by name, then the ones this encoder writes itself.
        self.dispatch: dict[str, Callable[[CompiledNode, str, str, Resets], None]] = {
            name: self._registered(rule) for name, rule in nusmv_rules().items()
        }
        self.dispatch.update(
            loop_queue=self._loop_rules,
            real_parallel=lambda x, here, called, resets: self._real_parallel_rules(
                x, here, called
            ),
            manual_selector=self._manual_rules,
        )
        for name in ("gated", "timeout", "sleep", "for_each"):
            self.dispatch[name] = self._with_name(self._gate_rules, name)
        for name in (
            "pipeline",
            "recovery",
            "round_robin",
            "repeat_each_tick",
            "if_then_else",
            "while_do_else",
        ):
            self.dispatch[name] = self._with_name(self._memory_rules, name)
        self.info: list[NodeInfo] = []
        has_internal = False
        has_keep_running = False
        has_endless_loop = False
        for node in self.nodes:
            if node.kind in (NodeKind.ACTION, NodeKind.CONDITION):
                internal = None
                if node.internal_status is not None:
                    internal = _S if node.internal_status == NodeStatus.SUCCESS else _F
                    has_internal = True
                self.info.append(NodeInfo(node, internal is None, internal))
                continue
            spec = node_semantics(node.type)
            if spec is None or spec.nusmv is None or spec.nusmv not in self.dispatch:
                reason = NOT_ENCODED.get(node.type, "not encoded")
                raise UnsupportedError(
                    f"the NuSMV encoding does not support {node.type} ({reason})",
                    location=node.source.location,
                    element=f"<{node.type}> '{node.label}'",
                    hints=(Hint.NATIVE_VERIFIER,),
                )
            # a simple decorator without a result map (KeepRunningUntilFailure) can tick forever
            has_keep_running |= (
                node.type in SIMPLE_DECORATORS and spec is not None and spec.result_map is None
            )
            # so can Repeat/Retry with -1; a RunOnce that has run, or a loop that never ticks
            # its child (a count <= 0 other than -1), answers without any leaf
            limit = node.params[0] if node.type in LOOP_KINDS else None
            has_endless_loop |= limit == -1
            has_internal |= node.type in ONCE_KINDS or (limit is not None and -1 != limit <= 0)
            self.info.append(NodeInfo(node, False, None, spec.nusmv))
        self.may_skip = self._may_skip()
        if (
            has_internal
            and (loop or has_keep_running or has_endless_loop)
            and not self._ticks_a_leaf()[0]
        ):
            raise UnsupportedError(
                "the NuSMV encoding does not model ticks that end without any leaf "
                "(AlwaysSuccess/AlwaysFailure & co, a RunOnce or a zero-count Repeat/"
                "RetryUntilSuccessful, with loop, "
                "KeepRunningUntilFailure or an endless Repeat/RetryUntilSuccessful: the engine "
                "could livelock)",
                element=self.nodes[0].label,
                hints=(Hint.NATIVE_VERIFIER,),
            )
        self.max_children = max((len(n.children) for n in self.nodes), default=0)
        self.rules: dict[str, list[tuple[str, str]]] = {}
        self.var_types: dict[str, str] = {}
        self.defines: list[tuple[str, str]] = []
        self.init: dict[str, str] = {}
        #: memory variables of project kinds (index, counters): reset to 0 by a halt
        self.memory_vars: list[tuple[str, int]] = []
        #: memory variables a halt keeps (ManualSelector's repeated selection, RunOnce's result)
        self.kept_vars: list[str] = []

    def _may_skip(self) -> list[bool]:
        """Per node: whether it can return SKIPPED (RunOnce ``then_skip``, a gate closed on
        SKIPPED; a sequence/reactive node all of whose children may skip; a status map or
        SubTree over one that may). A parent of such a child whose rule is not in
        ``SKIP_AWARE`` is refused. O(N), children before parents (reverse pre-order)."""
        skip = [False] * len(self.nodes)
        for info in reversed(self.info):
            x = info.node
            if info.rule is None:
                continue
            spec = node_semantics(x.type)
            aware = info.rule in SKIP_AWARE and (
                info.rule != "simple_decorator"
                or (spec is not None and spec.result_map is not None)
            )
            if info.rule == "run_once":
                skip[x.id] = bool(x.params[0])
            elif info.rule == "gated":
                gate = spec.gate if spec is not None else None
                skip[x.id] = gate is not None and gate.closed == NodeStatus.SKIPPED.name
            elif aware:
                skip[x.id] = bool(x.children) and all(skip[c] for c in x.children)
            if not aware and any(skip[c] for c in x.children):
                raise UnsupportedError(
                    f"the NuSMV encoding does not support a child that may return SKIPPED "
                    f"under {x.type} (SKIPPED is encoded under Sequence/Fallback & co, the "
                    "reactive controls, Inverter/Force* and SubTree only)",
                    location=x.source.location,
                    element=f"<{x.type}> '{x.label}'",
                    hints=(Hint.NATIVE_VERIFIER,),
                )
        return skip

    def _ticks_a_leaf(self) -> list[bool]:
        """Per node: whether every tick of it ticks an environment leaf (a sufficient, static
        test; docs/nusmv.md). A root that does cannot livelock (no tick ends without a leaf),
        so internal answers (RunOnce, SingleTrigger, AlwaysSuccess...) are allowed with
        ``loop`` under it. Two facts per node, children first: ``sure`` (any tick) and
        ``busy`` (a tick while the node is RUNNING):

        - a condition leaf: both; an action leaf: ``busy`` (RUNNING, it asks), ``sure`` only
          under a parent that never ticks it again once completed without resetting it (the
          sequences, status maps, SubTree, RunOnce; a stale action answers its old status
          without asking); a reactive node: its first child is ``sure`` (it starts there);
        - Sequence/Fallback (no wake-up, no memory): child 0 ``sure`` and every later child
          ``busy`` (the index is above 0 at a tick's start only while that child is RUNNING:
          any completion moves or resets it in the same tick, a halt resets it);
        - a gated node, the other sequences: every child ``sure``;
        - status maps, SubTree, RunOnce, SingleTrigger: ``busy`` when the child is (RUNNING,
          they tick their RUNNING child), or ``sure`` if the child may skip (a SKIPPED child
          leaves a status map RUNNING); status maps and SubTree are ``sure`` when the child is.

        O(N)."""
        sure = [False] * len(self.nodes)
        busy = [False] * len(self.nodes)
        for info in reversed(self.info):
            x = info.node
            kids = list(x.children)
            spec = node_semantics(x.type) if info.rule is not None else None
            passes = info.rule in ("subtree", "run_once", "single_trigger") or (
                info.rule == "simple_decorator" and spec is not None and spec.result_map is not None
            )
            if info.env_leaf:
                parent = self.info[x.parent].rule if x.parent is not None else None
                busy[x.id] = True
                sure[x.id] = x.kind is NodeKind.CONDITION or parent in (
                    "sequence",
                    "simple_decorator",
                    "subtree",
                    "run_once",
                )
            elif not kids:
                continue
            elif info.rule == "reactive":
                sure[x.id] = busy[x.id] = sure[kids[0]]
            elif info.rule == "sequence" and not SEQ_LIKE[x.type][1] and not SEQ_LIKE[x.type][2]:
                plain = sure[kids[0]] and all(busy[c] for c in kids[1:])
                sure[x.id] = busy[x.id] = plain
            elif info.rule in ("sequence", "gated"):
                sure[x.id] = busy[x.id] = all(sure[c] for c in kids)
            elif passes:
                (c,) = kids
                sure[x.id] = info.rule in ("subtree", "simple_decorator") and sure[c]
                busy[x.id] = sure[c] if self.may_skip[c] else busy[c]
        return sure

    # -- naming ----------------------------------------------------------------------------
    def n(self, nid: int) -> str:
        return f"n{nid}"

    def st(self, nid: int) -> str:
        return f"st_{nid}"

    def rule(self, var: str, cond: str, value: str) -> None:
        self.rules.setdefault(var, []).append((cond, value))

    def is_seq_like(self, nid: int) -> bool:
        return self.nodes[nid].type in SEQ_LIKE

    def has_prev(self, nid: int) -> bool:
        """Whether ``nid``'s frame keeps ``prev_n``, its child's status when called (the
        wake-up test of the sequences and of Repeat/RetryUntilSuccessful)."""
        return self.is_seq_like(nid) or self.nodes[nid].type in LOOP_KINDS

    # -- declarations ----------------------------------------------------------------------
    def declare(self, cur_extra: list[str], init_cur: str) -> None:
        cur_values = [self.n(x.id) for x in self.nodes] + cur_extra
        self.var_types["cur"] = "{" + ", ".join(cur_values) + "}"
        self.var_types["res"] = "{NONE, R, S, F, K}"
        self.var_types["lidx"] = f"0..{max(self.max_children - 1, 1)}"
        self.var_types["wake"] = "boolean"
        self.init.update(cur=init_cur, res="NONE", lidx="0", wake="FALSE")
        for x in self.nodes:
            self.var_types[self.st(x.id)] = STATUS_ENUM
            self.init[self.st(x.id)] = "I"
            if self.is_seq_like(x.id):
                self.var_types[f"idx_{x.id}"] = f"0..{max(len(x.children) - 1, 1)}"
                self.init[f"idx_{x.id}"] = "0"
            if self.has_prev(x.id):
                self.var_types[f"prev_{x.id}"] = STATUS_ENUM
                self.init[f"prev_{x.id}"] = "I"

    def identity_vars(self) -> list[str]:
        out = ["cur", "wake"]
        for x in self.nodes:
            out.append(self.st(x.id))
            if self.is_seq_like(x.id):
                out.append(f"idx_{x.id}")
            if self.has_prev(x.id):
                out.append(f"prev_{x.id}")
            if f"rk_{x.id}" in self.var_types:
                out.append(f"rk_{x.id}")
        out += [var for var, _nid in self.memory_vars]
        out += self.kept_vars
        return out

    def memory(self, name: str, nid: int, top: int, *, reset_by_halt: bool = True) -> str:
        """Declare a memory variable ``0..top`` of node ``nid`` (reset by its halt unless
        ``reset_by_halt`` is false)."""
        var = f"{name}_{nid}"
        self.var_types[var] = f"0..{max(top, 1)}"
        self.init[var] = "0"
        if reset_by_halt:
            self.memory_vars.append((var, nid))
        else:
            self.kept_vars.append(var)
        return var

    # -- the rules -------------------------------------------------------------------------
    def call(self, cond: str, child: int) -> None:
        """``cur`` calls ``child``: it becomes the top of the stack with no result yet."""
        self.rule("cur", cond, self.n(child))
        self.rule("res", cond, "NONE")
        self.rule("lidx", cond, "0")

    def ret(self, cond: str, nid: int, status: str) -> None:
        """``nid`` returns ``status`` (an SMV expression over R/S/F) to its parent or to TOP."""
        node = self.nodes[nid]
        st = self.st(nid)
        if status == _K:  # never stored: the node keeps its status (docs/semantics.md §2)
            self.rule(st, cond, st)
        elif self.may_skip[nid] and status not in ST.values():
            self.rule(st, cond, f"case ({status}) = K : {st}; TRUE : {status}; esac")
        else:
            self.rule(st, cond, status)
        self.rule("cur", cond, self.n(node.parent) if node.parent is not None else "TOP")
        self.rule("res", cond, status)
        self.rule("lidx", cond, str(node.index))
        if self.has_prev(nid):
            self.rule(f"prev_{nid}", cond, "I")
        if f"rk_{nid}" in self.var_types:  # the reactive frame's flag: canonical off the stack
            self.rule(f"rk_{nid}", cond, "1")

    def build(self) -> None:
        """Every node's tick rules, and the halt closure."""
        resets: dict[int, list[str]] = {x.id: [] for x in self.nodes}  # child -> conditions
        for info in self.info:
            x = info.node
            here = f"cur = {self.n(x.id)}"
            called = f"{here} & res = NONE"
            if info.internal is not None:
                self.ret(called, x.id, info.internal)
                continue
            if info.env_leaf:
                if x.kind is NodeKind.ACTION:  # StatefulActionNode: old status, no callback
                    stale = f"{called} & ({self.st(x.id)} = S | {self.st(x.id)} = F)"
                    self.ret(stale, x.id, f"case {self.st(x.id)} = S : S; TRUE : F; esac")
                continue  # leaf requests: answered by the machine encoding
            assert info.rule is not None
            self.dispatch[info.rule](x, here, called, resets)
        # halt closure (pre-order ids: a parent's defines come before its children's)
        for x in self.nodes:
            parent_halt = f"hlt_{x.parent}" if x.parent is not None else "FALSE"
            self.defines.append((f"clr_{x.id}", any_of(resets[x.id] + [parent_halt])))
            self.defines.append((f"hlt_{x.id}", f"(clr_{x.id} & {self.st(x.id)} = R)"))
            # a halted node's memory is reset (Sequence/Fallback/Async*; not WithMemory)
            if self.is_seq_like(x.id) and not SEQ_LIKE[x.type][2]:
                self.rules.setdefault(f"idx_{x.id}", []).insert(0, (f"hlt_{x.id}", "0"))
        for var, nid in self.memory_vars:
            self.rules.setdefault(var, []).insert(0, (f"hlt_{nid}", "0"))
        for x in self.nodes:
            self.rules.setdefault(self.st(x.id), []).insert(0, (f"clr_{x.id}", "I"))

    def _registered(self, rule: NusmvRule) -> Callable[[CompiledNode, str, str, Resets], None]:
        """A registered family rule bound to this encoder."""

        def encode(x: CompiledNode, here: str, called: str, resets: Resets) -> None:
            rule(self, x, here, called, resets)

        return encode

    @staticmethod
    def _with_name(
        method: Callable[[CompiledNode, str, str, str, Resets], None], name: str
    ) -> Callable[[CompiledNode, str, str, Resets], None]:
        """One of this encoder's rules that serves several names, for ``name``."""

        def encode(x: CompiledNode, here: str, called: str, resets: Resets) -> None:
            method(x, name, here, called, resets)

        return encode

    def _manual_rules(
        self, x: CompiledNode, here: str, called: str, resets: dict[int, list[str]]
    ) -> None:
        """ManualSelector (docs/semantics.md, "ManualSelector"): the choice conditions after
        the ``n`` children are asked in order, the first SUCCESS is the pick, none means the last
        pick; a picked child's status is returned; with ``repeat_last_selection`` the first pick
        is kept in ``sel_<id>`` (0: none yet, i + 1: child i), which a halt does not reset."""
        n, repeat_last = x.params
        kids, choices = list(x.children[:n]), list(x.children[n:])
        back = f"{here} & res != NONE"
        sel = f"sel_{x.id}"
        choosing = called
        if n and repeat_last:
            self.var_types[sel] = f"0..{max(n, 1)}"
            self.init[sel] = "0"
            self.kept_vars.append(sel)
            for i, c in enumerate(kids):
                self.call(f"{called} & {sel} = {i + 1}", c)
            choosing = f"{called} & {sel} = 0"
        if n:
            self.rule(self.st(x.id), choosing, "R")

        def pick(cond: str, index: int) -> None:
            if index < n:
                if repeat_last:
                    self.rule(sel, cond, str(index + 1))
                self.call(cond, kids[index])
            else:
                self.ret(cond, x.id, ("S", "F", "R")[index - n])

        if choices:
            self.call(choosing, choices[0])
        else:  # one child under repeat_last_selection: the only pick
            pick(choosing, 0)
        for j, choice in enumerate(choices):
            answered = f"{back} & lidx = {n + j}"
            resets[choice].append(answered)  # a choice keeps no status
            pick(f"{answered} & res = S", j)
            if j + 1 < len(choices):
                self.call(f"{answered} & res != S", choices[j + 1])
            else:
                pick(f"{answered} & res != S", len(choices))
        self.ret(
            f"{back} & lidx < {max(n, 1)}" if n else "FALSE",
            x.id,
            "case res = S : S; res = F : F; TRUE : R; esac",
        )

    def _gate_rules(
        self, x: CompiledNode, rule: str, here: str, called: str, resets: dict[int, list[str]]
    ) -> None:
        """Project wrappers and gated abstractions (docs/semantics.md §10): the gate is the
        last child, a condition leaf the environment answers; only statuses are kept."""
        kids = list(x.children)
        back = f"{here} & res != NONE"
        passed = "case res = S : S; res = F : F; TRUE : R; esac"
        self.rule(self.st(x.id), called, "R")
        gate = kids[-1]
        from_gate = f"{back} & lidx = {len(kids) - 1}"
        resets[gate].append(from_gate)
        if rule == "sleep":
            self.call(called, gate)
            self.ret(f"{from_gate} & res = S", x.id, "S")
            self.ret(from_gate, x.id, "R")
            return
        c = kids[0]
        from_child = f"{back} & lidx = 0"
        if rule == "timeout":  # the gate says the timer fired; not asked on the first tick
            self.call(f"{called} & {self.st(x.id)} != R", c)
            self.call(called, gate)
            resets[c].append(f"{from_gate} & res = S")
            self.ret(f"{from_gate} & res = S", x.id, "F")
            self.call(from_gate, c)
            resets[c].append(f"{from_child} & (res = S | res = F)")
            self.ret(from_child, x.id, passed)
            return
        spec = node_semantics(x.type)
        assert spec is not None and spec.gate is not None
        closed = self._returned_status(x, x.params[0], "", skipped_ok=rule == "gated")
        if rule == "for_each":
            self.call(f"{called} & {self.st(c)} = R", c)
            self.call(called, gate)
            self.call(f"{from_gate} & res = S", c)
            self.ret(from_gate, x.id, closed)
            stop = "F" if closed == _S else "S"
            self.ret(f"{from_child} & res = R", x.id, "R")
            resets[c].append(f"{from_child} & res != R")
            self.ret(f"{from_child} & res = {stop}", x.id, stop)
            self.ret(from_child, x.id, "R")
            return
        gate_rule = spec.gate
        free = []
        if gate_rule.free_when_idle:
            free.append(f"{self.st(x.id)} = I")
        if gate_rule.free_when_running:
            free.append(f"{self.st(c)} = R")
        if free:
            self.call(f"{called} & {any_of(free)}", c)
        self.call(called, gate)
        self.call(f"{from_gate} & res = S", c)
        if gate_rule.halt_on_closed:
            resets[c].append(f"{from_gate} & res = F & {self.st(c)} = R")
        self.ret(from_gate, x.id, closed)
        if gate_rule.reset_on_done:
            resets[c].append(f"{from_child} & (res = S | res = F)")
        self.ret(from_child, x.id, passed)

    def _returned_status(
        self, x: CompiledNode, value: int, when: str, *, skipped_ok: bool = False
    ) -> str:
        """The SMV constant of a status node ``x`` returns by parameter (``value``); IDLE is
        refused, and SKIPPED unless ``skipped_ok`` (a gated node's closed gate, whose parents
        ``_may_skip`` checked)."""
        status = NodeStatus(value).name
        if skipped_ok and status == NodeStatus.SKIPPED.name:
            return _K
        if status not in ST or status == NodeStatus.IDLE.name:
            raise UnsupportedError(
                f"the NuSMV encoding does not support {x.type} returning {status}{when} "
                "(SKIPPED is not encoded); use --engine native",
                location=x.source.location,
                element=f"<{x.type}> '{x.label}'",
            )
        return ST[status]

    def _loop_rules(
        self, x: CompiledNode, here: str, called: str, resets: dict[int, list[str]]
    ) -> None:
        """LoopInt & co (loop_node.h). ``params = (if_empty, length)``: a literal queue keeps
        ``lq`` (elements left, reloaded when the node is ticked while IDLE); a {blackboard}
        queue (``length = -1``) asks its gate, the last child, whether an element is left.
        Either way an element is taken only while the child is not RUNNING."""
        if_empty, length = x.params
        empty = self._returned_status(x, if_empty, " on an empty queue")
        kids = list(x.children)
        c = kids[0]
        back = f"{here} & res != NONE"
        from_child = f"{back} & lidx = 0"
        resumed = f"{called} & {self.st(c)} = R"
        if length < 0:
            gate = kids[-1]
            from_gate = f"{back} & lidx = {len(kids) - 1}"
            resets[gate].append(from_gate)
            self.rule(self.st(x.id), resumed, "R")
            self.call(resumed, c)
            self.call(called, gate)
            opened = f"{from_gate} & res = S"
            self.rule(self.st(x.id), opened, "R")
            self.call(opened, c)
            self.ret(from_gate, x.id, empty)
        else:
            left = self.memory("lq", x.id, length)
            fresh = f"{called} & {self.st(x.id)} = I"
            if length == 0:
                self.ret(fresh, x.id, empty)
            else:
                self.rule(left, fresh, str(length - 1))
                self.rule(self.st(x.id), fresh, "R")
                self.call(fresh, c)
            self.rule(left, resumed, left)  # a RUNNING child: nothing is popped
            self.rule(self.st(x.id), resumed, "R")
            self.call(resumed, c)
            more = f"{called} & {left} > 0"
            self.rule(left, more, f"case {left} > 0 : {left} - 1; TRUE : 0; esac")
            self.rule(self.st(x.id), more, "R")
            self.call(more, c)
            self.ret(called, x.id, empty)
        self.ret(f"{from_child} & res = R", x.id, "R")
        resets[c].append(f"{from_child} & res != R")
        self.ret(f"{from_child} & res = F", x.id, "F")
        self.ret(from_child, x.id, "R")

    def _real_parallel_rules(self, x: CompiledNode, here: str, called: str) -> None:
        """stardust RealParallel: every child ticked in order on every tick, none reset;
        ``pr``/``pf`` remember within the tick whether a child was RUNNING / failed."""
        kids = list(x.children)
        back = f"{here} & res != NONE"
        ran = self.memory("pr", x.id, 1)
        failed = self.memory("pf", x.id, 1)
        self.rule(self.st(x.id), called, "R")
        self.rule(ran, called, "0")
        self.rule(failed, called, "0")
        self.call(called, kids[0])
        for i in range(len(kids)):
            at = f"{back} & lidx = {i}"
            if i + 1 < len(kids):
                self.rule(ran, f"{at} & res = R", "1")
                self.rule(failed, f"{at} & res = F", "1")
                self.call(at, kids[i + 1])
                continue
            self.rule(ran, at, "0")
            self.rule(failed, at, "0")
            status = f"case {ran} = 1 | res = R : R; {failed} = 1 | res = F : F; TRUE : S; esac"
            self.ret(at, x.id, status)

    def _memory_rules(
        self, x: CompiledNode, rule: str, here: str, called: str, resets: dict[int, list[str]]
    ) -> None:
        """PipelineSequence, RecoveryNode, RoundRobin, RepeatUnlessFailureEachTick
        (docs/semantics.md §10; SKIPPED children are not encoded)."""
        kids = list(x.children)
        n = len(kids)
        back = f"{here} & res != NONE"
        self.rule(self.st(x.id), called, "R")

        def reset_all(cond: str) -> None:
            for c in kids:
                resets[c].append(cond)

        passed = "case res = S : S; res = F : F; TRUE : R; esac"
        if rule in ("if_then_else", "while_do_else"):
            # docs/semantics.md §2: IfThenElse keeps the chosen branch (ci), WhileDoElse
            # re-ticks its condition every tick
            memo = self.memory("ci", x.id, n - 1) if rule == "if_then_else" else None
            if memo is not None:
                for i in range(n - 1, 0, -1):
                    self.call(f"{called} & {memo} = {i}", kids[i])
            self.call(called, kids[0])
            from_cond = f"{back} & lidx = 0"
            self.ret(f"{from_cond} & res = R", x.id, "R")
            if memo is not None:
                self.rule(memo, f"{from_cond} & res = S", "1")
            elif n == 3:
                resets[kids[2]].append(f"{from_cond} & res = S")
            self.call(f"{from_cond} & res = S", kids[1])
            if n == 3:
                if memo is not None:
                    self.rule(memo, f"{from_cond} & res = F", "2")
                else:
                    resets[kids[1]].append(f"{from_cond} & res = F")
                self.call(f"{from_cond} & res = F", kids[2])
            else:
                if memo is None:
                    reset_all(f"{from_cond} & res = F")
                self.ret(f"{from_cond} & res = F", x.id, "F")
            from_branch = f"{back} & lidx != 0"
            self.ret(f"{from_branch} & res = R", x.id, "R")
            reset_all(f"{from_branch} & res != R")
            if memo is not None:
                self.rule(memo, f"{from_branch} & res != R", "0")
            self.ret(from_branch, x.id, passed)
            return
        if rule == "pipeline":
            last = self.memory("pl", x.id, n - 1)
            self.call(called, kids[0])
            failed = f"{back} & res = F"
            reset_all(failed)
            self.rule(last, failed, "0")
            self.ret(failed, x.id, "F")
            for i in range(n):
                at = f"{back} & lidx = {i}"
                self.ret(f"{at} & res = R & {last} <= {i}", x.id, "R")
                self.rule(last, f"{at} & res = R & {last} <= {i}", str(i))
                if i + 1 < n:
                    self.call(at, kids[i + 1])  # SUCCESS, or RUNNING before the furthest
                else:
                    reset_all(f"{at} & res = S")  # (res = R returned above)
                    self.rule(last, at, "0")
                    self.ret(at, x.id, "S")
            return
        if rule == "repeat_each_tick":
            (limit,) = x.params
            c = kids[0]
            self.call(called, c)
            self.ret(f"{back} & res = R", x.id, "R")
            done = f"{back} & (res = S | res = F)"
            resets[c].append(done)
            if limit == -1:
                self.ret(f"{back} & res = S", x.id, "R")
                self.ret(back, x.id, "F")
                return
            count = self.memory("rc", x.id, limit - 1)
            self.rule(count, f"{back} & res = F", "0")
            self.ret(f"{back} & res = F", x.id, "F")
            finished = f"{back} & res = S & {count} >= {limit - 1}"
            self.rule(count, finished, "0")
            self.ret(finished, x.id, "S")
            self.rule(count, f"{back} & res = S", _inc(count, limit - 1))
            self.ret(f"{back} & res = S", x.id, "R")
            return
        if rule == "recovery":
            (retries,) = x.params
            main, recovery = kids
            cur = self.memory("ri", x.id, 1)
            tries = self.memory("rt", x.id, max(retries, 0))
            self.call(f"{called} & {cur} = 0", main)
            self.call(called, recovery)
            from_main, from_rec = f"{back} & lidx = 0", f"{back} & lidx = 1"
            for side in (from_main, from_rec):
                self.ret(f"{side} & res = R", x.id, "R")
            won = f"{from_main} & res = S"
            retry = f"{from_main} & res = F & {tries} < {retries}"
            lost = f"({from_main} & res = F & {tries} >= {retries}) | ({from_rec} & res = F)"
            for cond, status in ((won, "S"),):
                reset_all(cond)
                self.rule(cur, cond, "0")
                self.rule(tries, cond, "0")
                self.ret(cond, x.id, status)
            resets[main].append(retry)
            self.rule(cur, retry, "1")
            self.call(retry, recovery)
            reset_all(f"({lost})")
            self.rule(cur, f"({lost})", "0")
            self.rule(tries, f"({lost})", "0")
            self.ret(f"({lost})", x.id, "F")
            recovered = f"{from_rec} & res = S"
            resets[recovery].append(recovered)
            self.rule(cur, recovered, "0")
            self.rule(tries, recovered, _inc(tries, max(retries, 0)))
            self.call(recovered, main)
            return
        # round_robin
        (wrap,) = x.params
        pos = self.memory("rr", x.id, n - 1)
        fails = self.memory("rf", x.id, n)
        for i, c in enumerate(kids):
            self.call(f"{called} & {pos} = {i}", c)
        self.ret(f"{back} & res = R", x.id, "R")
        for i in range(n):
            at = f"{back} & lidx = {i}"
            end = i + 1 == n and not wrap
            nxt = (i + 1) % n
            won, lost = f"{at} & res = S", f"{at} & res = F"
            if end:  # the last child completed without wrap-around: FAILURE (as Nav2 reads)
                reset_all(f"{at} & res != R")
                self.rule(pos, f"{at} & res != R", "0")
                self.rule(fails, f"{at} & res != R", "0")
                self.ret(f"{at} & res != R", x.id, "F")
                continue
            reset_all(won)
            self.rule(pos, won, str(nxt))
            self.rule(fails, won, "0")
            self.ret(won, x.id, "S")
            more = f"{lost} & {fails} < {n - 1}"
            self.rule(pos, more, str(nxt))
            self.rule(fails, more, _inc(fails, n))
            self.call(more, kids[nxt])
            reset_all(lost)
            self.rule(pos, lost, "0")
            self.rule(fails, lost, "0")
            self.ret(lost, x.id, "F")

    def leaf_request(self, nid: int) -> str:
        """The condition: ``cur`` is env leaf ``nid`` asking the environment."""
        x = self.nodes[nid]
        cond = f"cur = {self.n(nid)} & res = NONE"
        if x.kind is NodeKind.ACTION:
            cond += f" & ({self.st(nid)} = I | {self.st(nid)} = R)"
        return f"({cond})"

    def env_leaves(self) -> list[CompiledNode]:
        return [i.node for i in self.info if i.env_leaf]

    def emit(self, module: str, params: str, extra_defines: list[tuple[str, str]]) -> str:
        lines = [f"MODULE {module}({params})", "VAR"]
        for var, typ in self.var_types.items():
            lines.append(f"  {var} : {typ};")
        lines.append("DEFINE")
        for name, expr in self.defines + extra_defines:
            lines.append(f"  {name} := {expr};")
        lines.append("ASSIGN")
        for var in self.var_types:
            lines.append(f"  init({var}) := {self.init[var]};")
            lines.append(f"  next({var}) := {case(self.rules.get(var, []), var)};")
        # NuSMV reserves S, F (and X, G, U, ...) as temporal operators: status constants are
        # written I/R/S/F/NONE above for readability and renamed to safe words here.
        return _SAFE_STATUS.sub(lambda m: "z" + m.group(1), "\n".join(lines) + "\n")


def _inc(var: str, top: int) -> str:
    """``var + 1`` kept inside ``0..top`` (NuSMV checks every assignment's range, even on
    states the rules never reach)."""
    return f"case {var} < {top} : {var} + 1; TRUE : {top}; esac"


_SAFE_STATUS = re.compile(r"(?<![\w$#-])(I|R|S|F|K|NONE)(?![\w$#-])")


def safe_text(text: str) -> str:
    return _SAFE_STATUS.sub(lambda m: "z" + m.group(1), text)


def status_value(smv_value: str) -> str:
    """The readable status constant of a safe one (``zS`` -> ``S``)."""
    return smv_value[1:] if smv_value.startswith("z") else smv_value


def describe_bt(core: BTCore, values: dict[str, str]) -> str:
    """A leaf-machine state as the native checker names it: ``label@path`` or the result."""
    cur = values.get("cur", "")
    if cur.startswith("n") and cur[1:].isdigit():
        node = core.nodes[int(cur[1:])]
        return f"{node.label}@{node.path or 'root'}"
    return {
        "DONE_S": RootResult.SUCCESS.value,
        "DONE_F": RootResult.FAILURE.value,
        "DONE_K": NodeStatus.SKIPPED.name,
    }.get(cur, cur)


class LeafBTEncoder:
    """The BT's leaf-execution machine (``fsmbt.semantics.leaf_machine.LeafMachine``)."""

    def __init__(
        self,
        doc: BTDocument | CompiledTree,
        module: str,
        inputs: Symbols,
        outputs: Symbols,
        *,
        loop: bool,
    ) -> None:
        self.core = BTCore(doc, loop=loop)
        self.module = module
        self.inputs = inputs
        self.outputs = outputs
        self.loop = loop
        inputs.add_all(tuple(o.value for o in LeafOutcome))
        for leaf in self.core.env_leaves():
            outputs.id(leaf.label)
        outputs.add_all(tuple(r.value for r in RootResult))
        if self.core.may_skip[0]:
            outputs.add_all((NodeStatus.SKIPPED.name,))

    def _identity(self) -> list[str]:
        """The variables that make up a state, as the native leaf machine keys it: for a plain
        Sequence/Fallback tree (``leaf_fast``) only the leaf about to be ticked (``cur``; a
        leaf ticked again after ``running`` is the same state there), else every variable
        (the interpreter's snapshot)."""
        from fsmbt.semantics.leaf_fast import is_plain_tree

        return ["cur"] if is_plain_tree(self.core.tree) else self.core.identity_vars()

    def encode(self) -> Encoding:
        from fsmbt.verify.nusmv.encode_fsm import NONE_OUT, Encoding

        core = self.core
        done = ["DONE_S", "DONE_F"] + (["DONE_K"] if core.may_skip[0] else [])
        core.declare(["TOP", *done], core.n(0))
        out_enum = self.outputs.enum([NONE_OUT])
        core.var_types["bres"] = out_enum
        core.init["bres"] = NONE_OUT
        core.build()
        ids = self.inputs
        outcome = {o.value: ST[o.status.name] for o in LeafOutcome}
        requests = []
        for leaf in core.env_leaves():
            req = core.leaf_request(leaf.id)
            requests.append(req)
            for name, status in outcome.items():
                if name == LeafOutcome.RUNNING and leaf.kind is NodeKind.CONDITION:
                    continue
                core.ret(f"go & {req} & inp = {ids.id(name)}", leaf.id, status)
        stable = any_of(requests + [f"cur = {d}" for d in done])
        # the root returned: re-tick on a wake-up, else the tick is over
        top = "cur = TOP"
        core.rule("wake", f"{top} & res = R & wake", "FALSE")
        core.call(f"{top} & res = R", 0)
        words = {_S: RootResult.SUCCESS.value, _F: RootResult.FAILURE.value}
        if core.may_skip[0]:
            words[_K] = NodeStatus.SKIPPED.name
        for status, word in words.items():
            ended = f"{top} & res = {status}"
            core.rules.setdefault("bres", []).append((ended, self.outputs.id(word)))
            if self.loop:
                if status != _K:  # Tree::tickRoot resets a completed root, not a skipped one
                    core.rules.setdefault(core.st(0), []).append((ended, "I"))
                core.call(ended, 0)
            else:
                core.rule("cur", ended, f"DONE_{status}")
                core.rule("res", ended, "NONE")
                core.rule("lidx", ended, "0")
                for var in core.var_types:  # RootResult: nothing else is remembered
                    if var not in ("cur", "res", "lidx", "bres"):
                        core.rules.setdefault(var, []).insert(0, (ended, core.init[var]))
        core.rules.setdefault("bres", []).insert(0, ("go", NONE_OUT))
        label_rows = [
            (req, self.outputs.id(leaf.label)) for req, leaf in zip(requests, core.env_leaves())
        ]
        defines = [
            ("stable", stable),
            ("final", any_of(f"cur = {d}" for d in done)),
            ("o1", "bres"),
            ("o2", case(label_rows, NONE_OUT)),
        ]
        condition_req = any_of(
            r for r, leaf in zip(requests, core.env_leaves()) if leaf.kind is NodeKind.CONDITION
        )
        for symbol, sid in sorted(ids.to_id.items()):
            if symbol == LeafOutcome.RUNNING:
                value = f"(stable & !final & !{condition_req})"
            elif symbol in outcome:
                value = "(stable & !final)"
            else:
                value = "FALSE"
            defines.append((f"offers_{sid}", value))
        text = core.emit(self.module, "go, inp", defines)
        ident = [(v, safe_text(core.var_types[v])) for v in self._identity()]
        return Encoding(
            self.module,
            text,
            ["o1", "o2"],
            list(outcome),
            ident,
            decode_state=lambda values: describe_bt(core, values),
            var_order=list(core.var_types),
        )
