"""The outcome pairing in NuSMV: an outcome-driven FSM and its structured tree (docs/nusmv.md,
"The outcome pairing (structured trees)"; docs/semantics.md §11, "The outcome pairing").

Both modules step on the source states' outcomes, as the native pairing's machines do
(``fsmbt.verify.outcome_pairing``), but each is written here from the models and the rules,
never from the native machines:

- the FSM side (``OutcomeFSMEncoder``): one variable ``q``, the atomic state about to run (its
  path) or the root's result. An outcome follows its transition, up through every container
  whose final state it reaches (the container's completion transition for that outcome) and
  down into every container it enters (its initial state), to the next atomic state or a
  top-level final state (``SUCCESS``/``FAILURE`` by the top-level exit's status); ``running``
  keeps the state. Output: the state's label, or the result. Offered: the state's outcomes
  (``OutcomeView``: halting ``preempted`` ones removed) and ``running``. A Concurrence read in
  rounds (a ``Parallel``/``ParallelAll`` in the tree; docs/semantics.md §11) adds, per child,
  its outcome so far and, per container child, where it is: ``encode_rounds`` (the round
  reading, the turn and the outcome map's decision, written from the documented rules).
- the tree side (``OutcomeBTEncoder``): BehaviorTree.CPP's tick rules (``encode_bt.BTCore`` and
  its families) over the tree the blackboard model parses (``outcome_blackboard.OutcomeTree``:
  it refuses every use of a modelled entry it does not cover), plus the three blackboard forms a
  structured tree uses: each modelled entry ``K`` is an enum variable ``bb_k`` (``unset`` or
  one of the literals written to it: Scripts' values, outcomes written through an ``outcome``
  port); ``Script`` (``K:='v'`` assignments) writes its values (the last one per key) and
  returns SUCCESS; ``Switch2..6`` ticks the first child whose case equals the entry (else the
  default), keeps its running child's index ``sw_n`` and resets a running child that is no
  longer the match, resets every child when one completes (``switch_node.h``). A leaf named
  after a source state answers with that state's outcomes: a binary state's outcome is the
  leaf's status by the outcome rules (``Unit.status``, ``outcome_rules``); a dispatch state's
  leaf returns SUCCESS and writes the outcome's name to its ``outcome`` entry; ``running`` is
  RUNNING. A leaf no state is named after keeps the plain leaf outcomes.

Livelock: a tree that ticks forever without a leaf is the native machine's ``LIVELOCK`` state;
NuSMV does not model that state, so when the tree holds a node that may tick forever it checks
in a run of its own (``livelock_model``: the tree alone, a forward search) that no state the tree
reaches micro-steps forever, and refuses the pair by name when one does (``--engine both`` keeps
the native verdict). The same ``EG`` on the product cost 46 s (``-df``) and over 120 s (whole)
on a 6-state machine whose tree alone takes 0.2 s.

Refused by name (``UnsupportedError``, NuSMV's limits): a child that may return SKIPPED under
a Switch, a livelock (above). Size: O(states x outcomes) for the FSM side plus
``encode_rounds``' rows per concurrence child outcome; the tree's ``BTCore`` text plus
O(entries x values) for the blackboard.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import Hint, UnsupportedError
from fsmbt.model.fsm import FSM
from fsmbt.model.kinds import NodeKind
from fsmbt.semantics.compiled import CompiledNode
from fsmbt.semantics.outcome_blackboard import SCRIPT, SWITCH, OutcomeTree
from fsmbt.semantics.outcome_rules import FAILURE, OutcomeError, OutcomeRules
from fsmbt.semantics.outcome_view import RUNNING_INPUT, OutcomeView, Unit
from fsmbt.semantics.status import LeafOutcome, RootResult
from fsmbt.verify.nusmv.encode_bt import LeafBTEncoder
from fsmbt.verify.nusmv.encode_fsm import NONE_OUT, Encoding
from fsmbt.verify.nusmv.encode_rounds import RUNS, Child, RoundTable, Row, Target, negate
from fsmbt.verify.nusmv.families.common import ST
from fsmbt.verify.nusmv.families.contract import BTCore, Resets
from fsmbt.verify.nusmv.smv import Symbols, all_of, any_of, case, enum_type

#: The value of an entry nothing has written yet.
UNSET = "bu"

#: Where going to a state lands (``OutcomeFSMEncoder._enter``): an atomic state or a result,
#: the start of a concurrence read in rounds, the end of a concurrence's container child.
AT, ROUND, ENDED = "at", "round", "ended"
#: (kind, value, whether a container child's loop went round on the way)
Landing = tuple[str, str, bool]


def _refuse(why: str, element: str) -> UnsupportedError:
    return UnsupportedError(
        f"the NuSMV encoding of the outcome pairing does not cover {why}",
        element=element,
        hints=(Hint.NATIVE_VERIFIER,),
    )


class OutcomeFSMEncoder:
    """The outcome-driven FSM as an SMV module (the module docstring, "the FSM side")."""

    follows = False

    def __init__(self, view: OutcomeView, module: str, inputs: Symbols, outputs: Symbols) -> None:
        self.view = view
        self.module = module
        self.inputs = inputs
        self.outputs = outputs
        self.units = {
            u.path: u for r in view.regions.values() for u in r.units.values() if not u.container
        }
        self.region_of = {u.path: p for p, r in view.regions.items() for u in r.units.values()}
        self.round_trips = frozenset(t for r in view.regions.values() for t in r.round_trips)
        self.states = Symbols("q")
        for path in self.units:
            self.states.id(path)
        for unit in self.units.values():
            inputs.add_all(unit.outcomes)
            outputs.id(unit.label)
        inputs.id(RUNNING_INPUT)
        #: the outcomes a concurrence's child ended with (the ``dn`` variables' values)
        self.done_ids = Symbols("dv")
        #: region path -> its concurrence read in rounds (``encode_rounds``)
        self.rounds: dict[str, RoundTable] = {}
        for path, region in view.regions.items():
            if region.parallel:
                self.rounds[path] = self._round_table(len(self.rounds), path)
        self.start = self._landing_target(self._start())
        self.rows: list[Row] = []
        for path, unit in self.units.items():
            self.rows += self._moves(path, unit)
        targets = [self.start, *(row.target for row in self.rows)]
        self.results = sorted({t.path for t in targets if t.path and t.path not in self.units})
        for word in self.results:
            self.states.id(word)
            outputs.id(word)

    # -- reading the machine ---------------------------------------------------------------
    def _round_table(self, key: int, path: str) -> RoundTable:
        region = self.view.regions[path]
        concurrence = region.concurrence
        assert concurrence is not None
        children: list[Child] = []
        for index, label in enumerate(concurrence.labels):
            unit = region.units[label]
            if not unit.container:
                children.append(Child(index, unit.path, False, unit.path))
                continue
            kind, entry, _trip = self._enter(unit.path, self.view.regions[unit.path].initial)
            assert kind == AT and entry in self.units, "a container child runs a state first"
            inside = [p for p in self.units if p.startswith(unit.path + "/")]
            children.append(Child(index, unit.path, True, entry, inside))
        for outcomes in concurrence.outcomes:
            self.done_ids.add_all(outcomes)
        return RoundTable(key, path, concurrence, children)

    def _start(self) -> Landing:
        if self.view.top.parallel:
            return ROUND, "", False
        return self._enter("", self.view.top.initial)

    def _enter(self, region_path: str, target: str) -> Landing:
        """Where going to ``target`` in a region lands (the module docstring): an atomic
        state or the root's result (``AT``), the start of a concurrence read in rounds
        (``ROUND``, its region), or the end of a concurrence's container child (``ENDED``, its
        outcome); and whether it went round a loop of such a child (``Region.round_trips``).
        O(nesting depth) steps; a cycle of containers that enter and leave each other without
        running a state is an ``OutcomeError``."""
        seen: set[tuple[str, str]] = set()
        round_trip = False
        regions = self.view.regions
        while (region_path, target) not in seen:
            seen.add((region_path, target))
            region = regions[region_path]
            if region.machine.states[target].final:
                owner = region.owner
                if owner is None:
                    return AT, self.view.root_result(target), round_trip
                region_path = self.region_of[owner.path]
                if regions[region_path].parallel:
                    return ENDED, target, round_trip
                round_trip = round_trip or (owner.path, target) in self.round_trips
                target = owner.targets[target]
                continue
            unit = region.units[target]
            if unit.container and regions[unit.path].parallel:
                return ROUND, unit.path, round_trip
            if not unit.container:
                return AT, unit.path, round_trip
            region_path, target = unit.path, regions[unit.path].initial
        raise OutcomeError(
            "containers enter and leave each other forever without running a state",
            element=f"state '{target}'",
        )

    def _landing_target(self, landing: Landing) -> Target:
        kind, value, _trip = landing
        if kind == ROUND:
            return self.rounds[value].entry_target()
        assert kind == AT, "a container child ends inside its concurrence only"
        return Target(value)

    def _context(self, path: str) -> tuple[RoundTable, int] | None:
        """The concurrence read in rounds whose child runs the atomic state ``path``, and the
        child's index; ``None`` outside every one (a SMACH ``outcome_cb`` state included)."""
        unit, region_path = self.units[path], self.region_of[path]
        table = self.rounds.get(region_path)
        if table is not None and unit.name in table.concurrence.labels:
            return table, table.concurrence.labels.index(unit.name)
        while True:
            owner = self.view.regions[region_path].owner
            if owner is None:
                return None
            region_path = self.region_of[owner.path]
            table = self.rounds.get(region_path)
            if table is not None:
                return table, table.concurrence.labels.index(owner.name)

    # -- the moves -------------------------------------------------------------------------
    def _moves(self, path: str, unit: Unit) -> list[Row]:
        """Every guarded move out of the atomic state ``path`` (disjoint guards)."""
        here = Target(path)
        running = f"go & q = {self.states.id(path)} & inp = {self.inputs.id(RUNNING_INPUT)}"
        context = self._context(path)
        rows: list[Row] = []
        if context is None:
            rows.append(Row(running, here))
            for o in unit.outcomes:
                guard = f"go & q = {self.states.id(path)} & inp = {self.inputs.id(o)}"
                landing = self._enter(self.region_of[path], unit.targets[o])
                rows.append(Row(guard, self._landing_target(landing)))
            return rows
        table, index = context
        child = table.children[index]
        rows += table.next_child_rows(running, index, here, {})
        for o in unit.outcomes:
            guard = f"go & q = {self.states.id(path)} & inp = {self.inputs.id(o)}"
            if not child.container:
                rows += self._ended(table, index, o, guard)
                continue
            kind, value, trip = self._enter(self.region_of[path], unit.targets[o])
            trip = trip or (path, o) in self.round_trips  # a loop back to its head
            if kind == ENDED:
                rows += self._ended(table, index, value, guard)
                continue
            assert kind == AT and value in child.positions, "a container child stays inside"
            sets = {table.pos_var(index): self.states.id(value)} if child.tracked else {}
            if trip:  # its loop went round: its tree returned RUNNING, the next child's turn
                rows += table.next_child_rows(guard, index, Target(value), sets)
            else:
                rows.append(Row(guard, Target(value), sets))
        return rows

    def _ended(self, table: RoundTable, index: int, outcome: str, guard: str) -> list[Row]:
        """Child ``index`` ended with ``outcome``: the source decision leaves the concurrence
        (through its ``outcome_cb`` state when it has one), else the next child's turn."""
        rows: list[Row] = []
        decided: list[str] = []
        reset = table.reset()
        reset = {var: self._value(var, v) for var, v in reset.items()}
        callback = table.concurrence.callback_state
        owner = self.view.regions[table.region].owner
        for cond, container_outcome in table.decision_rows(index, outcome, self.done_ids):
            target = callback if callback is not None else container_outcome
            if owner is None or callback is not None or target in owner.targets:
                landing = self._enter(table.region, target)
                rows.append(
                    Row(all_of([guard, *decided, cond]), self._landing_target(landing), reset)
                )
            # else an outcome the concurrence never gives (its product never reaches that
            # final state, so the container has no transition for it): no combination the
            # rounds reach makes ``cond`` hold here, and no row is written
            decided.append(negate(cond))
        sets = {table.done_var(index): self.done_ids.id(outcome)}
        if table.children[index].tracked:
            sets[table.pos_var(index)] = self.states.id(table.children[index].entry)
        rows += table.next_child_rows(all_of([guard, *decided]), index, None, sets)
        return rows

    def _value(self, var: str, value: str) -> str:
        """An SMV value for a round variable: ``dnr`` as is, a position as its ``q`` id."""
        return value if var.startswith("dn") else self.states.id(value)

    def _out(self, state: str) -> str:
        unit = self.units.get(state)
        return self.outputs.id(unit.label if unit is not None else state)

    def encode(self) -> Encoding:
        q, ids = self.states, self.inputs
        next_q: list[tuple[str, str]] = []
        next_o1: list[tuple[str, str]] = []
        assigned: dict[str, list[tuple[str, str]]] = {}
        for row in self.rows:
            if row.target.var:
                next_q.append((row.guard, row.target.var))
                child = next(
                    c for t in self.rounds.values() for c in t.children
                    if t.pos_var(c.index) == row.target.var
                )  # fmt: skip
                for p in child.positions:
                    cond = all_of([row.guard, f"{row.target.var} = {q.id(p)}"])
                    next_o1.append((cond, self._out(p)))
            else:
                next_q.append((row.guard, q.id(row.target.path)))
                next_o1.append((row.guard, self._out(row.target.path)))
            for var, value in row.sets.items():
                assigned.setdefault(var, []).append((row.guard, value))
        final = any_of(f"q = {q.id(r)}" for r in self.results)
        lines = [
            f"MODULE {self.module}(go, inp)",
            "VAR",
            f"  q : {q.enum()};",
            f"  o1 : {self.outputs.enum([NONE_OUT])};",
        ]
        round_vars: list[tuple[str, str]] = []
        inits: list[str] = []
        for table in self.rounds.values():
            for c in table.children:
                outs = [self.done_ids.id(o) for o in table.concurrence.outcomes[c.index]]
                round_vars.append((table.done_var(c.index), enum_type([RUNS, *outs], "dvpad")))
                inits.append(f"  init({table.done_var(c.index)}) := {RUNS};")
            for c in table.children:
                if c.tracked:
                    values = [q.id(p) for p in c.positions]
                    round_vars.append((table.pos_var(c.index), enum_type(values, "qpad")))
                    inits.append(f"  init({table.pos_var(c.index)}) := {q.id(c.entry)};")
        lines += [f"  {var} : {typ};" for var, typ in round_vars]
        lines += [
            "DEFINE",
            "  stable := TRUE;",
            f"  final := {final};",
        ]
        for symbol, sid in sorted(ids.to_id.items()):
            if symbol == RUNNING_INPUT:
                offered = "!final"
            else:
                offered = any_of(
                    f"q = {q.id(p)}" for p, u in self.units.items() if symbol in u.outcomes
                )
            lines.append(f"  offers_{sid} := {offered};")
        start = self.start.path
        lines += [
            "ASSIGN",
            f"  init(q) := {q.id(start)};",
            f"  next(q) := {case(next_q, 'q')};",
            f"  init(o1) := {self._out(start)};",
            f"  next(o1) := {case(next_o1 + [('go', NONE_OUT)], 'o1')};",
            *inits,
        ]
        for var, _typ in round_vars:
            lines.append(f"  next({var}) := {case(assigned.get(var, []), var)};")

        def describe(values: dict[str, str]) -> str:
            name = q.name(values.get("q", "")) or "?"
            unit = self.units.get(name)
            return unit.label if unit is not None else name

        return Encoding(
            self.module,
            "\n".join(lines) + "\n",
            ["o1"],
            [*dict.fromkeys(o for u in self.units.values() for o in u.outcomes), RUNNING_INPUT],
            [("q", q.enum()), *round_vars],
            decode_state=describe,
            var_order=["q", *(var for var, _t in round_vars), "o1"],
        )


