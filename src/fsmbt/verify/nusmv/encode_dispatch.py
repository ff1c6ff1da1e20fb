"""A dispatch tree (docs/semantics.md §12 and §12a) as an SMV module of its macro steps
(docs/nusmv.md, "The dispatch form").

Written from the tree's structure and BehaviorTree.CPP 4.8.2's rules of its built-in nodes,
not from the converter and not from the native machine's explored graph:

- the blackboard entries the tree writes (every key of a ``DispatchEntry``'s ``_onSuccess``;
  the digits ``fsm_d0``.. and ``fsm_d_<level>_J``) are enum variables ``b<k>``: ``unset`` or one
  of the literals the tree writes to that key (and ``a``..``g``); ``event`` is the input;
- a tick of the nodes the encoding accepts (``fsmbt.semantics.dispatch_memoryless``: ``Switch``,
  ``KeepRunningUntilFailure``, ``ReactiveFallback``, ``SubTree``, ``AlwaysSuccess``,
  ``AlwaysFailure``, ``DispatchEntry``) is a function of those entries and the event, so it is
  written as DEFINEs, children before parents: ``s_n``/``f_n`` (node ``n`` returns SUCCESS /
  FAILURE; RUNNING otherwise) and, parents before children, ``h_n`` (the tick reaches ``n``).
  ``Switch``: the first case equal to the entry's value, else the default (an unset entry or an
  unset ``event`` equals no case); ``KeepRunningUntilFailure``: SUCCESS becomes RUNNING;
  ``ReactiveFallback``: the first child that does not fail; ``SubTree``: its child's;
  ``DispatchEntry``: SUCCESS, then its ``_onSuccess`` writes;
- a macro step (input ``inp`` = the event, ``go``): the ``DispatchEntry`` the tick reaches
  (at most one, ``dispatch_memoryless``) writes its assignments and outputs its ``action``
  (slot ``o1``); ``fin`` holds whether the root returned SUCCESS. The start tick (every entry
  and ``event`` unset) is evaluated here by the same rules to give the initial values.

``stable`` is always true (one tick per input), ``final`` is ``fin`` (the tree has terminated
when the last tick returned SUCCESS), every event of the alphabet is offered (the native
``DispatchMachine`` takes every event; an ignored one keeps the state). So the product's five
properties read the same states, outputs and statuses as the native pairing "FSM ~ dispatch
BT (macro steps)" (docs/verification.md §2); a state's identity is the entries and ``fin``.
Size: O(nodes x cases) SMV text, one variable per written key.
"""

from __future__ import annotations

from collections.abc import Sequence

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import Hint, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.compiled import SUCCESS, CompiledNode
from fsmbt.semantics.dispatch_memoryless import KEEP_RUNNING, REACTIVE_FALLBACK, memory_refusal
from fsmbt.semantics.dispatch_runtime import (
    DIGIT_PREFIX,
    DIGITS,
    EVENT_KEY,
    DispatchMachine,
    is_dispatch_bt,
)
from fsmbt.semantics.machine import FSMMachine
from fsmbt.semantics.outcome_blackboard import SWITCH
from fsmbt.verify.nusmv.encode_fsm import NONE_OUT, Encoding, FSMEncoder
from fsmbt.verify.nusmv.smv import Symbols, all_of, any_of, case

UNSET = "bu"

#: A valuation of the written entries (``None``: unset) and the pending event.
Valuation = dict[str, str | None]


