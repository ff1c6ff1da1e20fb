"""A behavior tree's leaf-execution machine as an SMV module by macro steps: one step per leaf
outcome (docs/nusmv.md, "Trees by macro steps"; docs/semantics.md §2, §4).

Why: the micro-step encoding (``encode_bt``) gives every node a status variable and walks the
call stack one node per step; past ~32 leaves NuSMV's model building gives up (a 597-node plain
tree: 1 013 variables, out of time at 60 s). Here a state is only what a leaf request needs:

- ``pos``, an ``unsigned word``: the leaf about to be ticked (leaves numbered in pre-order),
  or ``DONE_S``/``DONE_F`` after the root's result (``loop`` off);
- per plain ``Sequence``/``Fallback`` below a reactive node (2+ children): ``ix_n``, the
  index of its RUNNING child as of its last RUNNING return (0 once it completed or was
  halted); a plain node outside every reactive node is only ever entered fresh (index 0) or
  resumed along the path that returned RUNNING, which ``rt_n`` below jumps over;
- per ``SequenceWithMemory`` (2+ children): ``wi_n``, its index (a halt keeps it, a FAILURE
  keeps it), and ``wr_n``, whether the child at that index is RUNNING (the ``prev == IDLE``
  test of its wake-up);
- ``bres``: the root's result output in this step.

The step is written from the tree's structure and the documented tick rules of each kind
(docs/semantics.md §2, BehaviorTree.CPP 4.8.2), never from the interpreter's tables or the
converter's output. Per node, bottom-up, three DEFINEs say how the node returns in this step:
``rs_n``/``rf_n``/``rr_n`` (SUCCESS/FAILURE/RUNNING), composed from its children's (a leaf's
are ``go & pos = leaf & inp = outcome``). A step ends in exactly one of: a parent entering its
next child (``en_c``, the first leaf a tick of ``c`` reaches, read over the *next* memory), the
root returning SUCCESS/FAILURE, or the root returning RUNNING, after which the tree is ticked
again at once (a RUNNING root result is invisible, docs/semantics.md §3): ``rt_n`` is where
that re-tick lands, the topmost reactive ancestor on the RUNNING path restarting at its child
0 (``en``) or, without one, the leaf that returned RUNNING (the plain nodes resume their
running child) or the WithMemory node's next child after a wake-up. Halts are a
combinational closure ``hz_n`` (an ancestor halts ``n``'s branch in this step: a reactive
node's RUNNING or stopping child halts every other child), which clears ``ix``/``wr`` below;
``wi`` survives halts (``halt_resets_memory`` false for SequenceWithMemory).

Facts of this node class the encoding rests on (docs/semantics.md §4a, "Soundness"): every
tick of a node ticks a leaf (only environment leaves are accepted), no node returns SKIPPED, a
completed node has reset its children, a RUNNING node's parent is RUNNING, and a plain
node's index is non-zero only while it is RUNNING - so halting a branch is "clear every
``ix``/``wr`` in it", and a wake-up always reaches the root (every kind passes RUNNING up).

Supported kinds: ``SUPPORTED``; anything else is refused by name (``UnsupportedError``; the
micro-step encoder stays the fallback). Size: O(N) DEFINEs of O(children) each, one case row
per memory variable and child; the state has ceil(log2(leaves + 2)) + sum of memory bits.
"""

from __future__ import annotations

from dataclasses import dataclass

from fsmbt.model.bt import BTDocument
from fsmbt.model.bt_nodes import NodeKind
from fsmbt.model.errors import FsmbtError, Hint, UnsupportedError
from fsmbt.semantics.bt_interpreter import CompiledNode, CompiledTree
from fsmbt.semantics.status import LeafOutcome, RootResult
from fsmbt.verify.nusmv.encode_fsm import NONE_OUT, Encoding, enum_bits
from fsmbt.verify.nusmv.smv import Symbols, any_of, case

SEQUENCE, FALLBACK, MEMORY = "sequence", "fallback", "memory"
R_SEQUENCE, R_FALLBACK = "reactive_sequence", "reactive_fallback"
INVERTER, FORCE_SUCCESS, FORCE_FAILURE, PASS = "inverter", "force_success", "force_failure", "pass"