class OutcomeBTEncoder(LeafBTEncoder):
    """The structured tree's leaf-execution machine over outcomes (the module docstring, "the
    tree side")."""

    def __init__(
        self, doc: BTDocument, view: OutcomeView, module: str, inputs: Symbols, outputs: Symbols
    ) -> None:
        tree = OutcomeTree(doc)  # the blackboard model's parse and its soundness checks
        self.view = view
        self.tree_name = doc.main.id
        self.outcome_keys = tree.outcome_keys
        values: dict[str, dict[str, None]] = {key: {} for key in sorted(tree.modelled)}
        for node in tree.nodes:
            if node.type == SCRIPT:
                for key, value in node.params:
                    values[key].setdefault(value, None)
        for nid, key in tree.outcome_keys.items():
            unit = view.by_label.get(tree.nodes[nid].label)
            if unit is not None and unit.dispatch and not unit.container:
                values[key].update(dict.fromkeys(unit.outcomes))
        #: entry -> (SMV variable, its values' symbols)
        self.entries: dict[str, tuple[str, Symbols]] = {}
        for k, key in enumerate(values):
            table = Symbols(f"b{k}v")
            table.add_all(values[key])
            self.entries[key] = (f"bb_{k}", table)
        #: per environment leaf: the inputs it accepts (filled by ``_answer``)
        self.accepts: dict[int, tuple[str, ...]] = {}
        super().__init__(
            tree,
            module,
            inputs,
            outputs,
            loop=False,
            own_rules={SWITCH: self._switch, SCRIPT: self._script},
            static_livelock=False,
        )
        for unit in view.leaf_units():
            inputs.add_all(unit.outcomes)
        inputs.id(RUNNING_INPUT)

    # -- the blackboard --------------------------------------------------------------------
    def _declare_more(self) -> None:
        core = self.core
        for var, table in self.entries.values():
            core.var_types[var] = table.enum([UNSET])
            core.init[var] = UNSET
            core.kept_vars.append(var)  # part of the state; a halt does not touch it

    def _equals(self, key: str, value: str) -> str:
        var, table = self.entries[key]
        return f"{var} = {table.to_id[value]}" if value in table.to_id else "FALSE"

    def _switch(
        self, core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets
    ) -> None:
        """Switch2..6 on a modelled entry (``outcome_blackboard``'s rule, switch_node.h)."""
        key, cases = x.params
        kids = list(x.children)
        for c in kids:
            if core.may_skip[c]:
                raise _refuse("a child that may return SKIPPED under a Switch", x.label)
        eq = [self._equals(key, value) for value in cases]
        take = [
            all_of([*(_not(e) for e in eq[:i]), eq[i] if i < len(eq) else "TRUE"])
            for i in range(len(kids))
        ]
        running = core.memory("sw", x.id, len(kids))  # 0: none; i + 1: child i RUNNING
        for i, c in enumerate(kids):
            resets[c].append(f"{called} & {running} = {i + 1} & !{_paren(take[i])}")
            core.call(f"{called} & {_paren(take[i])}", c)
        back = f"{here} & res != NONE"
        for i in range(len(kids)):
            core.rule(running, f"{back} & res = R & lidx = {i}", str(i + 1))
        core.ret(f"{back} & res = R", x.id, "R")
        done = f"{back} & (res = S | res = F)"
        for c in kids:
            resets[c].append(done)
        core.rule(running, done, "0")
        core.ret(done, x.id, "case res = S : S; TRUE : F; esac")

    def _script(
        self, core: BTCore, x: CompiledNode, here: str, called: str, resets: Resets
    ) -> None:
        """``K:='v'`` assignments: the values written in order (the last per key), SUCCESS."""
        for key, value in dict(x.params).items():
            var, table = self.entries[key]
            core.rule(var, called, table.id(value))
        core.ret(called, x.id, "S")

    # -- the leaves' answers ---------------------------------------------------------------
    def _answer(self, leaf: CompiledNode, req: str) -> None:
        unit = self.view.by_label.get(leaf.label)
        if unit is None or unit.container:
            super()._answer(leaf, req)
            plain = [o.value for o in LeafOutcome]
            if leaf.kind is NodeKind.CONDITION:
                plain.remove(RUNNING_INPUT)
            self.accepts[leaf.id] = tuple(plain)
            return
        core, ids = self.core, self.inputs
        key = self.outcome_keys.get(leaf.id) if unit.dispatch else None
        for outcome in unit.outcomes:
            cond = f"go & {req} & inp = {ids.id(outcome)}"
            if unit.dispatch:
                if key is not None:
                    var, table = self.entries[key]
                    core.rule(var, cond, table.id(outcome))
                core.ret(cond, leaf.id, ST["SUCCESS"])
                continue
            status = unit.status[outcome]
            assert status is not None, "a binary unit has a status for every outcome"
            core.ret(cond, leaf.id, ST["FAILURE"] if status == FAILURE else ST["SUCCESS"])
        accepted = unit.outcomes
        if leaf.kind is not NodeKind.CONDITION:
            core.ret(f"go & {req} & inp = {ids.id(RUNNING_INPUT)}", leaf.id, "R")
            accepted = (*accepted, RUNNING_INPUT)
        self.accepts[leaf.id] = accepted

    def _offers(self, symbol: str, requests: Sequence[str], condition_req: str) -> str:
        leaves = self.core.env_leaves()
        return any_of(
            req for req, leaf in zip(requests, leaves) if symbol in self.accepts.get(leaf.id, ())
        )

    def _input_names(self) -> list[str]:
        return list(self.inputs.to_id)

    def encode(self) -> Encoding:
        """The tree's module, with its BDD order grouped by node (``node_order``)."""
        encoding = super().encode()
        encoding.var_order = node_order(encoding.var_order)
        return encoding

    # -- the livelock check ----------------------------------------------------------------
    def livelock_model(self, encoding: Encoding) -> tuple[str, str] | None:
        """The model (SMV text, BDD order) of the livelock check, or ``None`` when no node
        may keep its child ticking without end (``BTCore.ticks_forever``: KeepRunningUntilFailure,
        an endless Repeat/Retry) - without one, and with the root's result ending the run,
        every run of ticks without a leaf is finite. The tree alone, every input its leaves
        accept offered: ``AG !(EG !r.stable)`` - no reachable state micro-steps forever
        (exact: micro-steps are deterministic). A forward search, the tree's variables only."""
        if not self.core.ticks_forever:
            return None
        ids = list(self.inputs.to_id.values())
        offered = any_of(f"(inp = {i} & r.offers_{i})" for i in ids)
        main = [
            "MODULE main",
            "IVAR",
            f"  inp : {enum_type(ids, 'in_pad')};",
            "VAR",
            f"  r : {encoding.module}(go, inp);",
            "DEFINE",
            f"  go := r.stable & {offered};",
            "SPEC AG !(EG !r.stable);",
        ]
        order = "inp\n" + "".join(f"r.{v}\n" for v in encoding.var_order)
        return encoding.text + "\n" + "\n".join(main) + "\n", order

    def livelock_failure(self) -> UnsupportedError:
        """A failed livelock check: the tree can tick forever without a leaf, which the native
        machine models as its ``LIVELOCK`` state and NuSMV does not."""
        return _refuse(
            "a tree that can tick forever without ticking a leaf (the native machine's "
            "LIVELOCK state)",
            f"tree '{self.tree_name}'",
        )


