"""A loop-execution BT (docs/semantics.md, 'The LEBT protocol') as an SMV module: the tree's tick rules (``BTCore``) with the
LEBT leaves answered from a blackboard held in SMV variables, and the macro-step protocol of
``fsmbt.semantics.lebt`` (leaves and macro step) as transitions:

- ``bbs`` (blackboard ``state``, starts at the start pseudo-state), ``bbe`` (``event``,
  ``ev_none`` when none is pending), ``lres`` (the last tick's root result), ``tick2`` (the
  second tick of a macro step is running), action slots ``a1..aK`` with count ``nact``.
- input ``e`` (stable = between macro steps): ``bbe := e``, tick the root. A guard leaf answers
  FAILURE iff ``(bbs, bbe)`` is one of its pairs; a state leaf's first tick (status IDLE) runs its
  action, sets ``bbs``, clears ``bbe`` and answers RUNNING (SUCCESS when final); later ticks
  answer SUCCESS on a pending exit event, drop any other pending event and stay RUNNING.
- the root returns: RUNNING with a wake-up re-ticks at once; SUCCESS with the event still
  pending ticks once more (once); otherwise the macro step ends and the pending event is
  dropped. Status ``final`` iff the last result is SUCCESS and ``bbs`` left the start.
K bounds the actions one macro step can run (2 ticks x (final state leaves + 1)); a spec checks
the bound is never exceeded, else the pair is rejected as unsupported.
"""

from __future__ import annotations

from collections.abc import Sequence

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import Hint, UnsupportedError
from fsmbt.semantics.lebt.fast import strict_lebt_sels
from fsmbt.semantics.lebt.leaves import LebtLeaves
from fsmbt.semantics.lebt.spec import NO_EVENT
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
from fsmbt.verify.nusmv.smv import Symbols, any_of, case, enum_type

MAX_SLOTS = 6


