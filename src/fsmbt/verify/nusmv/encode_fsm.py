"""An FSM as an SMV module: the macro-step machine (FSM vs LEBT, FSM vs FSM) or the FSM read as
a leaf-execution machine (BT vs FSM), with the same meaning as ``fsmbt.semantics.machine``'s
``FSMMachine`` and ``fsmbt.verify.pairing``'s ``FSMLeafMachine`` (docs/verification.md).

Module interface shared by every machine encoding (``MODULE name(go, inp)``): ``go`` says the
environment gives input ``inp`` now; DEFINEs ``stable`` (waiting for input), ``final`` (status
"final"), ``offers_<input>``; output slots ``o1..ok`` holding what the last step (or the start)
output, ``o_none`` for an empty slot. An FSM takes one step per input, so it is always stable.
Size: O(S + T) lines for S states and T transitions.

The position ``q`` is an ``unsigned word[B]`` (B = ceil(log2 of the number of states), state
i written ``0udB_i``, i its index in the state table), not an enumeration: NuSMV turns an
enumerated ``next(q) := case ... esac`` of n rows into a decision diagram with one leaf per
state and then a relation per leaf, 5.3 s of model building per 1 000-state module, against
0.65 s for the word, whose case is built one bit at a time (docs/nusmv.md, "Building the
model"). Codes past the last state are excluded by ``INVAR q <= last``: never reached from the
start anyway (no row leads there), but the runs without a forward search (``-df``) would
compute their fixpoints over them too (the CTL run of a 300-state pair: 2.7 s without the
``INVAR``, 0.54 s with it).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from fsmbt.model.errors import InputError
from fsmbt.model.flatten import flatten
from fsmbt.model.fsm import FSM
from fsmbt.semantics.status import LeafOutcome, MachineStatus
from fsmbt.verify.nusmv.smv import Symbols, any_of, case

NONE_OUT = "out_none"
LEAF_OUTCOMES = tuple(outcome.value for outcome in LeafOutcome)


@dataclass
class Encoding:
    """What the product needs to know about one machine's module."""

    module: str
    text: str
    slots: list[str]
    inputs: list[str]  # inputs the machine may be offered (names)
    id_vars: list[tuple[str, str]]  # identity variables (name, SMV type) at stable points
    follows: bool = False
    # the state's description from its variables' values (dict of var -> value)
    decode_state: Callable[[dict[str, str]], str] = str
    var_order: list[str] = field(default_factory=list)  # the module's variables, for the BDD order
    # when the identity is one variable: every value it may take, in order (``specs.REACH``)
    id_values: list[str] = field(default_factory=list)
    # the ``unsigned word`` position variable (name, bits), if the module has one
    position: tuple[str, int] | None = None
    # ask the product to interleave this module's position bits with the other module's
    # (``specs._order``; docs/nusmv.md, "Trees by macro steps")
    interleave: bool = False
    # the variables holding outputs, with their bits, interleaved like ``position``
    output_words: list[tuple[str, int]] = field(default_factory=list)
    # identity DEFINEs -> the variable their frozen copy is ordered next to (``specs._order``)
    id_near: dict[str, str] = field(default_factory=dict)
    # the input ``inp_s`` ordered after the source's variables when both modules ask for it
    # (an FSM read by events; ``specs._order``; docs/nusmv.md, "Sixth round")
    input_after_source: bool = False


def enum_bits(enum: str) -> int:
    """The bits NuSMV's boolean encoding gives an enumeration written ``{a, b, ...}``."""
    values = enum.count(",") + 1
    return max(1, (values - 1).bit_length())


class _Codes:
    """The states' binary codes: ``id(name)`` is the ``unsigned word`` constant of a state
    (its index in ``states``), ``to_name`` decodes one (as NuSMV prints it) to the name."""

    def __init__(self, states: Symbols) -> None:
        self.bits = max(1, (len(states.to_id) - 1).bit_length())
        self.type = f"unsigned word[{self.bits}]"
        self._of = {name: f"0ud{self.bits}_{i}" for i, name in enumerate(states.to_id)}
        self.to_name = {code: name for name, code in self._of.items()}
        self.last = f"0ud{self.bits}_{len(self._of) - 1}"
        self.unused = (1 << self.bits) > len(self._of)

    def id(self, name: str) -> str:
        return self._of[name]