class DispatchEncoder:
    """The macro-step machine of a dispatch tree (see the module docstring).

    Raises ``UnsupportedError`` (node named, with its location) for a node the encoding does
    not model, and the native machine's ``InputError``/``UnsupportedError`` for what no
    dispatch tree may hold (another leaf type, a post-condition other than a
    ``DispatchEntry``'s ``_onSuccess`` of ``KEY:='literal'`` assignments)."""

    def __init__(
        self,
        doc: BTDocument,
        module: str,
        inputs: Symbols,
        outputs: Symbols,
        *,
        alphabet: Sequence[str],
        parsed: DispatchMachine | None = None,
    ) -> None:
        # the form's checks and tables (leaf type, post-conditions, entries, _onSuccess writes);
        # no tick is taken (``parsed``: ``doc``'s, when the caller already built it)
        if parsed is None:
            parsed = DispatchMachine(doc, ())
        self.tree = parsed.tree
        refused = memory_refusal(self.tree)
        if refused is not None:
            node, why = refused
            raise UnsupportedError(
                f"the NuSMV encoding of the dispatch form does not support {node.source.type}: "
                f"{why}",
                location=node.source.location,
                element=f"<{node.source.type}> '{node.label}'",
                hints=(Hint.NATIVE_VERIFIER,),
            )
        self.nodes = self.tree.nodes
        self.module = module
        self.inputs = inputs
        self.outputs = outputs
        self.alphabet = list(alphabet)
        self._offered = frozenset(self.alphabet)
        inputs.add_all(self.alphabet)
        self.entries = parsed.entries  # node id -> (state port, action or None)
        self.writes: dict[int, dict[str, str]] = {}
        values: dict[str, dict[str, None]] = {}
        for nid, pairs in parsed.on_success.items():
            written = {k: v for k, v in pairs if k != EVENT_KEY}  # event is unset after a tick
            self.writes[nid] = written
            for key, value in written.items():
                values.setdefault(key, dict.fromkeys(DIGITS)).setdefault(value, None)
        #: key -> (SMV variable, value symbols); only keys the tree writes can hold a value
        self.keys: dict[str, tuple[str, Symbols]] = {}
        for k, key in enumerate(sorted(values)):
            table = Symbols(f"b{k}v")
            table.add_all(values[key])
            self.keys[key] = (f"b{k}", table)
        for _state, action in self.entries.values():
            if action is not None:
                outputs.id(action)
        self._paths = self._entry_paths()

    # -- one tick: as SMV expressions (the module) and on concrete values (the start tick) ------
    def _eq_smv(self, key: str, value: str) -> str:
        if key == EVENT_KEY:
            sid = self.inputs.to_id.get(value)
            return "FALSE" if sid is None or value not in self._offered else f"inp = {sid}"
        found = self.keys.get(key)
        if found is None or value not in found[1].to_id:
            return "FALSE"
        return f"{found[0]} = {found[1].id(value)}"

    def _switch_rows(self, node: CompiledNode, eq: list[str]) -> list[str]:
        """Per child of a Switch: the condition that the tick takes it (the first equal
        case, else the default)."""
        return [
            all_of([*(_not(e) for e in eq[:i]), eq[i] if i < len(eq) else "TRUE"])
            for i in range(len(node.children))
        ]

    def _smv_tick(self) -> list[tuple[str, str]]:
        """DEFINEs ``s_n``, ``f_n`` (children first) and ``h_n`` (parents first)."""
        defines: list[tuple[str, str]] = []
        take: dict[int, list[str]] = {}
        for node in reversed(self.nodes):
            n, kids = node.id, node.children
            if node.type == SWITCH:
                key, cases = node.params
                rows = self._switch_rows(node, [self._eq_smv(key, c) for c in cases])
                take[n] = rows
                s = any_of(all_of([r, f"s_{c}"]) for r, c in zip(rows, kids))
                f = any_of(all_of([r, f"f_{c}"]) for r, c in zip(rows, kids))
            elif node.type == KEEP_RUNNING:
                s, f = "FALSE", f"f_{kids[0]}"
            elif node.type == REACTIVE_FALLBACK:
                s = any_of(
                    all_of([*(f"f_{c}" for c in kids[:i]), f"s_{kids[i]}"])
                    for i in range(len(kids))
                )
                f = all_of(f"f_{c}" for c in kids)
            elif node.kind is NodeKind.SUBTREE:
                s, f = f"s_{kids[0]}", f"f_{kids[0]}"
            elif node.internal_status is not None:
                ok = node.internal_status == SUCCESS
                s, f = ("TRUE", "FALSE") if ok else ("FALSE", "TRUE")
            else:  # DispatchEntry
                s, f = "TRUE", "FALSE"
            defines += [(f"f_{n}", f), (f"s_{n}", s)]
        defines.reverse()  # s_n/f_n only read children's: any order is fine for NuSMV
        defines.append(("h_0", "TRUE"))
        for node in self.nodes:
            for i, c in enumerate(node.children):
                if node.type == SWITCH:
                    reach = all_of([f"h_{node.id}", take[node.id][i]])
                elif node.type == REACTIVE_FALLBACK:
                    reach = all_of([f"h_{node.id}", *(f"f_{k}" for k in node.children[:i])])
                else:
                    reach = f"h_{node.id}"
                defines.append((f"h_{c}", reach))
        return defines

    def concrete_tick(self, env: Valuation, event: str | None) -> tuple[bool, int | None]:
        """One tick by the same rules on concrete values: (root returned SUCCESS, the
        ``DispatchEntry`` reached or ``None``). Two passes over the nodes, O(nodes x cases)."""
        succ: dict[int, bool] = {}
        fail: dict[int, bool] = {}
        take: dict[int, int] = {}
        for node in reversed(self.nodes):
            n, kids = node.id, node.children
            if node.type == SWITCH:
                key, cases = node.params
                value = event if key == EVENT_KEY else env.get(key)
                i = cases.index(value) if value in cases else len(cases)
                take[n] = i
                succ[n], fail[n] = succ[kids[i]], fail[kids[i]]
            elif node.type == KEEP_RUNNING:
                succ[n], fail[n] = False, fail[kids[0]]
            elif node.type == REACTIVE_FALLBACK:
                first = next((c for c in kids if not fail[c]), None)
                succ[n], fail[n] = first is not None and succ[first], first is None
            elif node.kind is NodeKind.SUBTREE:
                succ[n], fail[n] = succ[kids[0]], fail[kids[0]]
            elif node.internal_status is not None:
                succ[n] = node.internal_status == SUCCESS
                fail[n] = not succ[n]
            else:
                succ[n], fail[n] = True, False
        nid: int | None = 0
        while nid is not None and nid not in self.entries:  # the path the tick takes
            node = self.nodes[nid]
            if not node.children:
                nid = None
            elif node.type == SWITCH:
                nid = node.children[take[nid]]
            elif node.type == REACTIVE_FALLBACK:
                nid = next((c for c in node.children if not fail[c]), None)
            else:
                nid = node.children[0]
        return succ[0], nid

    # -- the module ----------------------------------------------------------------------------
    def encode(self) -> Encoding:
        started, entered = self.concrete_tick({}, None)
        start_env = dict(self.writes.get(entered, {})) if entered is not None else {}
        out_enum = self.outputs.enum([NONE_OUT])
        lines = [f"MODULE {self.module}(go, inp)", "VAR"]
        order = []
        for var, table in self.keys.values():
            lines.append(f"  {var} : {table.enum([UNSET])};")
            order.append(var)
        lines += [f"  o1 : {out_enum};", "  fin : boolean;", "DEFINE"]
        lines += [f"  {name} := {expr};" for name, expr in self._smv_tick()]
        lines += ["  stable := TRUE;", "  final := fin;"]
        for symbol, sid in sorted(self.inputs.to_id.items()):
            lines.append(f"  offers_{sid} := {'TRUE' if symbol in self._offered else 'FALSE'};")
        lines.append("ASSIGN")
        for key, (var, table) in self.keys.items():
            rows = [
                (f"go & h_{nid}", table.id(written[key]))
                for nid, written in self.writes.items()
                if key in written
            ]
            first = start_env.get(key)
            lines.append(f"  init({var}) := {UNSET if first is None else table.id(first)};")
            lines.append(f"  next({var}) := {case(rows, var)};")
        outs = [
            (f"go & h_{nid}", self.outputs.id(action))
            for nid, (_state, action) in self.entries.items()
            if action is not None
        ]
        first_out = NONE_OUT
        if entered is not None and self.entries[entered][1] is not None:
            first_out = self.outputs.id(self.entries[entered][1] or "")
        lines += [
            f"  init(o1) := {first_out};",
            f"  next(o1) := {case(outs + [('go', NONE_OUT)], 'o1')};",
            f"  init(fin) := {'TRUE' if started else 'FALSE'};",
            "  next(fin) := case go : s_0; TRUE : fin; esac;",
        ]
        ident = [(var, table.enum([UNSET])) for var, table in self.keys.values()]
        return Encoding(
            self.module,
            "\n".join(lines) + "\n",
            ["o1"],
            list(self.alphabet),
            [*ident, ("fin", "boolean")],
            decode_state=self.describe,
            var_order=[*order, "fin", "o1"],
        )

    # -- traces --------------------------------------------------------------------------------
    def _entry_paths(self) -> dict[int, list[tuple[str, tuple[str, ...], int]]]:
        """Per ``DispatchEntry``: the index reads on its path that it does not overwrite,
        ``(key, cases, child index taken)`` (a ``Switch`` on a written key, not ``event``)."""
        paths: dict[int, list[tuple[str, tuple[str, ...], int]]] = {}
        for nid in self.entries:
            written = self.writes.get(nid, {})
            reads = []
            child, parent = nid, self.nodes[nid].parent
            while parent is not None:
                node = self.nodes[parent]
                if node.type == SWITCH and node.params[0] in self.keys:
                    if node.params[0] not in written:
                        reads.append((node.params[0], node.params[1], self.nodes[child].index))
                child, parent = parent, node.parent
            paths[nid] = reads
        return paths

    def valuation(self, values: dict[str, str]) -> Valuation:
        """The entries' values in a trace state (``None``: unset)."""
        env: Valuation = {}
        for key, (var, table) in self.keys.items():
            smv = values.get(var, UNSET)
            env[key] = None if smv == UNSET else table.name(smv)
        return env

    def describe(self, values: dict[str, str]) -> str:
        """A state's name as the native machine gives it: the ``state`` port of a
        ``DispatchEntry`` that writes this index (its writes and the index reads on its path
        agree with it; the first in tree order), else the digits, most significant first
        (``start`` when none is set)."""
        env = self.valuation(values)
        for nid, (state, _action) in self.entries.items():
            if not state or any(env.get(k) != v for k, v in self.writes.get(nid, {}).items()):
                continue
            if all(
                (cases.index(env[key]) if env[key] in cases else len(cases)) == taken
                for key, cases, taken in self._paths[nid]
            ):
                return state
        digits = [v for k, v in sorted(env.items()) if k.startswith(DIGIT_PREFIX) and v]
        return "".join(reversed(digits)) or "start"


