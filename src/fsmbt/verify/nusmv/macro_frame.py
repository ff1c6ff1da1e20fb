"""The macro-step frame shared by the blackboard encoders of FSM ~ BT pairs (``encode_lebt.py``
for the LEBT, ``encode_sv.py`` for the BSD/CHDS state-variable trees).

Both run a tree by macro steps over ``BTCore``'s tick rules with the same frame variables:
``bbe`` (the pending event, ``ev_none`` when none), ``lres`` (the last tick's root result),
the action slots ``a1..aK`` with their count ``nact`` and the overflow flag ``ovf``. What differs
between the two (when a tick is repeated, what a leaf answers) stays in each encoder; what is
the same is written once here:

- a macro step starts on ``go``: the root is called, ``bbe`` takes the input's event (an input
  outside the alphabet: none), the slots are emptied;
- an action is recorded in the next free slot (past ``K``, ``ovf`` is set: the encoders' extra
  spec then refuses the pair as unsupported);
- when the root returns, a pending wake-up re-ticks it at once (BehaviorTree.CPP's
  ``Tree::tickRoot``); otherwise the tick has *ended*: the root's status is reset unless it is
  RUNNING and ``lres`` keeps the result;
- the defines every encoding exports: one output per slot and the inputs it offers.

Each function adds rules in the order the encoders added them before (a variable's rules are a
``case``: order matters within one variable, not across them). Cost: O(K + alphabet) rules.
"""

from __future__ import annotations

from collections.abc import Sequence

from fsmbt.model.bt import BTDocument
from fsmbt.model.errors import Hint, UnsupportedError
from fsmbt.verify.nusmv.encode_bt import BTCore
from fsmbt.verify.nusmv.encode_fsm import NONE_OUT
from fsmbt.verify.nusmv.smv import Symbols, case


def frame_core(doc: BTDocument, what: str) -> BTCore:
    """``doc``'s tick rules (``BTCore``, no ``loop``); a root that may return SKIPPED is refused
    (the macro-step protocols read SUCCESS/FAILURE/RUNNING only). ``what``: the tree's kind,
    for the message."""
    core = BTCore(doc, loop=False)
    if core.may_skip[0]:
        raise UnsupportedError(
            f"the NuSMV encoding of {what} does not support a root that may return SKIPPED",
            element=core.nodes[0].label,
            hints=(Hint.NATIVE_VERIFIER,),
        )
    return core


def frame_symbols(inputs: Symbols, alphabet: Sequence[str], start: str) -> tuple[Symbols, Symbols]:
    """The inputs get the ``alphabet``; returns the symbol tables of ``bbs`` (the states,
    ``start`` first: its id is the initial value) and of ``bbe`` (the alphabet's events)."""
    inputs.add_all(alphabet)
    states = Symbols("bs")
    states.id(start)
    events = Symbols("ev")
    events.add_all(alphabet)
    return states, events


def declare_frame(
    core: BTCore, types: dict[str, str], inits: dict[str, str], slots: int, out_enum: str
) -> None:
    """Declare the encoder's variables ``types`` (with their ``inits``) and then the action
    slots ``a1..aK`` (no action), in that order (it is the BDD order where the encoder keeps
    the declaration order), and build the tree's tick rules."""
    for j in range(1, slots + 1):
        types[f"a{j}"] = out_enum
        inits[f"a{j}"] = NONE_OUT
    core.var_types.update(types)
    core.init.update(inits)
    core.build()


def start_step(
    core: BTCore, inputs: Symbols, events: Symbols, alphabet: Sequence[str], slots: int
) -> None:
    """On ``go``: call the root, take the input's event into ``bbe``, empty the slots."""
    core.call("go", 0)
    core.rule(
        "bbe",
        "go",
        case([(f"inp = {inputs.id(e)}", events.id(e)) for e in alphabet], "ev_none"),
    )
    core.rule("nact", "go", "0")
    for j in range(1, slots + 1):
        core.rule(f"a{j}", "go", NONE_OUT)


def record_action(core: BTCore, when: str, action: str, slots: int) -> None:
    """Where ``when`` holds, ``action`` (an output id) goes into the next free slot; past the
    last slot ``ovf`` is set instead."""
    for j in range(1, slots + 1):
        core.rule(f"a{j}", f"{when} & nact = {j - 1}", action)
    core.rule("ovf", f"{when} & nact = {slots}", "TRUE")
    core.rule("nact", f"{when} & nact < {slots}", "nact + 1")


def root_returned(core: BTCore) -> str:
    """The rules for the root's return: a pending wake-up re-ticks at once; otherwise the tick
    has ended (the root's status reset unless RUNNING, ``lres`` its result). Returns the
    condition "the tick has ended", for the encoder's own rules on what follows."""
    top = "cur = TOP & res != NONE"
    core.rule("wake", f"{top} & res = R & wake", "FALSE")
    core.call(f"{top} & res = R & wake", 0)
    ended = f"{top} & !(res = R & wake)"
    core.rules.setdefault(core.st(0), []).append((f"{ended} & res != R", "I"))
    core.rule("lres", ended, "case res = S : lr_S; res = F : lr_F; TRUE : lr_R; esac")
    return ended


def step_defines(inputs: Symbols, alphabet: Sequence[str], slots: int) -> list[tuple[str, str]]:
    """The outputs ``o1..oK`` (the slots) and ``offers_<input>`` for every input symbol."""
    defines = [(f"o{j}", f"a{j}") for j in range(1, slots + 1)]
    offered = set(alphabet)
    for symbol, sid in sorted(inputs.to_id.items()):
        defines.append((f"offers_{sid}", "TRUE" if symbol in offered else "FALSE"))
    return defines