#: A node's own variable: ``<kind>_<node id>`` (``st_7``, ``ci_7``, ``sw_7``...).
_NODE_VAR = re.compile(r"([a-z]+)_(\d+)")
#: A blackboard entry's variable (``OutcomeBTEncoder.entries``).
_ENTRY_VAR = re.compile(r"bb_\d+")
#: The call stack's variables (``encode_bt``), in their order: the entries go after the last.
_STACK = ("cur", "res", "lidx")


def node_order(order: Sequence[str]) -> list[str]:
    """The BDD order of a structured tree's module, grouped so the relation stays small:

    - each node's memory variables (a Switch's ``sw_n``, an IfThenElse's ``ci_n``, a loop's
      counter...) right after its status ``st_n`` instead of after every node's status: the
      rules that read and write them test ``st_n`` and the node's call, and NuSMV's relation
      over them blows up when they are far apart (a 20-state machine's 131-node tree: the
      monolithic relation past 120 s, 2.4 s grouped);
    - the blackboard entries (``bb_k``, ``k`` a key, not a node) right after the call stack
      (``cur``, ``res``, ``lidx``), not after every node: every Switch's call and every
      Script's write tests ``cur`` beside the entry, so with the entries last each such rule
      spans the whole order. Measured on eight 20-state machines' pairs
      (``bench_nusmv_structured_phases.py --seeds 1,...,8 --sizes 20``, the copies, variant
      ``before`` against now): two past 60 s -> 54 s and 30 s wall, the six others
      3.8-27.6 s -> 1.8-9.7 s (docs/nusmv.md, "The outcome pairing", "Eighth round").

    Every other variable keeps its place."""
    owned: dict[str, list[str]] = {}
    for var in order:
        found = _NODE_VAR.fullmatch(var)
        if found and found.group(1) not in ("st", "bb"):
            owned.setdefault(found.group(2), []).append(var)
    placed = {v for group in owned.values() for v in group}
    entries = [v for v in order if _ENTRY_VAR.fullmatch(v)]
    placed.update(entries)
    anchor = next((v for v in reversed(_STACK) if v in order), None)
    grouped: list[str] = [] if anchor is not None else list(entries)
    for var in order:
        if var in placed:
            continue
        grouped.append(var)
        if var == anchor:
            grouped += entries
        found = _NODE_VAR.fullmatch(var)
        if found and found.group(1) == "st":
            grouped += owned.pop(found.group(2), [])
    grouped += [v for group in owned.values() for v in group]  # a node without a status
    return grouped