#: node type -> its tick rule here (docs/semantics.md §2)
SUPPORTED: dict[str, str] = {
    "Sequence": SEQUENCE,
    "Fallback": FALLBACK,
    "SequenceWithMemory": MEMORY,
    "ReactiveSequence": R_SEQUENCE,
    "ReactiveFallback": R_FALLBACK,
    "Inverter": INVERTER,
    "ForceSuccess": FORCE_SUCCESS,
    "ForceFailure": FORCE_FAILURE,
    "SubTree": PASS,
}
REACTIVE = frozenset({R_SEQUENCE, R_FALLBACK})
#: what each decorator returns for its child's SUCCESS and FAILURE
_MAPS = {
    INVERTER: ("F", "S"),
    FORCE_SUCCESS: ("S", "S"),
    FORCE_FAILURE: ("F", "F"),
    PASS: ("S", "F"),
}
ENCODING_NAME = "macro-step tree (encode_macro)"


def refusal(doc: BTDocument | CompiledTree) -> str | None:
    """Why the macro-step encoding does not apply to ``doc`` (the first node it does not
    model, named), or ``None`` when it does. O(N)."""
    try:
        tree = doc if isinstance(doc, CompiledTree) else CompiledTree(doc)
    except FsmbtError as exc:  # a tree the interpreter does not compile (a dispatch tree's
        return f"not a tree the interpreter compiles: {exc}"  # Switch): other encoders
    for node in tree.nodes:
        if node.kind in (NodeKind.ACTION, NodeKind.CONDITION):
            if node.internal_status is not None:
                return (
                    f"<{node.type}> '{node.label}': internal leaves are not encoded by macro steps"
                )
            continue
        if node.type not in SUPPORTED:
            return f"<{node.type}> '{node.label}': not encoded by macro steps"
        if not node.children:
            return f"<{node.type}> '{node.label}': a control without children"
    return None


def applies(doc: BTDocument | CompiledTree) -> bool:
    return refusal(doc) is None


@dataclass
class _Plan:
    """The tree's facts the text is written from (pre-order arrays, computed once)."""

    kind: list[str]  # SUPPORTED rule, or "leaf"
    leaf_code: dict[int, int]  # leaf node id -> its position number
    first: list[int]  # per node: the first leaf position of its subtree
    last: list[int]  # per node: the last leaf position of its subtree
    ix: set[int]  # plain nodes with an ``ix_n``
    wm: set[int]  # WithMemory nodes with ``wi_n``/``wr_n``