class FSMEncoder:
    """Encodes a (flattened) FSM; ``leaf=True`` reads it as ``FSMLeafMachine`` does."""

    def __init__(
        self,
        fsm: FSM,
        module: str,
        inputs: Symbols,
        outputs: Symbols,
        *,
        alphabet: Sequence[str],
        leaf: bool = False,
        loop: bool = False,
    ) -> None:
        self.fsm = flatten(fsm)
        if self.fsm.initial is None:
            raise InputError("the state machine has no initial state", element=self.fsm.name)
        self.module = module
        self.inputs = inputs
        self.outputs = outputs
        self.alphabet = list(LEAF_OUTCOMES) if leaf else list(alphabet)
        self.leaf = leaf
        self.loop = loop
        self.states = Symbols("q")
        self.start_pseudo: str | None = None
        if not leaf and self.fsm.initial_event is not None:
            self.start_pseudo = self.fsm.start_name or "__start__"
            if self.start_pseudo in self.fsm.states:
                self.start_pseudo = None  # FSMMachine treats it as the real state then
        if self.start_pseudo is not None:
            self.states.id(self.start_pseudo)
        self.states.add_all(self.fsm.states)
        self.codes = _Codes(self.states)  # the states are all known now
        inputs.add_all(self.alphabet)

    def _out(self, name: str) -> str:
        action = self.fsm.states[name].action
        return NONE_OUT if action is None else self.outputs.id(action)

    def encode(self) -> Encoding:
        fsm = self.fsm
        table = fsm.transition_map()
        q = self.codes
        lines = [
            f"MODULE {self.module}(go, inp)",
            "VAR",
            f"  q : {q.type};",
            f"  o1 : {{{NONE_OUT}}};",
        ]
        # o1/o2 are typed after every output value is known (placeholder replaced below)
        next_q: list[tuple[str, str]] = []
        next_o1: list[tuple[str, str]] = []
        next_o2: list[tuple[str, str]] = []
        initial = fsm.initial
        assert initial is not None
        if self.leaf:
            for name, state in fsm.states.items():
                if state.final:
                    continue  # a final state takes no input (it offers none)
                for symbol in self.alphabet:
                    t = table.get(name, {}).get(symbol)
                    target = t.target if t is not None else name
                    guard = f"go & q = {q.id(name)} & inp = {self.inputs.id(symbol)}"
                    o2 = NONE_OUT
                    if self.loop and fsm.states[target].final and target != initial:
                        o2 = self._out(initial)
                        lands = initial
                    else:
                        lands = target
                    next_q.append((guard, q.id(lands)))
                    next_o1.append((guard, self._out(target)))
                    next_o2.append((guard, o2))
            start_q, start_o = initial, [self._out(initial), NONE_OUT]
        else:
            if self.start_pseudo is not None:
                ev = fsm.initial_event or ""
                guard = f"go & q = {q.id(self.start_pseudo)} & inp = {self.inputs.id(ev)}"
                next_q.append((guard, q.id(initial)))
                next_o1.append((guard, self._out(initial)))
            for name, state in fsm.states.items():
                if state.final:
                    continue
                for label, t in table.get(name, {}).items():
                    if label is None or label not in self.alphabet:
                        continue
                    guard = f"go & q = {q.id(name)} & inp = {self.inputs.id(label)}"
                    next_q.append((guard, q.id(t.target)))
                    next_o1.append((guard, self._out(t.target)))
            if self.start_pseudo is not None:
                start_q, start_o = self.start_pseudo, [NONE_OUT]
            else:
                start_q, start_o = initial, [self._out(initial)]
        slots = ["o1", "o2"] if self.leaf else ["o1"]
        out_enum = self.outputs.enum([NONE_OUT])
        lines[-1] = f"  o1 : {out_enum};"
        if self.leaf:
            lines.append(f"  o2 : {out_enum};")
        finals = [q.id(n) for n, s in fsm.states.items() if s.final]
        if q.unused:  # the runs without a forward search (-df) must not see unused codes
            lines += ["INVAR", f"  q <= {q.last};"]
        lines += [
            "DEFINE",
            "  stable := TRUE;",
            f"  final := {any_of(f'q = {f}' for f in finals)};",
        ]
        for symbol in sorted(set(self.inputs.to_id) | set(self.alphabet)):
            offered = symbol in self.alphabet
            value = ("!final" if self.leaf else "TRUE") if offered else "FALSE"
            lines.append(f"  offers_{self.inputs.id(symbol)} := {value};")
        lines += [
            "ASSIGN",
            f"  init(q) := {q.id(start_q)};",
            f"  next(q) := {case(next_q, 'q')};",
            f"  init(o1) := {start_o[0]};",
            f"  next(o1) := {case(next_o1 + [('go', NONE_OUT)], 'o1')};",
        ]
        if self.leaf:
            lines += [
                f"  init(o2) := {start_o[1]};",
                f"  next(o2) := {case(next_o2 + [('go', NONE_OUT)], 'o2')};",
            ]
        names = q.to_name

        def decode(values: dict[str, str]) -> str:
            return names.get(values.get("q", ""), "?")

        return Encoding(
            self.module,
            "\n".join(lines) + "\n",
            slots,
            list(self.alphabet),
            [("q", q.type)],
            follows=self.leaf,
            decode_state=decode,
            var_order=["q", *slots],
            id_values=list(q.to_name),
            position=("q", q.bits),
            output_words=[(slot, enum_bits(out_enum)) for slot in slots],
            input_after_source=not self.leaf,
        )

    def status_of(self, values: dict[str, str]) -> str:
        name = self.codes.to_name.get(values.get("q", ""))
        final = name in self.fsm.states and self.fsm.states[name].final
        status: MachineStatus = MachineStatus.FINAL if final else MachineStatus.RUNNING
        return str(status.value)
