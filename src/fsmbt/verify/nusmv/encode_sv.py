"""A state-variable tree (the BSD and CHDS baselines' result, docs/baselines.md) as an SMV module.

Where the semantics come from: ``fsmbt.semantics.state_variable_runtime`` - the leaves'
behaviour (``leaf_outcome``) and the macro step (``StateVariableMachine._settle``) that the
native checker explores for these trees - never the converters' rules. The tick rules of the
tree's controls are ``BTCore``'s (the same micro-step encoding of BehaviorTree.CPP as for every
other tree, docs/nusmv.md "Encoding"); only the leaves' answers and the macro step are written
here. The leaves are read (ports, the initial state, the start pseudo-state) with the native
machine's own parser, so a malformed leaf is the same ``InputError`` on both engines.

Blackboard variables: ``bbs`` (``state``; an enumeration of every state a leaf names), ``bbe``
(the pending ``event``, ``ev_none`` = none), ``ent`` (``entered``), ``sw`` (a leaf switched
the state during this tick), ``lres`` (the last tick's root result), ``nt`` (ticks of this macro
step so far), action slots ``a1..aK`` with count ``nact``. Leaves (``req`` = the interpreter
asks the leaf):

- ``SvIsState(s)``: SUCCESS iff ``bbs = s``; ``SvGuard(s, e)``: SUCCESS iff ``bbs = s & bbe = e``;
- ``SvEntryAction`` / ``SvMode``: when ``!ent``, output the action and set ``ent``; SUCCESS
  (``SvMode``: RUNNING unless final);
- ``SvAssign(t)``: switch to ``t`` (``bbs := t``, ``ent``/``bbe`` cleared, ``sw`` set), SUCCESS;
- ``SvTransition(s, e/t...)``: final: SUCCESS; a pending ``e`` with ``bbs = s``: switch to
  ``t``, SUCCESS; otherwise RUNNING.

Macro step: input ``e`` sets ``bbe`` and ticks the root; when the root returns and ``sw`` holds,
the root is ticked again (``nt + 1``), at most ``MAX_TICKS_PER_STEP`` ticks; a switch in the
last one sets ``lvl`` (the native machine's livelock ``InputError``); otherwise the step ends and
the pending event is dropped. The start is the same settle with no event. ``final`` iff the last
result is SUCCESS and ``bbs`` is not the start pseudo-state.

Static bounds (``SvLeafFacts``, the unguarded cycle check): without an *unguarded*
``SvAssign`` leaf (one not behind an ``SvGuard`` in a reactive sequence, ``guarded``) a macro
step switches at most once (every other switch needs a pending event and clears it), so at
most two ticks and two actions run and neither livelock nor slot overflow can happen: no spec
is added and ``nt`` is ``1..2`` (BSD and CHDS trees alike). With one, two invariants
are checked on every state the result reaches (alone included): ``sv_livelock`` (``!lvl``; a
failure is the native checker's livelock ``InputError``, word for word) and ``output_overflow``
(at most ``MAX_ACTIONS`` actions per step, else ``UnsupportedError`` naming the limit).

Size: O(N · d) SMV text for N nodes of depth d (``BTCore``) plus O(T) rules for the T
``event/target`` items of the transition leaves.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import Hint, InputError, UnsupportedError
from fsmbt.semantics import state_variable_runtime as sv
from fsmbt.semantics.bt_interpreter import CompiledTree
from fsmbt.semantics.lebt.spec import NO_EVENT
from fsmbt.semantics.nodes import node_semantics
from fsmbt.verify.nusmv.encode_bt import safe_text
from fsmbt.verify.nusmv.encode_fsm import NONE_OUT, Encoding
from fsmbt.verify.nusmv.macro_frame import (
    declare_frame,
    frame_core,
    frame_symbols,
    record_action,
    root_returned,
    start_step,
    step_defines,
)
from fsmbt.verify.nusmv.smv import Symbols

#: Actions one macro step may output in the encoding (slots ``a1..aK``): an entry action before
#: and one after a switch, what every BSD/CHDS conversion needs (at most one switch per step).
MAX_ACTIONS = 2
#: The extra checks (``specs.product``'s ``extra_specs``) and what a failure means.
LIVELOCK_SPEC = "sv_livelock"
OVERFLOW_SPEC = "output_overflow"


@dataclass(frozen=True)
class SvLeafFacts:
    """What the static bounds read of the leaves: whether any may switch without an event."""

    unguarded_assigns: bool

    @property
    def may_livelock(self) -> bool:
        """A macro step can switch more than once only through an unguarded ``SvAssign``: an
        ``SvTransition`` switch needs the pending event and clears it, and so does an
        ``SvAssign`` that a guard must pass first (``guarded``). Without an unguarded one a
        step switches at most once: at most two ticks (no livelock) and two actions (an
        action needs ``!ent``, which only a switch clears): no overflow of ``MAX_ACTIONS``."""
        return self.unguarded_assigns

    @staticmethod
    def of(tree: CompiledTree, leaves: dict[int, sv.SvLeaf]) -> SvLeafFacts:
        """The facts of ``tree`` (the unguarded cycle check, O(N))."""
        return SvLeafFacts(
            unguarded_assigns=any(
                leaf.type == sv.ASSIGN and not guarded(tree, nid, leaves)
                for nid, leaf in leaves.items()
            )
        )


def guarded(tree: CompiledTree, nid: int, leaves: dict[int, sv.SvLeaf]) -> bool:
    """Whether leaf ``nid`` is ticked only after an ``SvGuard`` returned SUCCESS in the same
    tick: its parent is a reactive sequence (it ticks its children from the first on every
    tick and goes on only past a SUCCESS; pre-conditions, which could skip the guard, are
    rejected by the interpreter) and an earlier sibling is an ``SvGuard`` leaf, which succeeds
    only on a pending event (CHDS's switching subtrees). O(children)."""
    node = tree.nodes[nid]
    if node.parent is None:
        return False
    parent = tree.nodes[node.parent]
    spec = node_semantics(parent.type)
    if spec is None or not spec.reactive or spec.is_fallback:
        return False
    before = parent.children[: node.index]
    return any(c in leaves and leaves[c].type == sv.GUARD for c in before)


class SvEncoder:
    """``StateVariableMachine`` (the native checker's machine for these trees) in SMV."""

    def __init__(
        self,
        doc: BTDocument,
        module: str,
        inputs: Symbols,
        outputs: Symbols,
        *,
        alphabet: Sequence[str],
        machine: sv.StateVariableMachine | None = None,
    ) -> None:
        self.core = frame_core(doc, "a state-variable tree")
        # the leaves' ports, the initial state and the start pseudo-state, parsed (and
        # validated) as the native machine does; its exploration is never used (``machine``:
        # ``doc``'s, when the caller already built it)
        if machine is None:
            machine = sv.StateVariableMachine(doc, ())
        self.name = machine.name
        self.leaves: dict[int, sv.SvLeaf] = dict(machine.leaves)
        self.initial_state = machine.initial_state
        self.pseudo_start = machine.pseudo_start
        self.facts = SvLeafFacts.of(self.core.tree, self.leaves)
        self.module = module
        self.inputs = inputs
        self.outputs = outputs
        self.alphabet = list(alphabet)
        self.states, self.events = frame_symbols(inputs, self.alphabet, self.initial_state)
        for leaf in self.leaves.values():
            for name in (leaf.state, leaf.target, *(t for _e, t in leaf.transitions)):
                if name:
                    self.states.id(name)
            if leaf.type in (sv.ENTRY_ACTION, sv.MODE) and leaf.action is not None:
                outputs.id(leaf.action)
        self.slots = MAX_ACTIONS
        #: ticks one macro step may take in the encoding: the native bound, or 2 when the
        #: static bound shows no step switches twice (``SvLeafFacts``): a smaller ``nt``
        self.ticks = sv.MAX_TICKS_PER_STEP if self.facts.may_livelock else 2

    # -- the extra checks ----------------------------------------------------------------------
    def extra_specs(self) -> list[tuple[str, str]]:
        """The livelock and slot checks, only when the static bound does not exclude them."""
        if not self.facts.may_livelock:
            return []
        return [(LIVELOCK_SPEC, "!r.lvl"), (OVERFLOW_SPEC, "!r.ovf")]

    def extra_failure(self, name: str) -> Exception:
        """The error a failed extra check stands for: the livelock is the native machine's own
        ``InputError`` (same words), the overflow the encoding's limit."""
        if name == LIVELOCK_SPEC:
            return InputError(
                f"the tree does not settle within {sv.MAX_TICKS_PER_STEP} ticks (livelock)",
                element=self.name,
            )
        return UnsupportedError(
            f"the NuSMV encoding of a state-variable tree holds at most {self.slots} actions "
            "per macro step (MAX_ACTIONS in fsmbt.verify.nusmv.encode_sv); this tree runs "
            "more in one step",
            element=self.name,
            hints=(Hint.NATIVE_VERIFIER,),
        )

    # -- encoding ------------------------------------------------------------------------------
    def _ev(self, event: str) -> str | None:
        if event == NO_EVENT:
            return None
        return self.events.to_id.get(event)  # an event outside the alphabet never occurs

    def _switch(self, cond: str, target: str) -> None:
        core = self.core
        core.rule("bbs", cond, self.states.id(target))
        core.rule("ent", cond, "FALSE")
        core.rule("sw", cond, "TRUE")
        core.rule("bbe", cond, "ev_none")

    def _leaf(self, nid: int, leaf: sv.SvLeaf) -> None:
        """One leaf's answer, as ``state_variable_runtime.leaf_outcome``."""
        core, k = self.core, self.slots
        req = core.leaf_request(nid)
        if leaf.type == sv.IS_STATE:
            here = f"bbs = {self.states.id(leaf.state)}" if leaf.state else "FALSE"
            core.ret(req, nid, f"case {here} : S; TRUE : F; esac")
        elif leaf.type == sv.GUARD:
            ev = self._ev(leaf.event)
            match = (
                f"(bbs = {self.states.id(leaf.state)} & bbe = {ev})"
                if ev is not None and leaf.state
                else "FALSE"
            )
            core.ret(req, nid, f"case {match} : S; TRUE : F; esac")
        elif leaf.type in (sv.ENTRY_ACTION, sv.MODE):
            enter = f"{req} & !ent"
            if leaf.action is not None:
                record_action(core, enter, self.outputs.id(leaf.action), k)
            core.rule("ent", enter, "TRUE")
            done = leaf.type == sv.ENTRY_ACTION or leaf.final
            core.ret(req, nid, "S" if done else "R")
        elif leaf.type == sv.ASSIGN:
            self._switch(req, leaf.target)
            core.ret(req, nid, "S")
        else:  # TRANSITION
            if not leaf.final and leaf.state:
                here = f"bbs = {self.states.id(leaf.state)}"
                for event, target in leaf.transitions:
                    ev = self._ev(event)
                    if ev is None:
                        continue
                    fire = f"{req} & {here} & bbe = {ev}"
                    self._switch(fire, target)
                    core.ret(fire, nid, "S")
            core.ret(req, nid, "S" if leaf.final else "R")

    def encode(self) -> Encoding:
        core, k = self.core, self.slots
        ticks = self.ticks
        core.declare(["TOP"], core.n(0))  # the start: the settle with no event
        out_enum = self.outputs.enum([NONE_OUT])
        extra_vars = {
            "bbs": self.states.enum(),
            "bbe": self.events.enum(["ev_none"]),
            "ent": "boolean",
            "sw": "boolean",
            "lres": "{lr_none, lr_R, lr_S, lr_F}",
            "nt": f"1..{ticks}",
            "lvl": "boolean",
            "nact": f"0..{k}",
            "ovf": "boolean",
        }
        inits = {
            "bbs": self.states.id(self.initial_state),
            "bbe": "ev_none",
            "ent": "FALSE",
            "sw": "FALSE",
            "lres": "lr_none",
            "nt": "1",
            "lvl": "FALSE",
            "nact": "0",
            "ovf": "FALSE",
        }
        declare_frame(core, extra_vars, inits, k, out_enum)
        stable = "(cur = TOP & res = NONE)"
        # a macro step starts: set the event, tick the root
        start_step(core, self.inputs, self.events, self.alphabet, k)
        core.rule("nt", "go", "1")
        core.rule("sw", "go", "FALSE")
        for nid, leaf in self.leaves.items():
            self._leaf(nid, leaf)
        # the root returned: a pending wake-up re-ticks at once (Tree::tickRoot)
        ended = root_returned(core)
        again = f"{ended} & sw & nt < {ticks}"  # a switch: the new state's subtree must run
        core.rule("sw", again, "FALSE")
        core.rule("nt", again, "nt + 1")
        core.call(again, 0)
        core.rule("lvl", f"{ended} & sw & nt = {ticks}", "TRUE")
        finish = f"{ended} & !(sw & nt < {ticks})"  # the pending event is dropped
        core.rule("res", finish, "NONE")
        core.rule("bbe", finish, "ev_none")
        core.rule("sw", finish, "FALSE")
        core.rule("nt", finish, "1")
        start = self.states.id(self.initial_state)
        final = "lres = lr_S" + (f" & bbs != {start}" if self.pseudo_start else "")
        defines = [("stable", stable), ("final", f"({final})")]
        defines += step_defines(self.inputs, self.alphabet, k)
        # the native state: interpreter snapshot, state, entered, last result
        ident = [
            ("bbs", extra_vars["bbs"]),
            ("ent", "boolean"),
            ("lres", extra_vars["lres"]),
        ]
        ident += [(v, safe_text(core.var_types[v])) for v in core.identity_vars()]
        text = core.emit(self.module, "go, inp", defines)
        names = self.states.to_name
        return Encoding(
            self.module,
            text,
            [f"o{j}" for j in range(1, k + 1)],
            list(self.alphabet),
            ident,
            decode_state=lambda values: names.get(values.get("bbs", ""), "?"),
            var_order=self.bdd_order(),
        )

    def bdd_order(self) -> list[str]:
        """The BDD order of the module's variables: the blackboard first (every leaf answer
        reads ``bbs``/``bbe``), then the tree's. Measured against the tree's variables first
        (NuSMV CPU s, one random FSM's copy / one-transition mutant, docs/nusmv.md): BSD 20
        states 20.9 -> 13.3 (copy), CHDS 10 states 2.4 -> 1.5 and 23.4 -> 17.8."""
        names = list(self.core.var_types)
        board = ["bbs", "bbe", "ent", "sw", "lres", "nt"]
        return board + [v for v in names if v not in board]