class MacroBTEncoder:
    """The leaf-execution machine (``fsmbt.semantics.leaf_machine.LeafMachine``) by macro
    steps; same module interface and outputs as ``encode_bt.LeafBTEncoder`` (``o1`` the root's
    result, ``o2`` the next leaf's label)."""

    def __init__(
        self,
        doc: BTDocument | CompiledTree,
        module: str,
        inputs: Symbols,
        outputs: Symbols,
        *,
        loop: bool,
    ) -> None:
        self.tree = doc if isinstance(doc, CompiledTree) else CompiledTree(doc)
        why = refusal(self.tree)
        if why is not None:
            raise UnsupportedError(
                f"the macro-step NuSMV encoding does not support {why}",
                element=self.tree.nodes[0].label,
                hints=(Hint.NATIVE_VERIFIER,),
            )
        self.nodes = self.tree.nodes
        self.module = module
        self.inputs = inputs
        self.outputs = outputs
        self.loop = loop
        inputs.add_all(tuple(o.value for o in LeafOutcome))
        self.leaves = [n for n in self.nodes if n.is_env_leaf]
        for leaf in self.leaves:
            outputs.id(leaf.label)
        outputs.add_all(tuple(r.value for r in RootResult))
        self.plan = self._plan()
        count = len(self.leaves) + 2  # the leaves, DONE_S, DONE_F
        self.bits = max(1, (count - 1).bit_length())
        self.done_s = self.code(len(self.leaves))
        self.done_f = self.code(len(self.leaves) + 1)

    # -- facts ---------------------------------------------------------------------------
    def _plan(self) -> _Plan:
        nodes = self.nodes
        kind = [
            "leaf" if n.kind in (NodeKind.ACTION, NodeKind.CONDITION) else SUPPORTED[n.type]
            for n in nodes
        ]
        leaf_code = {leaf.id: i for i, leaf in enumerate(self.leaves)}
        first = [0] * len(nodes)
        last = [0] * len(nodes)
        for node in reversed(nodes):  # children (higher pre-order ids) first
            if node.id in leaf_code:
                first[node.id] = last[node.id] = leaf_code[node.id]
            else:
                first[node.id] = first[node.children[0]]
                last[node.id] = last[node.children[-1]]
        under = [False] * len(nodes)  # a proper ancestor is reactive
        for node in nodes:  # parents first
            if node.parent is not None:
                under[node.id] = under[node.parent] or kind[node.parent] in REACTIVE
        ix = {
            n.id
            for n in nodes
            if kind[n.id] in (SEQUENCE, FALLBACK) and under[n.id] and len(n.children) > 1
        }
        wm = {n.id for n in nodes if kind[n.id] == MEMORY and len(n.children) > 1}
        return _Plan(kind, leaf_code, first, last, ix, wm)

    def code(self, number: int) -> str:
        return f"0ud{self.bits}_{number}"

    def _within(self, nid: int) -> str:
        """``pos`` is a leaf of ``nid``'s subtree (a range of pre-order leaf numbers)."""
        a, b = self.plan.first[nid], self.plan.last[nid]
        if a == b:
            return f"pos = {self.code(a)}"
        return f"(pos >= {self.code(a)} & pos <= {self.code(b)})"

    # -- the text --------------------------------------------------------------------------
    def encode(self) -> Encoding:
        plan, nodes = self.plan, self.nodes
        ids = self.inputs
        out_enum = self.outputs.enum([NONE_OUT])
        var_types: dict[str, str] = {"pos": f"unsigned word[{self.bits}]", "bres": out_enum}
        init: dict[str, str] = {
            "pos": self.code(plan.leaf_code[self._first_leaf(0)]),
            "bres": NONE_OUT,
        }
        for node in nodes:
            if node.id in plan.ix:
                var_types[f"ix_{node.id}"] = f"0..{len(node.children) - 1}"
                init[f"ix_{node.id}"] = "0"
            if node.id in plan.wm:
                var_types[f"wi_{node.id}"] = f"0..{len(node.children) - 1}"
                init[f"wi_{node.id}"] = "0"
                var_types[f"wr_{node.id}"] = "boolean"
                init[f"wr_{node.id}"] = "FALSE"
        defines: list[tuple[str, str]] = []
        rules: dict[str, list[tuple[str, str]]] = {var: [] for var in var_types}
        enters: list[tuple[str, str]] = []  # (condition, next position): a parent's next child
        outcome = {o: ids.id(o.value) for o in LeafOutcome}
        for node in reversed(nodes):  # the return defines, children first
            n, k = node.id, plan.kind[node.id]
            if k == "leaf":
                here = f"go & pos = {self.code(plan.leaf_code[n])}"
                defines.append((f"rs_{n}", f"({here} & inp = {outcome[LeafOutcome.SUCCESS]})"))
                defines.append((f"rf_{n}", f"({here} & inp = {outcome[LeafOutcome.FAILURE]})"))
                running = (
                    "FALSE"
                    if node.kind is NodeKind.CONDITION
                    else f"({here} & inp = {outcome[LeafOutcome.RUNNING]})"
                )
                defines.append((f"rr_{n}", running))
                defines.append((f"rt_{n}", self.code(plan.leaf_code[n])))
                continue
            defines += self._returns(node, k, enters, rules)
        # entering (over the next memory) and the halt closure, parents first
        for node in nodes:
            defines.append((f"en_{node.id}", self._enter(node)))
            defines.append((f"hz_{node.id}", self._halted(node)))
        root_done = "(rs_0 | rf_0)"
        if self.loop:  # Tree::tickRoot ticks the completed root again at once
            rows = [(root_done, "en_0")]
        else:
            rows = [("rs_0", self.done_s), ("rf_0", self.done_f)]
        rows.append(("rr_0", "rt_0"))
        rules["pos"] = rows + enters
        rules["bres"] = [
            ("rs_0", self.outputs.id(RootResult.SUCCESS.value)),
            ("rf_0", self.outputs.id(RootResult.FAILURE.value)),
            ("go", NONE_OUT),
        ]
        if not self.loop:  # a root result ends the run: nothing else is remembered
            for var in var_types:
                if var not in ("pos", "bres"):
                    rules[var].insert(0, (root_done, init[var]))
        final = f"(pos = {self.done_s} | pos = {self.done_f})"
        conditions = [
            f"pos = {self.code(plan.leaf_code[leaf.id])}"
            for leaf in self.leaves
            if leaf.kind is NodeKind.CONDITION
        ]
        labels = [
            (f"pos = {self.code(plan.leaf_code[leaf.id])}", self.outputs.id(leaf.label))
            for leaf in self.leaves
        ]
        defines += [
            ("stable", "TRUE"),
            ("final", final),
            ("o1", "bres"),
            ("o2", case(labels, NONE_OUT)),
            ("at_condition", any_of(conditions)),
        ]
        names = {o.value for o in LeafOutcome}
        for symbol, sid in sorted(ids.to_id.items()):
            if symbol == LeafOutcome.RUNNING.value:
                offered = "(!final & !at_condition)"
            else:
                offered = "!final" if symbol in names else "FALSE"
            defines.append((f"offers_{sid}", offered))
        identity, canon = self._identity()
        defines += canon
        lines = [f"MODULE {self.module}(go, inp)", "VAR"]
        lines += [f"  {var} : {typ};" for var, typ in var_types.items()]
        lines += ["INVAR", f"  pos <= {self.done_f};", "DEFINE"]
        lines += [f"  {name} := {expr};" for name, expr in defines]
        lines.append("ASSIGN")
        for var in var_types:
            lines.append(f"  init({var}) := {init[var]};")
            lines.append(f"  next({var}) := {case(rules[var], var)};")
        names_of = {self.code(plan.leaf_code[leaf.id]): leaf for leaf in self.leaves}
        count = len(self.leaves) + 2

        def decode(values: dict[str, str]) -> str:
            pos = values.get("pos", "")
            if pos == self.done_s:
                return RootResult.SUCCESS.value
            if pos == self.done_f:
                return RootResult.FAILURE.value
            leaf = names_of.get(pos)
            return "?" if leaf is None else f"{leaf.label}@{leaf.path or 'root'}"

        return Encoding(
            self.module,
            "\n".join(lines) + "\n",
            ["o1", "o2"],
            [o.value for o in LeafOutcome],
            identity,
            decode_state=decode,
            var_order=list(var_types),
            # a tree without memory: its state is ``pos`` alone, listed for the per-state
            # reachability runs (``reach``)
            id_values=[self.code(i) for i in range(count)] if len(identity) == 1 else [],
            position=("pos", self.bits),
            output_words=[("bres", enum_bits(out_enum))],
            interleave=True,
            id_near={v: v[1:] for v, _ in identity if v.startswith("c")},
        )

    def _first_leaf(self, nid: int) -> int:
        """The leaf a fresh tick of ``nid`` reaches first with every memory at its start
        (index 0 everywhere): child 0 down to a leaf. O(depth)."""
        node = self.nodes[nid]
        while node.children:
            node = self.nodes[node.children[0]]
        return node.id

    def _returns(
        self,
        node: CompiledNode,
        kind: str,
        enters: list[tuple[str, str]],
        rules: dict[str, list[tuple[str, str]]],
    ) -> list[tuple[str, str]]:
        """``node``'s return defines ``rs/rf/rr``, its resume target ``rt``, the rows of
        ``enters`` where it ticks its next child, and the rules of its own memory (§2)."""
        n = node.id
        kids = node.children
        rs = [f"rs_{c}" for c in kids]
        rf = [f"rf_{c}" for c in kids]
        rr = [f"rr_{c}" for c in kids]
        resume = case([(f"rr_{c}", f"rt_{c}") for c in kids], "pos")
        if kind in _MAPS:
            on_s, on_f = _MAPS[kind]
            child = kids[0]
            succ = [f"rs_{child}"] if on_s == "S" else []
            succ += [f"rf_{child}"] if on_f == "S" else []
            fail = [f"rs_{child}"] if on_s == "F" else []
            fail += [f"rf_{child}"] if on_f == "F" else []
            return [
                (f"rs_{n}", any_of(succ)),
                (f"rf_{n}", any_of(fail)),
                (f"rr_{n}", f"rr_{child}"),
                (f"rt_{n}", f"rt_{child}"),
            ]
        # the status that moves a sequence-like node to its next child, and the one it stops on
        go_on, stop = (rs, rf) if kind in (SEQUENCE, MEMORY, R_SEQUENCE) else (rf, rs)
        go_on_last = go_on[-1]
        ticking_on = [(go_on[i], f"en_{kids[i + 1]}") for i in range(len(kids) - 1)]
        running = list(rr)
        if kind == MEMORY and n in self.plan.wm:
            wr = f"wr_{n}"
            # a synchronous success (the child was IDLE) with more to go: wake-up, RUNNING
            running += [f"({go_on[i]} & !{wr})" for i in range(len(kids) - 1)]
            ticking_on = [(f"({cond} & {wr})", target) for cond, target in ticking_on]
            resume = case([(f"rr_{c}", f"rt_{c}") for c in kids], f"en_{n}")
            rules[f"wi_{n}"] = [(go_on[i], str(i + 1)) for i in range(len(kids) - 1)]
            rules[f"wi_{n}"].append((go_on_last, "0"))
            rules[wr] = [(f"hz_{n}", "FALSE"), (any_of(rr), "TRUE"), (any_of(rs + rf), "FALSE")]
        if kind in REACTIVE:
            resume = f"en_{n}"
        if n in self.plan.ix:
            var = f"ix_{n}"
            rules[var] = [(f"hz_{n}", "0")]
            rules[var] += [(f"rr_{c}", str(i)) for i, c in enumerate(kids)]
            rules[var].append((any_of(rs + rf), "0"))
        enters += ticking_on
        returns = [
            (f"r{'s' if go_on is rs else 'f'}_{n}", go_on_last),
            (f"r{'f' if go_on is rs else 's'}_{n}", any_of(stop)),
            (f"rr_{n}", any_of(running)),
            (f"rt_{n}", resume),
        ]
        if kind in REACTIVE:  # a RUNNING or stopping child halts every other child
            returns.append((f"hx_{n}", any_of(rr + stop)))
        return returns

    def _enter(self, node: CompiledNode) -> str:
        """The first leaf a tick of ``node`` reaches now, over the memory after this step."""
        kind = self.plan.kind[node.id]
        if kind == "leaf":
            return self.code(self.plan.leaf_code[node.id])
        kids = node.children
        var = None
        if node.id in self.plan.ix:
            var = f"ix_{node.id}"
        elif node.id in self.plan.wm:
            var = f"wi_{node.id}"
        if var is None:  # fresh (index 0), reactive, decorator
            return f"en_{kids[0]}"
        rows = [(f"next({var}) = {i}", f"en_{c}") for i, c in enumerate(kids[:-1])]
        return case(rows, f"en_{kids[-1]}")

    def _halted(self, node: CompiledNode) -> str:
        """``hz_n``: an ancestor halts ``node``'s branch in this step."""
        parent = node.parent
        if parent is None:
            return "FALSE"
        if self.plan.kind[parent] in REACTIVE:
            mine = (
                f"rr_{node.id} | r{'f' if self.plan.kind[parent] == R_SEQUENCE else 's'}_{node.id}"
            )
            return f"(hz_{parent} | (hx_{parent} & !({mine})))"
        return f"hz_{parent}"

    def _identity(self) -> tuple[list[tuple[str, str]], list[tuple[str, str]]]:
        """The state's identity (``Encoding.id_vars``) and the DEFINEs it reads: ``pos`` and
        each memory variable as the native checker's canonical state keeps it
        (docs/semantics.md §4a): an ``ix_n`` only off the path to ``pos`` (on it, the path
        says the index and the variable is unread), a ``wr_n`` only when its index is not the
        last child (rule 2: that ``prev`` is never read)."""
        ident = [("pos", f"unsigned word[{self.bits}]")]
        defines: list[tuple[str, str]] = []
        for node in self.nodes:
            n = node.id
            top = len(node.children) - 1
            if n in self.plan.ix:
                defines.append((f"cix_{n}", f"case {self._within(n)} : 0; TRUE : ix_{n}; esac"))
                ident.append((f"cix_{n}", f"0..{top}"))
            if n in self.plan.wm:
                ident.append((f"wi_{n}", f"0..{top}"))
                defines.append((f"cwr_{n}", f"(wr_{n} & wi_{n} != {top})"))
                ident.append((f"cwr_{n}", "boolean"))
        return ident, defines


def leaf_count(doc: BTDocument | CompiledTree) -> int:
    tree = doc if isinstance(doc, CompiledTree) else CompiledTree(doc)
    return sum(1 for n in tree.nodes if n.is_env_leaf)