class LebtEncoder:
    def __init__(
        self,
        doc: BTDocument,
        module: str,
        inputs: Symbols,
        outputs: Symbols,
        *,
        alphabet: Sequence[str],
    ) -> None:
        self.core = frame_core(doc, "an LEBT")
        self.leaves = LebtLeaves.of(self.core.tree)
        self.module = module
        self.inputs = inputs
        self.outputs = outputs
        self.alphabet = list(alphabet)
        self.states, self.events = frame_symbols(inputs, self.alphabet, self.leaves.start)
        for guard in self.leaves.guards.values():
            for source, _event in guard.pairs:
                self.states.id(source)
        for spec in self.leaves.states.values():
            self.states.id(spec.state)
            if spec.action is not None:
                outputs.id(spec.action)
        finals = sum(1 for s in self.leaves.states.values() if s.final)
        self.slots = max(1, min(2 * (finals + 1), MAX_SLOTS))

    def extra_specs(self) -> list[tuple[str, str]]:
        return [("output_overflow", "!r.ovf")]

    def extra_failure(self, name: str) -> Exception:
        """The error a failed extra check (the slot bound) stands for."""
        return UnsupportedError(
            f"the NuSMV encoding bounds the actions of one macro step at {self.slots}; this "
            "LEBT runs more in one step",
            hints=(Hint.NATIVE_VERIFIER,),
        )

    def _ev(self, event: str) -> str | None:
        if event == NO_EVENT:
            return "ev_none"
        return self.events.to_id.get(event)  # an event outside the alphabet never occurs

    def _running_leaf(self) -> tuple[str, str] | None:
        """For a tree of the strict LEBT grammar, its state between macro steps as the native
        fast path keys it: the running state leaf (``runl``), with ``bbs`` and ``lres``. Every
        other status, index and frame local follows from that leaf's position there
        (``fsmbt.semantics.lebt.fast``), so comparing these three compares the same states as
        comparing all variables, with a frozen copy of 3 variables instead of ~3 per node
        (the reachability spec's cost). ``None`` for any other tree: all variables count."""
        if strict_lebt_sels(self.core.tree) is None:
            return None
        core = self.core
        leaves = sorted(self.leaves.states)
        rows = [(f"{core.st(nid)} = R", f"rl_{nid}") for nid in leaves]
        return case(rows, "rl_none"), enum_type(["rl_none"] + [f"rl_{n}" for n in leaves], "rl_pad")

    def encode(self) -> Encoding:
        core, k = self.core, self.slots
        init_cur = core.n(0) if self.leaves.init_on_start else "TOP"
        core.declare(["TOP"], init_cur)
        out_enum = self.outputs.enum([NONE_OUT])
        extra_vars = {
            "bbs": self.states.enum(),
            "bbe": self.events.enum(["ev_none"]),
            "lres": "{lr_none, lr_R, lr_S, lr_F}",
            "tick2": "boolean",
            "nact": f"0..{k}",
            "ovf": "boolean",
        }
        inits = {
            "bbs": self.states.id(self.leaves.start),
            "bbe": "ev_none",
            "lres": "lr_none",
            "tick2": "FALSE",
            "nact": "0",
            "ovf": "FALSE",
        }
        declare_frame(core, extra_vars, inits, k, out_enum)
        stable = "(cur = TOP & res = NONE)"
        # a macro step starts: set the event, tick the root
        start_step(core, self.inputs, self.events, self.alphabet, k)
        core.rule("tick2", "go", "FALSE")
        # guard leaves
        for nid, guard in self.leaves.guards.items():
            req = core.leaf_request(nid)
            matches = []
            for source, event in guard.pairs:
                ev = self._ev(event)
                if ev is not None:
                    matches.append(f"(bbs = {self.states.id(source)} & bbe = {ev})")
            core.ret(req, nid, f"case {any_of(matches)} : F; TRUE : S; esac")
        # state leaves
        for nid, spec in self.leaves.states.items():
            req = core.leaf_request(nid)
            start = f"{req} & {core.st(nid)} = I"
            if spec.action is not None:
                record_action(core, start, self.outputs.id(spec.action), k)
            core.rule("bbs", start, self.states.id(spec.state))
            core.rule("bbe", start, "ev_none")
            core.ret(start, nid, "S" if spec.final else "R")
            running = f"{req} & {core.st(nid)} = R"
            exits = [e for e in (self._ev(x) for x in spec.exits) if e not in (None, "ev_none")]
            exit_pending = any_of(f"bbe = {e}" for e in exits)
            core.ret(f"{running} & {exit_pending}", nid, "S")
            core.rule("bbe", f"{running} & bbe != ev_none & !{exit_pending}", "ev_none")
            core.ret(running, nid, "R")
        # the root returned
        ended = root_returned(core)
        again = f"{ended} & res = S & bbe != ev_none & !tick2"
        core.rule("tick2", again, "TRUE")
        core.call(again, 0)
        finish = f"{ended} & !(res = S & bbe != ev_none & !tick2)"  # the event is dropped
        core.rule("res", finish, "NONE")
        core.rule("bbe", finish, "ev_none")
        core.rule("tick2", finish, "FALSE")
        defines = [
            ("stable", stable),
            ("final", f"(lres = lr_S & bbs != {self.states.id(self.leaves.start)})"),
        ]
        defines += step_defines(self.inputs, self.alphabet, k)
        ident = [("bbs", extra_vars["bbs"]), ("lres", extra_vars["lres"])]
        runl = self._running_leaf()
        if runl is None:
            ident += [(v, safe_text(core.var_types[v])) for v in core.identity_vars()]
        else:
            defines.append(("runl", runl[0]))
            ident.append(("runl", runl[1]))
        text = core.emit(self.module, "go, inp", defines)
        names = self.states.to_name
        return Encoding(
            self.module,
            text,
            [f"o{j}" for j in range(1, k + 1)],
            list(self.alphabet),
            ident,
            decode_state=lambda values: names.get(values.get("bbs", ""), "?"),
            var_order=list(core.var_types),
        )
