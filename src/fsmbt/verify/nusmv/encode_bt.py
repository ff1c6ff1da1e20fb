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
dispatches on, and the traits its whole-tree checks read (``families.contract.RuleTraits``:
which rules encode a child that returns SKIPPED and which may return it, the frame variables
``idx_n``/``prev_n``, the livelock test's facts), so this module names no node kind and no
rule. Leaf requests are where the environment answers: in a leaf-execution machine
they are the stable states that take an input (success/failure/running); the LEBT encoding
(``encode_lebt``) answers them from its blackboard instead. Supported node types are listed in
``SUPPORTED`` (derived from the registry); anything else raises ``UnsupportedError`` (docs/nusmv.md says why).
Size: O(N · d) SMV text for N nodes of depth d.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import Hint, UnsupportedError
from fsmbt.semantics.bt_interpreter import CompiledNode, CompiledTree
from fsmbt.semantics.nodes import NUSMV_ENCODED, NodeSemantics, all_nodes, node_semantics
from fsmbt.semantics.status import LeafOutcome, NodeStatus, RootResult
from fsmbt.verify.nusmv.families.common import FAILURE, SKIPPED, ST, SUCCESS
from fsmbt.verify.nusmv.families.contract import NO_TRAITS, NusmvRule, Resets, RuleTraits
from fsmbt.verify.nusmv.families.registry import nusmv_rules, rule_traits
from fsmbt.verify.nusmv.smv import Symbols, any_of, case

if TYPE_CHECKING:
    from fsmbt.verify.nusmv.encode_fsm import Encoding

# The encoding rules by node kind, from the registry's ``nusmv`` field.
SUPPORTED = NUSMV_ENCODED
#: type -> why the encoding refuses it
NOT_ENCODED = {n.name: n.nusmv_refusal for n in all_nodes() if n.nusmv_refusal is not None}
#: The SMV type of a stored status (``families.common.ST``).
STATUS_ENUM = "{I, R, S, F}"


@dataclass
class NodeInfo:
    node: CompiledNode
    env_leaf: bool
    internal: str | None  # "S"/"F" for AlwaysSuccess & co
    rule: str | None = None  # the kind's NuSMV rule name (the registry's ``nusmv`` field)
    spec: NodeSemantics | None = None  # the kind's declaration (``None`` for a leaf)
    traits: RuleTraits = NO_TRAITS  # what the whole-tree checks read of the rule


class BTCore:
    """The tick rules of one compiled tree as SMV (shared by the leaf and LEBT encodings).

    ``rules`` collects ``(condition, value)`` pairs per variable in priority order; the caller
    adds its own rules (leaf answers, what happens when the root returns) and emits the module.
    """

    def __init__(
        self,
        doc: BTDocument | CompiledTree,
        *,
        loop: bool,
        own_rules: Mapping[str, NusmvRule] | None = None,
        static_livelock: bool = True,
    ) -> None:
        """``own_rules``: rules by node type for compiled types the registry does not know
        (the outcome pairing's blackboard Switch and Script, ``encode_outcome``); they have
        the default ``RuleTraits``. ``static_livelock=False``: the caller checks livelock
        itself (``encode_outcome``'s exact check), so the static refusal below is skipped."""
        self.tree = doc if isinstance(doc, CompiledTree) else CompiledTree(doc)
        self.nodes = self.tree.nodes
        self.loop = loop
        # One table from NuSMV rule name to the rule (docs/semantics.md "Node families"): the
        # families' rules (``families.registry``: the built-in family modules and any rule
        # registered at run time), read once per encoder.
        self.dispatch: dict[str, NusmvRule] = dict(nusmv_rules())
        own = dict(own_rules or {})
        self.dispatch.update(own)
        self.info: list[NodeInfo] = []
        has_internal = False
        forever = False
        for node in self.nodes:
            if node.kind in (NodeKind.ACTION, NodeKind.CONDITION):
                internal = None
                if node.internal_status is not None:
                    internal = SUCCESS if node.internal_status == NodeStatus.SUCCESS else FAILURE
                    has_internal = True
                self.info.append(NodeInfo(node, internal is None, internal))
                continue
            if node.type in own:
                self.info.append(NodeInfo(node, False, None, node.type))
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
            traits = rule_traits(spec.nusmv)
            # a node that can tick forever (KeepRunningUntilFailure, an endless Repeat/Retry),
            # one that can answer without any leaf (a RunOnce that has run, a zero-count loop):
            # the families say which (``RuleTraits``)
            forever |= traits.ticks_forever is not None and traits.ticks_forever(node, spec)
            alone = traits.answers_alone
            has_internal |= alone is not None and alone(node, spec)
            self.info.append(NodeInfo(node, False, None, spec.nusmv, spec, traits))
        self.may_skip = self._may_skip()
        #: some node may keep its child ticking without end (the livelock test's trigger)
        self.ticks_forever = forever
        if static_livelock and has_internal and (loop or forever) and not self._ticks_a_leaf()[0]:
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
        """Per node: whether it can return SKIPPED (its rule's ``returns_skipped``: RunOnce
        ``then_skip``, a gate closed on SKIPPED; a sequence/reactive node all of whose children
        may skip; a status map or SubTree over one that may). A parent of such a child whose
        rule is not ``skip_aware`` is refused. O(N), children before parents (reverse
        pre-order)."""
        skip = [False] * len(self.nodes)
        for info in reversed(self.info):
            x, spec, traits = info.node, info.spec, info.traits
            if info.rule is None or spec is None:
                continue
            if traits.returns_skipped is not None:
                skip[x.id] = traits.returns_skipped(x, spec, skip)
            aware = traits.skip_aware is not None and traits.skip_aware(x, spec)
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

        The facts of a node with children are its rule's ``leaf_facts`` (``RuleTraits``;
        neither without). O(N)."""
        sure = [False] * len(self.nodes)
        busy = [False] * len(self.nodes)
        for info in reversed(self.info):
            x = info.node
            if info.env_leaf:
                parent = self.info[x.parent].traits if x.parent is not None else NO_TRAITS
                busy[x.id] = True
                sure[x.id] = x.kind is NodeKind.CONDITION or parent.keeps_completed
            elif x.children and info.spec is not None and info.traits.leaf_facts is not None:
                facts = info.traits.leaf_facts(x, info.spec, sure, busy, self.may_skip)
                sure[x.id], busy[x.id] = facts
        return sure

    # -- naming ----------------------------------------------------------------------------
    def n(self, nid: int) -> str:
        return f"n{nid}"

    def st(self, nid: int) -> str:
        return f"st_{nid}"

    def rule(self, var: str, cond: str, value: str) -> None:
        self.rules.setdefault(var, []).append((cond, value))

    def is_seq_like(self, nid: int) -> bool:
        """Whether ``nid``'s frame keeps ``idx_n``, its running child's index (its rule's
        ``RuleTraits.index``: the sequences)."""
        return self.info[nid].traits.index

    def has_prev(self, nid: int) -> bool:
        """Whether ``nid``'s frame keeps ``prev_n``, its child's status when called (its rule's
        ``RuleTraits.prev``: the wake-up test of the sequences and of Repeat/Retry)."""
        return self.info[nid].traits.prev

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
        if status == SKIPPED:  # never stored: the node keeps its status (docs/semantics.md §2)
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

    def build(self, root_reset: str | None = None) -> None:
        """Every node's tick rules, and the halt closure. ``root_reset``: a condition under
        which the root's parent resets it from outside (``haltChild``: ``halt()`` when
        RUNNING, the status reset otherwise; ``encode_local``'s external ``halt`` between
        ticks), joined to ``clr_0`` like any parent's reset."""
        resets: Resets = {x.id: [] for x in self.nodes}  # child -> conditions
        if root_reset is not None:
            resets[0].append(root_reset)
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
            self.dispatch[info.rule](self, x, here, called, resets)
        # halt closure (pre-order ids: a parent's defines come before its children's)
        for x in self.nodes:
            parent_halt = f"hlt_{x.parent}" if x.parent is not None else "FALSE"
            self.defines.append((f"clr_{x.id}", any_of(resets[x.id] + [parent_halt])))
            self.defines.append((f"hlt_{x.id}", f"(clr_{x.id} & {self.st(x.id)} = R)"))
            # a halted node's index is reset (Sequence/Fallback/Async*; not WithMemory)
            spec = self.info[x.id].spec
            if self.is_seq_like(x.id) and spec is not None and not spec.with_memory:
                self.rules.setdefault(f"idx_{x.id}", []).insert(0, (f"hlt_{x.id}", "0"))
        for var, nid in self.memory_vars:
            self.rules.setdefault(var, []).insert(0, (f"hlt_{nid}", "0"))
        for x in self.nodes:
            self.rules.setdefault(self.st(x.id), []).insert(0, (f"clr_{x.id}", "I"))

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
        own_rules: Mapping[str, NusmvRule] | None = None,
        static_livelock: bool = True,
    ) -> None:
        self.core = BTCore(doc, loop=loop, own_rules=own_rules, static_livelock=static_livelock)
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

    # -- what a subclass may change (``encode_outcome``: outcomes as inputs, a blackboard) ----
    def _declare_more(self) -> None:
        """Declare variables of the subclass's own before the tick rules are built."""

    def _answer(self, leaf: CompiledNode, req: str) -> None:
        """The rules of the environment's answer to ``leaf``'s request ``req``: each leaf
        outcome (``running`` for an action only) is the leaf's status."""
        for outcome in LeafOutcome:
            if outcome is LeafOutcome.RUNNING and leaf.kind is NodeKind.CONDITION:
                continue
            status = ST[outcome.status.name]
            self.core.ret(f"go & {req} & inp = {self.inputs.id(outcome.value)}", leaf.id, status)

    def _offers(self, symbol: str, requests: Sequence[str], condition_req: str) -> str:
        """The condition that input ``symbol`` is offered (``requests``: each environment
        leaf's request, ``condition_req`` any condition leaf's)."""
        if symbol == LeafOutcome.RUNNING:
            return f"(stable & !final & !{condition_req})"
        if symbol in self._input_names():
            return "(stable & !final)"
        return "FALSE"

    def _input_names(self) -> list[str]:
        """The inputs the machine may be offered (``Encoding.inputs``)."""
        return [o.value for o in LeafOutcome]

    def encode(self) -> Encoding:
        from fsmbt.verify.nusmv.encode_fsm import NONE_OUT, Encoding

        core = self.core
        done = ["DONE_S", "DONE_F"] + (["DONE_K"] if core.may_skip[0] else [])
        core.declare(["TOP", *done], core.n(0))
        out_enum = self.outputs.enum([NONE_OUT])
        core.var_types["bres"] = out_enum
        core.init["bres"] = NONE_OUT
        self._declare_more()
        core.build()
        ids = self.inputs
        requests = []
        for leaf in core.env_leaves():
            req = core.leaf_request(leaf.id)
            requests.append(req)
            self._answer(leaf, req)
        stable = any_of(requests + [f"cur = {d}" for d in done])
        # the root returned: re-tick on a wake-up, else the tick is over
        top = "cur = TOP"
        core.rule("wake", f"{top} & res = R & wake", "FALSE")
        core.call(f"{top} & res = R", 0)
        words = {SUCCESS: RootResult.SUCCESS.value, FAILURE: RootResult.FAILURE.value}
        if core.may_skip[0]:
            words[SKIPPED] = NodeStatus.SKIPPED.name
        for status, word in words.items():
            ended = f"{top} & res = {status}"
            core.rules.setdefault("bres", []).append((ended, self.outputs.id(word)))
            if self.loop:
                if status != SKIPPED:  # Tree::tickRoot resets a completed root, not a skipped one
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
            defines.append((f"offers_{sid}", self._offers(symbol, requests, condition_req)))
        text = core.emit(self.module, "go, inp", defines)
        ident = [(v, safe_text(core.var_types[v])) for v in self._identity()]
        return Encoding(
            self.module,
            text,
            ["o1", "o2"],
            self._input_names(),
            ident,
            decode_state=lambda values: describe_bt(core, values),
            var_order=list(core.var_types),
        )