def _not(expr: str) -> str:
    return {"TRUE": "FALSE", "FALSE": "TRUE"}.get(expr, f"!({expr})")


def encode_dispatch_pair(
    source: FSM | BTDocument, result: FSM | BTDocument, inputs: Symbols, outputs: Symbols
) -> tuple[FSMEncoder | DispatchEncoder, FSMEncoder | DispatchEncoder] | None:
    """The (source, result) encoders of an FSM and a dispatch tree in either order, over the
    union of the FSM's events and the events the tree's switches test (as
    ``fsmbt.semantics.dispatch_runtime.machines_for_dispatch``); ``None`` for any other pair."""
    if isinstance(source, FSM) and isinstance(result, BTDocument) and is_dispatch_bt(result):
        fsm, doc, fsm_side, tree_side = source, result, "source", "result"
    elif isinstance(source, BTDocument) and isinstance(result, FSM) and is_dispatch_bt(source):
        fsm, doc, fsm_side, tree_side = result, source, "result", "source"
    else:
        return None
    parsed = DispatchMachine(doc, ())  # parsed and checked once, for its events and tables
    alphabet = list(dict.fromkeys([*FSMMachine(fsm).alphabet, *parsed.events()]))
    fsm_enc = FSMEncoder(fsm, fsm_side, inputs, outputs, alphabet=alphabet)
    tree_enc = DispatchEncoder(doc, tree_side, inputs, outputs, alphabet=alphabet, parsed=parsed)
    return (fsm_enc, tree_enc) if fsm_side == "source" else (tree_enc, fsm_enc)


def one_step_per_input(source: FSM | BTDocument, result: FSM | BTDocument) -> bool:
    """Both models are encoded as modules that take one step per input with no micro-steps
    (an FSM, a dispatch tree beside an FSM): ``check`` then splits the invariants from the
    CTL specs (docs/nusmv.md, "Two runs")."""
    if isinstance(source, FSM) and isinstance(result, FSM):
        return True
    return any(
        isinstance(a, FSM) and isinstance(b, BTDocument) and is_dispatch_bt(b)
        for a, b in ((source, result), (result, source))
    )