def _not(expr: str) -> str:
    return {"TRUE": "FALSE", "FALSE": "TRUE"}.get(expr, f"!{_paren(expr)}")


def _paren(expr: str) -> str:
    return expr if expr.startswith("(") or expr in ("TRUE", "FALSE") else f"({expr})"


def encode_outcome_pair(
    source: FSM,
    result: BTDocument,
    inputs: Symbols,
    outputs: Symbols,
    rules: OutcomeRules | None = None,
) -> tuple[OutcomeFSMEncoder, OutcomeBTEncoder]:
    """The (source, result) encoders of the outcome pairing, the FSM read under ``rules``
    (``None``: the defaults) as the structured conversion reads it.

    Raises:
        OutcomeError: the FSM is not outcome-driven (the state and the cause named).
        UnsupportedError: what the module docstring lists as refused.
    """
    from fsmbt.convert.structured.schedule import read_structured_view

    view = read_structured_view(source, rules)
    fsm_side = OutcomeFSMEncoder(view, "source", inputs, outputs)
    tree_side = OutcomeBTEncoder(result, view, "result", inputs, outputs)
    outputs.add_all(r.value for r in RootResult)
    return fsm_side, tree_side


__all__ = ["OutcomeBTEncoder", "OutcomeFSMEncoder", "encode_outcome_pair"]
